// FrameNode (frame_node.hpp): the frames, run info and sim status of one
// run, checked, reassembled and handed to the node's computation; its
// status, and the reasons it stops. node_main.cpp runs it in a process.
#include "frame_node.hpp"

#include "dynhet/flow_control.hpp"
#include "dynhet/lcm_guard.hpp"
#include "dynhet/message_checks.hpp"
#include "dynhet/run_info_scene.hpp"

#include <algorithm>
#include <cstdio>
#include <thread>

namespace dynhet {

FrameNode::FrameNode(lcm::LCM& out, int64_t run_filter, std::string name)
    : out_(out), run_filter_(run_filter), name_(std::move(name)) {
  status_.node = name_;
  status_.state = "waiting";
}

bool FrameNode::wants(const std::string& o) const {
  return std::find(info_->observables.begin(), info_->observables.end(), o) != info_->observables.end();
}

void FrameNode::check_sim_alive(double timeout) {
  if (!info_ || finished_ || sim_interrupted_) return;
  const double silent = std::chrono::duration<double>(Clock::now() - last_sim_news_).count();
  if (silent <= timeout) return;
  // Frames missing and no word from the sim: the frames, and likely the
  // sim's last status with them, were lost here, not the sim silent.
  assembler_.finish(info_->n_frames);
  if (assembler_.frames_lost() > 0)
    return finish(1, std::to_string(assembler_.frames_lost()) + " frames lost, and no word from the sim for " +
                         std::to_string(static_cast<int>(silent)) + " s (its final status lost with them?): " +
                         loss_cause());
  finish(1, "the sim has been silent for " + std::to_string(static_cast<int>(silent)) + " s");
}

// What this node observed of why it lost frames, and only that: its queue
// dropped chunks (counted by the Inbox), the kernel dropped datagrams at its
// socket (counted in /proc/net/udp), its receive loop stalled for seconds
// (the process was stopped or starved of CPU).
std::string FrameNode::loss_cause() const {
  if (!inbox_) return "unknown (no inbox)";
  const Inbox::Stats s = inbox_->stats();
  const auto secs = [](double t) {
    char b[32];
    std::snprintf(b, sizeof b, t < 10 ? "%.1f" : "%.0f", t);
    return std::string(b);
  };
  std::vector<std::string> causes;
  if (s.dropped > 0)
    causes.push_back("queue full: the node fell more than " + std::to_string(s.bound >> 20) + " MiB behind (" +
                     std::to_string(s.dropped) + " messages dropped; its longest message took " +
                     secs(longest_handler_) + " s to handle)");
  const int64_t drops = udp_socket_drops();
  const bool stalled = s.longest_receive_gap > 2.0;
  if (drops > 0)
    causes.push_back("socket buffer overflow: the kernel dropped " + std::to_string(drops) +
                     " datagrams at this node's socket" +
                     (stalled ? ", while the process took nothing for " + secs(s.longest_receive_gap) +
                                    " s at a stretch (stopped, or starved of CPU)"
                              : std::string(" (datagrams came faster than this process read them)")));
  else if (stalled)
    causes.push_back("stopped: the process took nothing for " + secs(s.longest_receive_gap) +
                     " s at a stretch (stopped, or starved of CPU)" +
                     (drops < 0 ? " (the kernel's drop count at its socket could not be read)" : ""));
  if (!causes.empty()) {
    std::string out;
    for (const std::string& c : causes) out += (out.empty() ? "" : "; ") + c;
    return out;
  }
  if (drops < 0) return "not known: this node's queue dropped nothing, and the kernel's drop count at its socket "
                        "could not be read";
  return "not at this node: its queue dropped nothing and the kernel dropped no datagram at its socket (the frames "
         "never reached it: missing from its input, or lost on the way)";
}

// A full queue is said at once, not only at the end.
void FrameNode::watch_inbox() {
  if (!inbox_) return;
  const Inbox::Stats s = inbox_->stats();
  if (s.dropped == inbox_dropped_seen_) return;
  if (inbox_dropped_seen_ == 0)
    std::fprintf(stderr, "%s_node: queue full: the node fell more than %lld MiB behind; messages dropped (frames "
                 "will be lost)\n", name_.c_str(), static_cast<long long>(s.bound >> 20));
  inbox_dropped_seen_ = s.dropped;
}

void FrameNode::input_ended() {
  if (finished_) return;
  if (done_said_) return finish(0, ""); // a replay that ends after the sim's "done"
  finish(1, info_ ? "input ended before the run did" : "no run info in the input");
}

void FrameNode::note_unauthenticated(const std::string& channel, const std::string& why) {
  ++unauthenticated_new_;
  const int64_t n = ++unauthenticated_said_;
  if (n <= 10 || n % 1000 == 0)
    std::fprintf(stderr, "%s_node: dropped a message on %s (%s; %lld so far)\n", name_.c_str(), channel.c_str(),
                 why.c_str(), static_cast<long long>(n));
}

void FrameNode::drain_unauthenticated() {
  const auto drops = bus_.drops();
  std::copy(drops.begin(), drops.end(), status_.bus_drops);
  if (const int64_t d = unauthenticated_new_.exchange(0))
    status_.messages_unauthenticated =
        static_cast<int32_t>(std::min<int64_t>(int64_t{status_.messages_unauthenticated} + d, INT32_MAX));
}

void FrameNode::reject(const std::string& channel, const std::string& why) {
  ++status_.messages_rejected;
  status_.last_rejection = channel + ": " + why;
  if (status_.messages_rejected <= 10 || status_.messages_rejected % 1000 == 0)
    std::fprintf(stderr, "%s_node: dropped a message on %s (%s; %d so far)\n", name_.c_str(), channel.c_str(),
                 why.c_str(), status_.messages_rejected);
}

// Decodes into m with every check, or rejects; any exception of the
// handler itself is caught too: no message can end the process.
template <class Msg, class Fn>
static void guarded(FrameNode& node, const lcm::ReceiveBuffer* rb, const std::string& ch, Fn&& fn) {
  Msg m;
  std::string why;
  // The receive thread checked the tag and queued the LCM bytes alone.
  if (!guard::safe_decode(rb->data, static_cast<int>(rb->data_size), m, why)) return node.reject(ch, why);
  try {
    fn(m);
  } catch (const std::exception& e) {
    node.reject(ch, std::string("handler: ") + e.what());
  }
}

void FrameNode::on_run_raw(const lcm::ReceiveBuffer* rb, const std::string& ch) {
  guarded<run_info_t>(*this, rb, ch, [&](const run_info_t& m) { on_run(m); });
}
void FrameNode::on_chunk_raw(const lcm::ReceiveBuffer* rb, const std::string& ch) {
  guarded<frame_chunk_t>(*this, rb, ch, [&](const frame_chunk_t& m) { on_chunk(m); });
}
void FrameNode::on_sim_status_raw(const lcm::ReceiveBuffer* rb, const std::string& ch) {
  guarded<sim_status_t>(*this, rb, ch, [&](const sim_status_t& m) { on_sim_status(m); });
}

void FrameNode::on_checkpoint_raw(const lcm::ReceiveBuffer* rb, const std::string& ch) {
  guarded<checkpoint_t>(*this, rb, ch, [&](const checkpoint_t& m) { on_checkpoint(m); });
}

void FrameNode::handle(const Inbox::Message& m) {
  lcm::ReceiveBuffer rb{const_cast<uint8_t*>(m.data.data()), static_cast<uint32_t>(m.data.size()), m.recv_utime};
  const auto t0 = Clock::now();
  if (m.channel == kChanFrame) on_chunk_raw(&rb, m.channel);
  else if (m.channel == kChanRun) on_run_raw(&rb, m.channel);
  else if (m.channel == kChanSimStatus) on_sim_status_raw(&rb, m.channel);
  else if (m.channel == kChanCheckpoint) on_checkpoint_raw(&rb, m.channel);
  longest_handler_ = std::max(longest_handler_, std::chrono::duration<double>(Clock::now() - t0).count());
}

void FrameNode::on_run(const run_info_t& mm) {
  const run_info_t* m = &mm;
  if (info_ || (run_filter_ && m->run_id != run_filter_)) return;
  if (const std::string bad = run_info_problem(*m); !bad.empty()) return reject(kChanRun, "run info: " + bad);
  info_ = std::make_unique<run_info_t>(*m);
  assembler_.expect(m->n_particles, m->n_frames, m->chunk_particles);
  last_sim_news_ = Clock::now();
  status_.run_id = m->run_id;
  status_.frames_expected = m->n_frames;
  status_.state = "running";
  if (inbox_) inbox_->set_bound(queue_bound_bytes(m->n_particles, m->chunk_particles, inbox_->stats().hard_cap));
  // A socket buffer that holds a whole frame: the node's threads may be off
  // the CPU for as long as a frame takes to arrive (at N = 4 x 10^6 an 8
  // MiB buffer overflowed by a datagram on the 2-core machine).
  const int64_t want = frame_receive_buffer_bytes(m->n_particles, m->chunk_particles);
  const int64_t got = grow_udp_receive_buffers(want);
  std::fprintf(stderr, "%s_node: run %lld, N=%d, %d frames, %d origins x %d lags, queue of frames up to %lld MiB, "
               "socket buffer %.1f MiB\n",
               name_.c_str(), static_cast<long long>(m->run_id), m->n_particles, m->n_frames, m->n_origins,
               m->n_lags, inbox_ ? static_cast<long long>(inbox_->stats().bound >> 20) : 0LL, got / 1048576.0);
  if (got >= 0 && got / 2 < want)
    std::fprintf(stderr, "%s_node: warning: the socket buffer holds less than a frame (%.1f MiB): frames may be "
                 "lost if this node is off the CPU while one arrives; raise net.core.rmem_max or run as root\n",
                 name_.c_str(), want / 1048576.0);
  // A re-analysis: the analysis of its file in place of the recorded one
  // (what decided the frames, and so the lines above, stays the recording's).
  if (!reanalysis_origin_.empty()) {
    try {
      apply_reanalysis(*info_, reanalysis_, reanalysis_origin_);
    } catch (const std::exception& e) {
      finish(1, e.what());
      return;
    }
  }
  try {
    start(*info_); // the node may keep references into it: the copy lives as long as the node
  } catch (const std::exception& e) {
    finish(1, e.what());
    return;
  }
  started_ = true;
  // Which origins and which used (origin, lag) pairs each frame serves.
  origin_at_.assign(m->n_frames, -1);
  pairs_at_.assign(m->n_frames, {});
  last_use_.assign(m->n_origins, -1);
  for (int k = 0; k < m->n_origins; ++k) {
    origin_at_[m->origin_frame[k]] = k;
    for (int j = 0; j < m->n_lags; ++j) {
      const int f = m->pair_frame[static_cast<size_t>(k) * m->n_lags + j];
      if (f < 0 || !uses_lag(j)) continue;
      pairs_at_[f].push_back({k, j});
      last_use_[k] = std::max(last_use_[k], f);
    }
  }
  if (resume_cut_ >= 0) load_cut();
}

void FrameNode::on_chunk(const frame_chunk_t& mm) {
  const frame_chunk_t* m = &mm;
  if (!info_ || finished_ || m->run_id != info_->run_id) return;
  if (int64_t(m->n_values) != 2 * int64_t(m->count)) {
    ++status_.chunks_rejected;
    return reject(kChanFrame, "chunk: n_values is not 2 x count");
  }
  const ChunkHeader h{m->frame_index, m->time,           m->n_particles, m->chunk_index,
                      m->chunk_count, m->first_particle, m->count};
  // A cut after an earlier frame is taken before any later chunk counts.
  if (!pending_cuts_.empty() && m->frame_index > first_pending_frame()) {
    try_cut(m->frame_index);
    if (finished_) return;
  }
  const int64_t bad = assembler_.chunks_malformed();
  auto frame = assembler_.add(h, m->position.data());
  if (assembler_.chunks_malformed() > bad) {
    ++status_.chunks_rejected;
    return reject(kChanFrame, "chunk of frame " + std::to_string(m->frame_index) +
                                  " is not one of this run's (N, frame, range) or has non-finite positions");
  }
  last_sim_news_ = last_chunk_ = Clock::now();
  if (done_said_) done_said_ = Clock::now(); // frames still coming: wait on
  if (frame && frame->index < info_->n_frames) on_frame(*frame);
  maybe_done();
}

void FrameNode::on_sim_status(const sim_status_t& mm) {
  const sim_status_t* m = &mm;
  if (!info_ || m->run_id != info_->run_id || finished_) return;
  last_sim_news_ = Clock::now();
  sim_interrupted_ = m->phase == "interrupted"; // checkpointed: wait for --resume
  // The pipeline resumes as a whole from its last whole cut: a node that
  // has had the signal too stops now; else once the sim is silent (anyone
  // can say "interrupted": a live sim goes on talking).
  if (sim_interrupted_ && checkpointing() && signal_) return stop_resumable(sim_stopped_why());
  // Chunks of a frame the sim has sent stopped coming: the rest are lost
  // (the sim, pacing on this node, would otherwise wait for it).
  if (m->frames_published > 0 && std::chrono::duration<double>(Clock::now() - last_chunk_).count() > kChunkGrace) {
    const int published = std::min(m->frames_published, info_->n_frames);
    if (const int n = assembler_.give_up_before(published); n > 0) {
      std::fprintf(stderr, "%s_node: %d frame%s lost (the sim has published %d; no chunk for %.0f s)\n",
                   name_.c_str(), n, n == 1 ? "" : "s", published, kChunkGrace);
      publish_status();
    }
  }
  if (m->phase == "done") {
    // Anyone on the bus can say "done": it ends the node at once only when
    // every frame is here; else once the sim has been silent (no status, no
    // chunk) for kDoneGrace seconds after it, which a forged "done" during
    // a live run never is.
    if (!done_said_) done_said_ = Clock::now();
    maybe_done();
  } else if (done_said_) {
    done_said_.reset(); // the sim goes on: that "done" was not its own
  }
  if (m->phase == "failed") finish(1, "sim failed: " + m->message);
}

void FrameNode::maybe_done() {
  if (!done_said_ || finished_) return;
  if (assembler_.frames_whole() >= info_->n_frames) return finish(0, "");
  if (std::chrono::duration<double>(Clock::now() - *done_said_).count() > kDoneGrace) finish(0, "");
}

void FrameNode::on_frame(const Frame& f) {
  if (frame_delay_ > 0) std::this_thread::sleep_for(std::chrono::duration<double>(frame_delay_));
  const int k0 = origin_at_[f.index];
  last_frame_ = f.index;
  last_time_ = f.time;
  if (k0 >= 0) { // every origin frame is seen (clusters' g_ab uses them all), then held while needed
    origins_[k0] = f.position;
    on_origin(k0, origins_[k0]);
  }
  bool added = false;
  for (const auto& [k, j] : pairs_at_[f.index]) {
    auto it = origins_.find(k);
    if (it == origins_.end()) continue; // the origin frame was lost
    on_pair(k, j, it->second, f);
    ++pairs_done_;
    added = true;
  }
  // Drop origins no later frame needs.
  for (auto it = origins_.begin(); it != origins_.end();)
    if (last_use_[it->first] <= f.index) {
      on_origin_dropped(it->first);
      it = origins_.erase(it);
    } else {
      ++it;
    }
  if (added) publish_results(false);
  // Right away, not at the next second: the sim paces its frames on it
  // (flow control, sim_node --pace-nodes).
  publish_status();
  try_cut();
}

void FrameNode::publish_status() {
  drain_unauthenticated();
  status_.utime = utime_now();
  status_.frames_whole = assembler_.frames_whole();
  status_.frames_lost = assembler_.frames_lost();
  status_.chunks_received = assembler_.chunks_received();
  status_.pairs_done = pairs_done_;
  status_.origins_held = static_cast<int32_t>(origins_.size());
  publish(node_status_channel(name_), status_);
  last_status_ = Clock::now();
}

std::string FrameNode::sim_stopped_why() const {
  return "the sim stopped resumably" + (saved_frame_ >= -1 ? "; this node's last part is after frame " +
                                                                 std::to_string(saved_frame_)
                                                           : std::string("; this node saved no part"));
}

void FrameNode::tick() {
  watch_inbox();
  if (sim_interrupted_ && checkpointing() && !finished_ &&
      std::chrono::duration<double>(Clock::now() - last_sim_news_).count() > kDoneGrace)
    stop_resumable(sim_stopped_why());
  if (signal_ && !finished_ && std::chrono::duration<double>(Clock::now() - signalled_at_).count() > kSignalWait)
    stop_resumable("signal " + std::to_string(signal_) + ", and no last cut from the sim within " +
                   std::to_string(static_cast<int>(kSignalWait)) + " s");
  if (info_) maybe_done();
  if (finished_) return;
  if (std::chrono::duration<double>(Clock::now() - last_status_).count() >= 1.0) publish_status();
}

void FrameNode::finish(int code, const std::string& why) {
  if (info_) assembler_.finish(info_->n_frames);
  if (info_ && started_) publish_results(true);
  status_.state = code == 0 ? "done" : "failed";
  // Frames lost in a run that ended: the cause this node knows, in its
  // last status (run.h5 keeps it) and its log.
  const std::string cause = code == 0 && assembler_.frames_lost() > 0 ? loss_cause() : "";
  status_.message = cause.empty() ? why : std::to_string(assembler_.frames_lost()) + " frames lost: " + cause;
  publish_status();
  std::fprintf(stderr, "%s_node: %s: %d frames whole, %d lost%s%s\n", name_.c_str(), status_.state.c_str(),
               assembler_.frames_whole(), assembler_.frames_lost(), why.empty() ? "" : "; ", why.c_str());
  if (!cause.empty()) std::fprintf(stderr, "%s_node: frames lost: %s\n", name_.c_str(), cause.c_str());
  if (inbox_) {
    const Inbox::Stats s = inbox_->stats();
    std::fprintf(stderr, "%s_node: queue (receive thread -> computation): peak %.2f MiB of %lld MiB, %lld messages "
                 "dropped; the longest message took %.3f s\n", name_.c_str(), double(s.peak_bytes) / (1 << 20),
                 static_cast<long long>(s.bound >> 20), static_cast<long long>(s.dropped), longest_handler_);
  }
  finished_ = true;
  exit_code_ = code;
}

} // namespace dynhet
