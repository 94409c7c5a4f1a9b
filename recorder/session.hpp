#pragma once
// The recorder's session (main.cpp starts it): the bus (and optionally a
// lcm-logger log) on one side, the RunRecorder on the other, the journal and
// checkpoint cuts, and the clocks that decide when to stop waiting.
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
#include <thread>

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

namespace dynhet::recorder {

using Clock = std::chrono::steady_clock;
inline double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

struct Options {
  std::string url, out, from_log, author, author_email;
  double timeout = 60, wait_run = 120;
  int64_t run_id = 0; // 0: the first run seen
  std::string checkpoint_dir;
  int resume_cut = -1;
  double cut_wait = 300; // after a signal: how long to wait for the next cut
  std::string analysis, analysis_toml; // re-analysis: the analysis file and its text
  double test_message_delay = 0; // tests: seconds of sleep per message taken from the bus (a recorder behind)
  dynhet::BusOptions bus;
};

// The one channel each message may come on (lcm_url.hpp: one channel per
// source): a message whose cutoff or node disagrees with its channel's is
// dropped and counted, whatever else it says (session.cpp).
std::string channel_of(const dynhet::run_info_t &);
std::string channel_of(const dynhet::sim_status_t &);
std::string channel_of(const dynhet::frame_chunk_t &);
std::string channel_of(const dynhet::node_status_t &);
template <class Result> std::string channel_of(const Result &m) { return dynhet::result_channel_of(m); }

// The bus (and optionally a log) on one side, the RunRecorder on the
// other, and the clocks that decide when to stop waiting.
class Session {
public:
  // `signal`: the last SIGINT/SIGTERM caught (0: none), set by main's handler.
  Session(lcm::LCM &lcm, dynhet::Bus bus, const Options &o, const std::atomic<int> &signal)
      : lcm_(lcm), bus_(std::move(bus)), opt_(o), rec_(o.out, DYNHET_VERSION, o.author, o.author_email),
        start_(Clock::now()), signal_(signal) {
    if (!o.analysis.empty()) rec_.set_reanalysis(o.analysis_toml, o.analysis);
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
  const std::atomic<int> &signal_;
  std::string fatal_, early_failure_;
  dynhet::node_status_t own_{}; // the recorder's own status (kept frames only)
  // Checkpoint cuts (--checkpoint-dir): the journal and the cuts' bookkeeping.
  std::unique_ptr<dynhet::RecorderCuts> cuts_;
  bool replaying_ = false, sim_interrupted_ = false;
  // Whether the sim has spoken on the bus in this process's life (a resumed
  // recorder has its run info from its journal, before any sim runs).
  bool sim_heard_live_ = false;
  static constexpr double kNoSimGrace = 10; // s after a signal, the sim still silent: it is not running
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
  void drain(); // handles what is queued before the end
  int finish(const std::string &reason);
  bool sim_ended() const { return rec_.completion().sim_ended() || log_done_; }

  void take_run(const dynhet::run_info_t &m);
  void take_sim(const dynhet::sim_status_t &m);
  void take_node(const dynhet::node_status_t &m) {
    if (m.node == dynhet::kRecorderNode) return; // the recorder's own (or one posing as it): no analysis node
    if (rec_.on_node_status(m)) last_progress_ = Clock::now();
  }
  template <class Result> void take_result(const Result &m) {
    if (rec_.on_result(m)) last_progress_ = Clock::now();
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
    if (opt_.test_message_delay > 0 && !replaying_)
      std::this_thread::sleep_for(std::chrono::duration<double>(opt_.test_message_delay));
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

} // namespace dynhet::recorder
