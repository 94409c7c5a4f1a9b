// The recorder's session (session.hpp).
#include "session.hpp"

namespace dynhet::recorder {

// The one channel each message may come on (session.hpp).
std::string channel_of(const dynhet::run_info_t &) { return dynhet::kChanRun; }
std::string channel_of(const dynhet::sim_status_t &) { return dynhet::kChanSimStatus; }
std::string channel_of(const dynhet::frame_chunk_t &) { return dynhet::kChanFrame; }
std::string channel_of(const dynhet::node_status_t &m) { return dynhet::node_status_channel(m.node); }

// Run info and sim status come from the log when one is given, results
// always from the bus. Every queue holds what the run can send while the
// recorder is behind (writing kept frames, a slow disk: as far behind as
// the sim's pacing window lets it fall, or further when not paced), so
// that LCM drops nothing before the check: kQueueSmall messages of each
// family of small messages (statuses, results, answers: a few hundred
// bytes to a few kB each, held only while the recorder is behind) and
// kQueueChunks frame chunks. What is lost all the same shows as a hole in
// its sender's numbers and is counted (bus_dropped_lost_recorder).
constexpr int kQueueSmall = 1 << 17, kQueueChunks = 1 << 14;

void Session::subscribe() {
  if (!opt_.from_log.empty()) {
    log_ = std::make_unique<lcm::LogFile>(opt_.from_log, "r");
    if (!log_->good()) fatal_ = "cannot read the log " + opt_.from_log;
  } else {
    lcm_.subscribe(dynhet::kChanRun, &Session::raw<dynhet::run_info_t, &Session::take_run>, this)
        ->setQueueCapacity(kQueueSmall);
    lcm_.subscribe(dynhet::kChanSimStatus, &Session::raw<dynhet::sim_status_t, &Session::take_sim>, this)
        ->setQueueCapacity(kQueueSmall);
    // Frames from the start: the first ones can follow the run info
    // closely, and LCM drops what arrives on a channel nobody subscribes.
    frames_ = lcm_.subscribe(dynhet::kChanFrame, &Session::raw<dynhet::frame_chunk_t, &Session::take_frame>, this);
    frames_->setQueueCapacity(kQueueChunks);
  }
  // Every channel of each family (a cutoff's, a node's), and names outside
  // the scheme that start like it, to be dropped and counted.
  using dynhet::channel_family;
  auto family = [&](const char *name, auto handler) {
    lcm_.subscribe(channel_family(name), handler, this)->setQueueCapacity(kQueueSmall);
  };
  family(dynhet::kChanNodeStatus, &Session::raw<dynhet::node_status_t, &Session::take_node>);
#define DYNHET_SUBSCRIBE(T) family(dynhet::ResultDecl<dynhet::T>::channel, &Session::raw<dynhet::T, &Session::take_result<dynhet::T>>);
  DYNHET_RESULT_TYPES(DYNHET_SUBSCRIBE)
#undef DYNHET_SUBSCRIBE
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
    if (cuts_) cuts_->set_run(*rec_.run_info()); // the run info it goes by (a re-analysis: the changed scene)
  } catch (const std::exception &e) {
    fatal_ = e.what(); // the file cannot be written
    return;
  }
  last_sim_ = last_progress_ = Clock::now();
  if (!replaying_) sim_heard_live_ = true;
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
  if (!replaying_) sim_heard_live_ = true;
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
#define DYNHET_DISPATCH(T) \
  else if (in(dh::ResultDecl<dh::T>::channel)) take_bytes<dh::T, &Session::take_result<dh::T>>(d, n, ch);
  DYNHET_RESULT_TYPES(DYNHET_DISPATCH)
#undef DYNHET_DISPATCH
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
        ->setQueueCapacity(kQueueSmall);
  subscribe();
  for (;;) {
    if (log_ && !log_done_ && fatal_.empty()) {
      log_done_ = !read_log(1000);
      if (log_done_) last_progress_ = Clock::now(); // the wait for results starts now
      dynhet::handle_timeout(lcm_, 0);
    } else if (dynhet::handle_timeout(lcm_, 100) < 0 && !signal_) {
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
  if (signal_ && !rec_.has_run()) {
    std::fprintf(stderr, "recorder: interrupted before any run info; no file written\n");
    return 2;
  }
  if (signal_ && cuts_) {
    // Stop after this recorder's part of the next cut (the sim takes one on
    // its signal), or once the sim has stopped, or after --cut-wait.
    if (!signalled_) {
      signalled_ = Clock::now();
      std::fprintf(stderr, "recorder: signal %d: stopping after the sim's next checkpoint cut\n", signal_.load());
    }
    // A resumed recorder signalled before any sim spoke (the launch script
    // stopped before starting the sim, or the sim stopped before its first
    // word): no cut will come, and nothing has changed since the cut it
    // resumed from.
    const bool no_sim = !sim_heard_live_ && since(*signalled_) > kNoSimGrace;
    if (cuts_->stop_cut_saved() || sim_interrupted_ || rec_.completion().sim_ended() || no_sim ||
        since(*signalled_) > opt_.cut_wait)
      return finish("interrupted by signal " + std::to_string(signal_.load()) +
                    (no_sim ? " before the sim spoke in this attempt" : "") + "; " + resumable());
    return -1;
  }
  if (signal_) return finish("interrupted by signal " + std::to_string(signal_.load()));
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
  const auto drops = bus_.drops();
  std::copy(drops.begin(), drops.end(), own_.bus_drops);
  own_.message = message;
  bus_.publish(lcm_, dynhet::node_status_channel(dynhet::kRecorderNode), own_);
  last_own_status_ = Clock::now();
}

// What is already queued when the recorder ends goes through the checks
// too (a copy of an old status sent after a node's "done" is counted, not
// left unread): until the queues are empty, for at most a few seconds.
void Session::drain() {
  if (log_) return;
  const auto t0 = Clock::now();
  while (since(t0) < 3.0 && dynhet::handle_timeout(lcm_, 50) > 0) {
  }
}

int Session::finish(const std::string &reason) {
  drain();
  rec_.bus_drops(bus_.drops());
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
  return signal_ ? 2 : 1;
}

} // namespace dynhet::recorder
