// recorder: writes one run to an H5MD file. It locks on to the first run
// info it hears, records sim status, node status and the observables'
// results (and the frames, if the scene keeps them), and closes the file
// when the sim has ended and every observable the run names has its final
// result and its node has said done.
//
// When the scene keeps the frames (and they come from the bus), the
// recorder publishes its own status on DYNHET_NODE_STATUS_recorder,
// after every kept frame and every second, as the analysis nodes do: the
// sim paces its frames on it (flow control), so that a recorder slowed by
// its writes, or stopped, loses none. Its own status is not a node's: it
// ignores it when it reads the nodes' status.
//
// `recorder --list-nodes LOG` prints the analysis nodes the run in an
// lcm-logger log needs (for replays) and exits.
//
// Exit: 0 complete; 1 incomplete (sim failed, results missing after
// --timeout, no run info within --wait-run); 2 interrupted (SIGINT or
// SIGTERM; the file is closed cleanly; with --checkpoint-dir, after its part
// of the next checkpoint cut, or because the sim stopped resumably); 3
// could not start (bus, log, output file or the cut to resume).
//
// With --checkpoint-dir it journals every message it takes and saves its
// part of each checkpoint cut (recorder_cuts.hpp); --resume-cut N rebuilds
// run.h5 from the journal up to cut N and goes on.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <climits>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>

#include "dynhet/bus.hpp"
#include "dynhet/bus_cli.hpp"
#include "dynhet/flow_control.hpp"
#include "dynhet/lcm_url.hpp"
#include "dynhet/scene.hpp"
#include "dynhet/lcm_exit.hpp"
#include "dynhet/lcm_guard.hpp"
#include "dynhet/message_checks.hpp"
#include "dynhet/cut.hpp"
#include "dynhet/state_archive.hpp"
#include "recorder_cuts.hpp"
#include "run_recorder.hpp"

namespace {

std::atomic<int> g_signal{0};
void on_signal(int sig) { g_signal = sig; }

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

struct Options {
  std::string url, out, from_log, author, author_email;
  double timeout = 60, wait_run = 120;
  int64_t run_id = 0; // 0: the first run seen
  std::string checkpoint_dir;
  int resume_cut = -1;
  double cut_wait = 300; // after a signal: how long to wait for the next cut
  dynhet::BusOptions bus;
};

// The one channel each message may come on (lcm_url.hpp: one channel per
// source): a message whose cutoff or node disagrees with its channel's is
// dropped and counted, whatever else it says.
std::string channel_of(const dynhet::run_info_t &) { return dynhet::kChanRun; }
std::string channel_of(const dynhet::sim_status_t &) { return dynhet::kChanSimStatus; }
std::string channel_of(const dynhet::frame_chunk_t &) { return dynhet::kChanFrame; }
std::string channel_of(const dynhet::node_status_t &m) { return dynhet::node_status_channel(m.node); }
using dynhet::cutoff_channel;
std::string channel_of(const dynhet::overlap_t &m) {
  return cutoff_channel(dynhet::kChanOverlap, m.cutoff_a, m.cage_relative);
}
std::string channel_of(const dynhet::chi4_t &m) {
  return cutoff_channel(dynhet::kChanChi4, m.cutoff_a, m.cage_relative);
}
std::string channel_of(const dynhet::s4_t &m) { return cutoff_channel(dynhet::kChanS4, m.cutoff_a, m.cage_relative); }
std::string channel_of(const dynhet::clusters_t &m) {
  return cutoff_channel(dynhet::kChanClusters, m.cutoff_a, m.cage_relative);
}
std::string channel_of(const dynhet::bond_breaking_t &) { return dynhet::kChanBondBreaking; }
std::string channel_of(const dynhet::msd_t &m) { return dynhet::result_channel(dynhet::kChanMsd, m.cage_relative); }
std::string channel_of(const dynhet::displacement_t &m) {
  return dynhet::result_channel(dynhet::kChanDisplacement, m.cage_relative);
}

// The bus (and optionally a log) on one side, the RunRecorder on the
// other, and the clocks that decide when to stop waiting.
class Session {
public:
  Session(lcm::LCM &lcm, dynhet::Bus bus, const Options &o)
      : lcm_(lcm), bus_(std::move(bus)), opt_(o), rec_(o.out, DYNHET_VERSION, o.author, o.author_email),
        start_(Clock::now()) {
    if (!o.checkpoint_dir.empty()) cuts_ = std::make_unique<dynhet::RecorderCuts>(lcm, bus_, o.checkpoint_dir);
  }

  int run();

private:
  lcm::LCM &lcm_;
  // The run's key: every message checked before it is decoded, the journal
  // replayed through the same checks (the same verdicts in the same order).
  dynhet::Bus bus_;
  Options opt_;
  dynhet::RunRecorder rec_;
  std::unique_ptr<lcm::LogFile> log_;
  lcm::Subscription *frames_ = nullptr;
  bool log_done_ = false;
  Clock::time_point start_, last_sim_, last_progress_, last_own_status_;
  std::string fatal_, early_failure_;
  dynhet::node_status_t own_{}; // the recorder's own status (kept frames only)
  // Checkpoint cuts (--checkpoint-dir): the journal and the cuts' bookkeeping.
  std::unique_ptr<dynhet::RecorderCuts> cuts_;
  bool replaying_ = false, sim_interrupted_ = false;
  std::string resumable() const {
    return cuts_->saved_cut() >= 0 ? "resumable: this recorder's last saved cut is " + std::to_string(cuts_->saved_cut())
                                   : "this recorder saved no cut";
  }
  std::optional<Clock::time_point> signalled_;
  // Messages taken from the bus per channel (said at the end: what a log of
  // the same run should hold). Bounded: any process may invent channels.
  std::map<std::string, long long> received_;
  void count_received(const std::string &ch) {
    if (received_.size() < 256 || received_.count(ch)) ++received_[ch];
    else ++received_["(other channels)"];
  }
  bool start_cuts(); // the journal, new or resumed; false: fatal_ says why
  void dispatch(const std::string &ch, const void *data, int size);
  void take_checkpoint(const lcm::ReceiveBuffer *rb, const std::string &ch);
  void journal_epoch(); // marks the journal: what follows came under this launch's epoch

  void subscribe();
  bool read_log(int max_events);
  int step(); // -1: keep going, else the exit code
  int finish(const std::string &reason);
  bool sim_ended() const { return rec_.completion().sim_ended() || log_done_; }

  void take_run(const dynhet::run_info_t &m);
  void take_sim(const dynhet::sim_status_t &m);
  void take_node(const dynhet::node_status_t &m) {
    if (m.node == dynhet::kRecorderNode) return; // the recorder's own (or one posing as it): no analysis node
    if (rec_.on_node_status(m)) last_progress_ = Clock::now();
  }
  template <class Msg, bool (dynhet::RunRecorder::*On)(const Msg &)> void take_result(const Msg &m) {
    if ((rec_.*On)(m)) last_progress_ = Clock::now();
  }
  void take_frame(const dynhet::frame_chunk_t &m) {
    const int before = rec_.frames_whole() + rec_.frames_lost();
    rec_.on_frame_chunk(m);
    if (rec_.frames_whole() + rec_.frames_lost() != before) publish_own_status("running"); // the sim paces on it
  }
  // Only for kept frames from the bus: the sim paces on them.
  bool paced() const { return rec_.keep_frames() && !log_; }
  void publish_own_status(const std::string &state, const std::string &message = "");
  // Every message is untrusted: decoded with every check (lcm_guard.hpp),
  // a bad one dropped and counted, and no handler's exception escapes.
  template <class Msg, void (Session::*Take)(const Msg &)>
  void raw(const lcm::ReceiveBuffer *rb, const std::string &ch) {
    take_bytes<Msg, Take>(rb->data, static_cast<int>(rb->data_size), ch);
  }
  template <class Msg, void (Session::*Take)(const Msg &)>
  void take_bytes(const void *data, int size, const std::string &ch) {
    if (!replaying_) count_received(ch);
    if (cuts_ && !replaying_) cuts_->journal().append(ch, data, static_cast<uint32_t>(size));
    Msg m;
    std::string why;
    int lcm_bytes = 0;
    if (!bus_.open(ch, data, static_cast<std::size_t>(size), lcm_bytes, why)) return unauthenticated(ch, why);
    if (!dynhet::guard::safe_decode(data, lcm_bytes, m, why)) return reject(ch, why);
    if (const std::string own = channel_of(m); ch != own)
      return reject(ch, "not this message's channel, which is " + own.substr(0, 80));
    try {
      (this->*Take)(m);
    } catch (const std::exception &e) {
      reject(ch, std::string("handler: ") + e.what());
    }
  }
  // Dropped by the bus (no tag, a wrong one, another launch's, a replay):
  // counted apart from the malformed ones.
  void unauthenticated(const std::string &ch, const std::string &why) {
    rec_.message_unauthenticated(ch, why);
    if (rec_.messages_unauthenticated() <= 10 || rec_.messages_unauthenticated() % 1000 == 0)
      std::fprintf(stderr, "recorder: dropped a message on %s (%s; %lld so far)\n", ch.c_str(), why.c_str(),
                   static_cast<long long>(rec_.messages_unauthenticated()));
  }
  void reject(const std::string &ch, const std::string &why) {
    rec_.message_rejected(ch, why);
    if (rec_.messages_rejected() <= 10 || rec_.messages_rejected() % 1000 == 0)
      std::fprintf(stderr, "recorder: dropped a message on %s (%s; %lld so far)\n", ch.c_str(), why.c_str(),
                   static_cast<long long>(rec_.messages_rejected()));
  }
};

// Run info and sim status come from the log when one is given, results
// always from the bus. Queues are deep: results and chunks come in bursts.
void Session::subscribe() {
  if (!opt_.from_log.empty()) {
    log_ = std::make_unique<lcm::LogFile>(opt_.from_log, "r");
    if (!log_->good()) fatal_ = "cannot read the log " + opt_.from_log;
  } else {
    lcm_.subscribe(dynhet::kChanRun, &Session::raw<dynhet::run_info_t, &Session::take_run>, this)
        ->setQueueCapacity(100);
    lcm_.subscribe(dynhet::kChanSimStatus, &Session::raw<dynhet::sim_status_t, &Session::take_sim>, this)
        ->setQueueCapacity(1000);
    // Frames from the start: the first ones can follow the run info
    // closely, and LCM drops what arrives on a channel nobody subscribes.
    frames_ = lcm_.subscribe(dynhet::kChanFrame, &Session::raw<dynhet::frame_chunk_t, &Session::take_frame>, this);
    frames_->setQueueCapacity(10000);
  }
  // Every channel of each family (a cutoff's, a node's), and names outside
  // the scheme that start like it, to be dropped and counted.
  using R = dynhet::RunRecorder;
  using dynhet::channel_family;
  lcm_.subscribe(channel_family(dynhet::kChanNodeStatus),
                 &Session::raw<dynhet::node_status_t, &Session::take_node>, this)
      ->setQueueCapacity(1000);
  lcm_.subscribe(channel_family(dynhet::kChanOverlap),
                 &Session::raw<dynhet::overlap_t, &Session::take_result<dynhet::overlap_t, &R::on_overlap>>, this)
      ->setQueueCapacity(10000);
  lcm_.subscribe(channel_family(dynhet::kChanChi4),
                 &Session::raw<dynhet::chi4_t, &Session::take_result<dynhet::chi4_t, &R::on_chi4>>, this)
      ->setQueueCapacity(10000);
  lcm_.subscribe(channel_family(dynhet::kChanMsd),
                 &Session::raw<dynhet::msd_t, &Session::take_result<dynhet::msd_t, &R::on_msd>>, this)
      ->setQueueCapacity(10000);
  lcm_.subscribe(channel_family(dynhet::kChanS4),
                 &Session::raw<dynhet::s4_t, &Session::take_result<dynhet::s4_t, &R::on_s4>>, this)
      ->setQueueCapacity(1000);
  lcm_.subscribe(channel_family(dynhet::kChanClusters),
                 &Session::raw<dynhet::clusters_t, &Session::take_result<dynhet::clusters_t, &R::on_clusters>>, this)
      ->setQueueCapacity(10000);
  lcm_.subscribe(
         channel_family(dynhet::kChanDisplacement),
         &Session::raw<dynhet::displacement_t, &Session::take_result<dynhet::displacement_t, &R::on_displacement>>,
         this)
      ->setQueueCapacity(1000);
  lcm_.subscribe(
         channel_family(dynhet::kChanBondBreaking),
         &Session::raw<dynhet::bond_breaking_t, &Session::take_result<dynhet::bond_breaking_t, &R::on_bond_breaking>>,
         this)
      ->setQueueCapacity(10000);
  // The launch scripts wait for this line before starting the sim.
  std::fprintf(stderr, "recorder: ready, waiting for run info%s%s (bus %s)\n", log_ ? " in " : "",
               log_ ? opt_.from_log.c_str() : "", bus_.describe());
}

void Session::take_run(const dynhet::run_info_t &m) {
  if (rec_.has_run() || (opt_.run_id && m.run_id != opt_.run_id)) return;
  if (const std::string bad = dynhet::run_info_problem(m); !bad.empty())
    return reject(dynhet::kChanRun, "run info: " + bad);
  try {
    if (!rec_.on_run(m)) return;
    if (cuts_) cuts_->set_run(m);
  } catch (const std::exception &e) {
    fatal_ = e.what(); // the file cannot be written
    return;
  }
  last_sim_ = last_progress_ = Clock::now();
  // Its socket gets every frame's datagrams, kept or not (results arrive
  // between them): a buffer that holds a whole frame, as the nodes ask.
  const int64_t got =
      dynhet::grow_udp_receive_buffers(dynhet::frame_receive_buffer_bytes(m.n_particles, m.chunk_particles));
  std::fprintf(stderr, "recorder: run %lld, N=%d, %d frames%s -> %s", static_cast<long long>(m.run_id),
               m.n_particles, m.n_frames, m.keep_frames ? " (kept)" : "", opt_.out.c_str());
  if (got >= 0) std::fprintf(stderr, ", socket buffer %.1f MiB", got / 1048576.0);
  std::fprintf(stderr, "\n");
}

void Session::take_sim(const dynhet::sim_status_t &m) {
  if (!rec_.has_run() && m.phase == "failed") early_failure_ = m.message;
  if (!rec_.on_sim_status(m)) return;
  if (!replaying_) sim_interrupted_ = m.phase == "interrupted";
  last_sim_ = Clock::now();
  if (rec_.completion().sim_ended()) last_progress_ = Clock::now();
}

// Feeds up to `max_events` of the log's run info, sim status and (when
// kept) frame chunks. Returns false at the end of the log.
bool Session::read_log(int max_events) {
  for (int i = 0; i < max_events; ++i) {
    const lcm::LogEvent *e = log_->readNextEvent();
    if (!e) return false;
    if (e->channel == dynhet::kChanRun)
      take_bytes<dynhet::run_info_t, &Session::take_run>(e->data, e->datalen, e->channel);
    if (e->channel == dynhet::kChanSimStatus)
      take_bytes<dynhet::sim_status_t, &Session::take_sim>(e->data, e->datalen, e->channel);
    if (e->channel == dynhet::kChanFrame && rec_.keep_frames())
      take_bytes<dynhet::frame_chunk_t, &Session::take_frame>(e->data, e->datalen, e->channel);
  }
  return true;
}

// Where a journaled message goes: the handler of its channel's family.
// The journal says under which launch's epoch the messages after it were
// received ("#bus_epoch": 8 bytes, then 1 if every epoch was taken), so
// that a replay of the journal gives each message the verdict it had.
constexpr const char *kJournalEpoch = "#bus_epoch";

void Session::journal_epoch() {
  uint8_t b[9];
  const uint64_t e = bus_.epoch();
  for (int i = 0; i < 8; ++i) b[i] = static_cast<uint8_t>(e >> (8 * i));
  b[8] = bus_.any_epoch() ? 1 : 0;
  cuts_->journal().append(kJournalEpoch, b, sizeof b);
}

void Session::dispatch(const std::string &ch, const void *d, int n) {
  using R = dynhet::RunRecorder;
  namespace dh = dynhet;
  auto in = [&](const char *family) { return ch.rfind(family, 0) == 0; };
  if (ch == kJournalEpoch) { // a replayed journal: the epoch of what follows
    if (n != 9) return;
    const auto *b = static_cast<const uint8_t *>(d);
    uint64_t e = 0;
    for (int i = 0; i < 8; ++i) e |= uint64_t{b[i]} << (8 * i);
    bus_.take_epoch(e, b[8] != 0);
    return;
  }
  if (ch == dh::kChanRun) take_bytes<dh::run_info_t, &Session::take_run>(d, n, ch);
  else if (ch == dh::kChanSimStatus) take_bytes<dh::sim_status_t, &Session::take_sim>(d, n, ch);
  else if (ch == dh::kChanFrame) take_bytes<dh::frame_chunk_t, &Session::take_frame>(d, n, ch);
  else if (in(dh::kChanNodeStatus)) take_bytes<dh::node_status_t, &Session::take_node>(d, n, ch);
  else if (in(dh::kChanOverlap)) take_bytes<dh::overlap_t, &Session::take_result<dh::overlap_t, &R::on_overlap>>(d, n, ch);
  else if (in(dh::kChanChi4)) take_bytes<dh::chi4_t, &Session::take_result<dh::chi4_t, &R::on_chi4>>(d, n, ch);
  else if (in(dh::kChanMsd)) take_bytes<dh::msd_t, &Session::take_result<dh::msd_t, &R::on_msd>>(d, n, ch);
  else if (in(dh::kChanS4)) take_bytes<dh::s4_t, &Session::take_result<dh::s4_t, &R::on_s4>>(d, n, ch);
  else if (in(dh::kChanClusters))
    take_bytes<dh::clusters_t, &Session::take_result<dh::clusters_t, &R::on_clusters>>(d, n, ch);
  else if (in(dh::kChanDisplacement))
    take_bytes<dh::displacement_t, &Session::take_result<dh::displacement_t, &R::on_displacement>>(d, n, ch);
  else if (in(dh::kChanBondBreaking))
    take_bytes<dh::bond_breaking_t, &Session::take_result<dh::bond_breaking_t, &R::on_bond_breaking>>(d, n, ch);
}

bool Session::start_cuts() {
  if (!cuts_) return true;
  try {
    std::filesystem::create_directories(cuts_->dir());
    if (opt_.resume_cut < 0) {
      cuts_->journal().create(cuts_->journal_path());
      journal_epoch();
      return true;
    }
    std::remove(opt_.out.c_str()); // rebuilt from the journal
    replaying_ = true;
    rec_.flush_each(false);
    const auto r = cuts_->resume(opt_.resume_cut, [&](const std::string &ch, const uint8_t *d, uint32_t n) {
      dispatch(ch, d, static_cast<int>(n));
    });
    replaying_ = false;
    rec_.flush_each(true);
    bus_.take_epoch(bus_.epoch(), bus_.any_epoch()); // this launch's, from here on
    journal_epoch();
    if (!fatal_.empty()) return false;
    if (!rec_.has_run() || rec_.run_id() != r.run_id)
      throw dynhet::BadPart(r.part +
                            ": its journal holds no run info of run " + std::to_string(r.run_id));
    if (dynhet::scene_hash(rec_.run_info()->scene_toml) != r.scene_hash)
      throw dynhet::BadPart(r.part + ": of another scene");
    std::fprintf(stderr, "recorder: resumed from cut %d after frame %d: %llu bytes of journal replayed into %s\n",
                 opt_.resume_cut, r.frame, static_cast<unsigned long long>(r.journal_bytes), opt_.out.c_str());
    return true;
  } catch (const std::exception &e) {
    replaying_ = false;
    rec_.flush_each(true);
    fatal_ = std::string("cannot resume: ") + e.what();
    return false;
  }
}

void Session::take_checkpoint(const lcm::ReceiveBuffer *rb, const std::string &ch) {
  if (!cuts_ || !rec_.has_run()) return;
  dynhet::checkpoint_t m;
  std::string why;
  int lcm_bytes = 0;
  if (!bus_.open(ch, rb->data, rb->data_size, lcm_bytes, why)) return unauthenticated(ch, why);
  if (!dynhet::guard::safe_decode(rb->data, lcm_bytes, m, why)) return reject(ch, why);
  if (m.run_id != rec_.run_id()) return;
  if (const std::string bad = dynhet::checkpoint_problem(m, rec_.n_frames()); !bad.empty())
    return reject(ch, "checkpoint: " + bad);
  if (const std::string bad = cuts_->on_message(m, ch); !bad.empty()) return reject(ch, "checkpoint: " + bad);
  for (int c : cuts_->save_ready()) {
    std::fprintf(stderr, "recorder: checkpoint: cut %d saved (journal %.1f MB)\n", c,
                 cuts_->journal().length() / 1e6);
  }
}

int Session::run() {
  if (!start_cuts()) {
    std::fprintf(stderr, "recorder: %s\n", fatal_.c_str());
    return 3;
  }
  if (cuts_)
    lcm_.subscribe(dynhet::channel_family(dynhet::kChanCheckpoint), &Session::take_checkpoint, this)
        ->setQueueCapacity(1000);
  subscribe();
  for (;;) {
    if (log_ && !log_done_ && fatal_.empty()) {
      log_done_ = !read_log(1000);
      if (log_done_) last_progress_ = Clock::now(); // the wait for results starts now
      dynhet::handle_timeout(lcm_, 0);
    } else if (dynhet::handle_timeout(lcm_, 100) < 0 && !g_signal) {
      return finish(dynhet::bus_lost(lcm_) ? dynhet::kBusLost : "LCM: receive failed");
    }
    const int code = step();
    if (code >= 0) return code;
  }
}

// One look at the clocks and the bookkeeping after a round of messages.
int Session::step() {
  if (!fatal_.empty()) {
    std::fprintf(stderr, "recorder: %s\n", fatal_.c_str());
    return 3;
  }
  if (g_signal && !rec_.has_run()) {
    std::fprintf(stderr, "recorder: interrupted before any run info; no file written\n");
    return 2;
  }
  if (g_signal && cuts_) {
    // Stop after this recorder's part of the next cut (the sim takes one on
    // its signal), or once the sim has stopped, or after --cut-wait.
    if (!signalled_) {
      signalled_ = Clock::now();
      std::fprintf(stderr, "recorder: signal %d: stopping after the sim's next checkpoint cut\n", g_signal.load());
    }
    if (cuts_->stop_cut_saved() || sim_interrupted_ || rec_.completion().sim_ended() ||
        since(*signalled_) > opt_.cut_wait)
      return finish("interrupted by signal " + std::to_string(g_signal.load()) + "; " + resumable());
    return -1;
  }
  if (g_signal) return finish("interrupted by signal " + std::to_string(g_signal.load()));
  // Anyone can say "interrupted": a live sim goes on talking; a stopped one is silent.
  if (cuts_ && sim_interrupted_ && since(last_sim_) > 10)
    return finish("interrupted: the sim stopped; " + resumable());
  if (!rec_.has_run()) {
    if (!early_failure_.empty() || log_done_ || since(start_) > opt_.wait_run) {
      std::fprintf(stderr, "recorder: no run info %s; no file written\n",
                   !early_failure_.empty() ? ("(the sim failed: " + early_failure_ + ")").c_str()
                   : log_done_             ? "in the log"
                                           : "within --wait-run");
      return 1;
    }
    return -1;
  }
  if (frames_ && !rec_.keep_frames()) { // the scene does not keep them
    lcm_.unsubscribe(frames_);
    frames_ = nullptr;
  }
  if (paced() && since(last_own_status_) >= 1.0) publish_own_status("running");
  if (rec_.completion().settled()) return finish("");
  const int t = static_cast<int>(opt_.timeout);
  if (sim_ended() && since(last_progress_) > opt_.timeout)
    return finish("timeout: no results for " + std::to_string(t) + " s after the sim ended");
  if (!sim_ended() && !log_ && since(last_sim_) > opt_.timeout)
    return finish("sim: silent for " + std::to_string(t) + " s");
  return -1;
}

void Session::publish_own_status(const std::string &state, const std::string &message) {
  if (!paced()) return;
  own_.utime = dynhet::utime_now();
  own_.run_id = rec_.run_id();
  own_.node = dynhet::kRecorderNode;
  own_.state = state;
  own_.frames_expected = rec_.n_frames();
  own_.frames_whole = rec_.frames_whole();
  own_.frames_lost = rec_.frames_lost();
  own_.chunks_received = rec_.chunks_received();
  own_.messages_rejected = static_cast<int32_t>(std::min<int64_t>(rec_.messages_rejected(), INT32_MAX));
  own_.messages_unauthenticated =
      static_cast<int32_t>(std::min<int64_t>(rec_.messages_unauthenticated(), INT32_MAX));
  own_.message = message;
  bus_.publish(lcm_, dynhet::node_status_channel(dynhet::kRecorderNode), own_);
  last_own_status_ = Clock::now();
}

int Session::finish(const std::string &reason) {
  const bool paced_run = paced();
  const std::vector<std::string> missing = rec_.finish(reason);
  if (paced_run) publish_own_status(missing.empty() ? "done" : "failed", missing.empty() ? "" : missing.front());
  const long long id = rec_.run_id();
  std::string counts;
  for (const auto &[ch, n] : received_) counts += " " + ch + " " + std::to_string(n) + ",";
  if (!counts.empty()) counts.pop_back();
  std::fprintf(stderr, "recorder: messages received per channel:%s\n", counts.c_str());
  if (missing.empty()) {
    std::fprintf(stderr, "recorder: run %lld complete -> %s\n", id, opt_.out.c_str());
    return 0;
  }
  std::string list;
  for (const std::string &m : missing) list += "\n  " + m;
  std::fprintf(stderr, "recorder: run %lld INCOMPLETE -> %s; missing:%s\n", id, opt_.out.c_str(),
               list.c_str());
  return g_signal ? 2 : 1;
}

// The nodes the run in `log_path` needs, named as the launch scripts
// start them ("overlap" -> overlap_node), on one line.
int list_nodes(const std::string &log_path) {
  lcm::LogFile log(log_path, "r");
  if (!log.good()) {
    std::fprintf(stderr, "recorder: cannot read the log %s\n", log_path.c_str());
    return 3;
  }
  while (const lcm::LogEvent *e = log.readNextEvent()) {
    dynhet::run_info_t run;
    std::string why;
    // Only to name the nodes replay.sh starts: the tag is not checked here
    // (the replayed run's processes check every message).
    if (e->channel != dynhet::kChanRun ||
        !dynhet::guard::safe_decode(e->data, static_cast<int>(dynhet::lcm_bytes_of(e->data, e->datalen)), run, why) ||
        !dynhet::run_info_problem(run).empty())
      continue;
    std::string line;
    for (const std::string &n : dynhet::nodes_for(run.observables)) line += (line.empty() ? "" : " ") + n;
    std::printf("%s\n", line.c_str());
    return 0;
  }
  std::fprintf(stderr, "recorder: no run info in %s\n", log_path.c_str());
  return 1;
}

} // namespace

int main(int argc, char **argv) {
  CLI::App app{"dynhet recorder: one run's results into an H5MD file"};
  Options o;
  std::string list_log;
  app.add_option("--lcm-url", o.url, "LCM URL (default: $LCM_DEFAULT_URL, else the project's)");
  app.add_option("--out", o.out, "output file (.h5); required unless --list-nodes");
  app.add_option("--from-log", o.from_log,
                 "read run info, sim status and frames from this lcm-logger log; "
                 "results still come from the bus");
  app.add_option("--timeout", o.timeout,
                 "seconds to wait for results once the sim has ended (counted from the "
                 "last result or node progress), and for a silent sim")
      ->capture_default_str();
  app.add_option("--wait-run", o.wait_run, "seconds to wait for the run info")->capture_default_str();
  app.add_option("--run-id", o.run_id, "record only this run (default: the first one seen)");
  dynhet::add_bus_options(app, o.bus);
  app.add_option("--author", o.author,
                 "the file's h5md/author name (default: $DYNHET_AUTHOR, else $USER, else \"unknown\")");
  app.add_option("--author-email", o.author_email, "the file's h5md/author email (default: none)");
  app.add_option("--checkpoint-dir", o.checkpoint_dir,
                 "journal every message here and save the recorder's part of each checkpoint cut "
                 "(docs/checkpoints.md); SIGTERM/SIGINT then stop it after the next cut");
  app.add_option("--resume-cut", o.resume_cut, "rebuild the file from the journal up to this cut and go on");
  app.add_option("--cut-wait", o.cut_wait, "after SIGTERM/SIGINT, wait at most this long (s) for the next cut")
      ->capture_default_str();
  app.add_option("--list-nodes", list_log,
                 "print the analysis nodes the run in this lcm-logger log needs, and exit");
  CLI11_PARSE(app, argc, argv);
  if (!list_log.empty()) return list_nodes(list_log);
  if (o.out.empty()) return app.exit(CLI::RequiredError("--out"));
  const std::optional<dynhet::Bus> bus = dynhet::bus_or_say("recorder", o.bus);
  if (!bus) return 2;

  const std::string url = dynhet::resolve_lcm_url(o.url);
  lcm::LCM lcm(url);
  if (dynhet::bus_unreachable(lcm, url)) {
    std::fprintf(stderr, "recorder: cannot open LCM at %s\n", url.c_str());
    return 3;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  Session session(lcm, *bus, o);
  const int code = session.run();
  // Its last status (the sim may pace on it) reaches the bus before it ends
  // (tcpq: dynhet/lcm_exit.hpp).
  if (const std::string why = dynhet::deliver_before_exit(lcm, url); !why.empty())
    std::fprintf(stderr, "recorder: %s\n", why.c_str());
  return code;
}
