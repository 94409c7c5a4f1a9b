#include "frame_node.hpp"

#include "dynhet/lcm_guard.hpp"
#include "dynhet/message_checks.hpp"

#include <algorithm>
#include <cstdio>

#include <CLI/CLI.hpp>

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

void FrameNode::loop_gap(double seconds) {
  if (seconds > longest_gap_) longest_gap_ = seconds;
}

std::string FrameNode::loss_cause() const {
  if (longest_gap_ > 2.0)
    return "this node took no frames for " + std::to_string(static_cast<int>(longest_gap_)) +
           " s at a stretch (stopped, starved of CPU, or busy with one frame) while frames kept coming, and its "
           "socket buffer overflowed";
  return "its socket buffer overflowed (frames came faster than this node took them; run_scene.sh's flow control "
         "prevents that, a bare sim_node without --pace-nodes does not)";
}

void FrameNode::input_ended() {
  if (finished_) return;
  if (done_said_) return finish(0, ""); // a replay that ends after the sim's "done"
  finish(1, info_ ? "input ended before the run did" : "no run info in the input");
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
  std::fprintf(stderr, "%s_node: run %lld, N=%d, %d frames, %d origins x %d lags\n", name_.c_str(),
               static_cast<long long>(m->run_id), m->n_particles, m->n_frames, m->n_origins, m->n_lags);
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
  const int64_t bad = assembler_.chunks_malformed();
  auto frame = assembler_.add(h, m->position.data());
  if (assembler_.chunks_malformed() > bad) {
    ++status_.chunks_rejected;
    return reject(kChanFrame, "chunk of frame " + std::to_string(m->frame_index) +
                                  " is not one of this run's (N, frame, range) or has non-finite positions");
  }
  last_sim_news_ = Clock::now();
  if (done_said_) done_said_ = Clock::now(); // frames still coming: wait on
  if (frame && frame->index < info_->n_frames) on_frame(*frame);
  maybe_done();
}

void FrameNode::on_sim_status(const sim_status_t& mm) {
  const sim_status_t* m = &mm;
  if (!info_ || m->run_id != info_->run_id || finished_) return;
  last_sim_news_ = Clock::now();
  sim_interrupted_ = m->phase == "interrupted"; // checkpointed: wait for --resume
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
}

void FrameNode::publish_status() {
  status_.utime = utime_now();
  status_.frames_whole = assembler_.frames_whole();
  status_.frames_lost = assembler_.frames_lost();
  status_.chunks_received = assembler_.chunks_received();
  status_.pairs_done = pairs_done_;
  status_.origins_held = static_cast<int32_t>(origins_.size());
  out_.publish(kChanNodeStatus, &status_);
  last_status_ = Clock::now();
}

void FrameNode::tick() {
  if (info_) maybe_done();
  if (finished_) return;
  if (std::chrono::duration<double>(Clock::now() - last_status_).count() >= 1.0) publish_status();
}

void FrameNode::finish(int code, const std::string& why) {
  if (info_) assembler_.finish(info_->n_frames);
  if (info_ && started_) publish_results(true);
  status_.state = code == 0 ? "done" : "failed";
  status_.message = why;
  publish_status();
  std::fprintf(stderr, "%s_node: %s: %d frames whole, %d lost%s%s\n", name_.c_str(), status_.state.c_str(),
               assembler_.frames_whole(), assembler_.frames_lost(), why.empty() ? "" : "; ", why.c_str());
  if (code == 0 && assembler_.frames_lost() > 0)
    std::fprintf(stderr, "%s_node: frames lost: %s\n", name_.c_str(), loss_cause().c_str());
  finished_ = true;
  exit_code_ = code;
}

int node_main(const std::string& program, const std::string& description, NodeFactory make_node, int argc,
              char** argv) {
  CLI::App app{description};
  std::string url, publish_url;
  int64_t run_id = 0;
  double wait_run = 300, sim_timeout = 60;
  app.add_option("--lcm-url", url, "LCM URL to read from (file://LOG?speed=0 replays a log)");
  app.add_option("--publish-url", publish_url, "LCM URL to publish on (default: the input bus)");
  app.add_option("--run-id", run_id, "only this run (default: the first one seen)");
  app.add_option("--wait-run", wait_run, "give up after this many seconds without run info");
  app.add_option("--sim-timeout", sim_timeout, "give up if the sim is silent this long (s) during a run");
  CLI11_PARSE(app, argc, argv);

  const std::string in_url = resolve_lcm_url(url);
  const bool replay = in_url.rfind("file://", 0) == 0;
  lcm::LCM in(in_url);
  std::unique_ptr<lcm::LCM> out_owned;
  if (!publish_url.empty() || replay) out_owned = std::make_unique<lcm::LCM>(resolve_lcm_url(publish_url));
  lcm::LCM& out = out_owned ? *out_owned : in;
  if (!in.good() || !out.good()) {
    std::fprintf(stderr, "%s: cannot open LCM (%s)\n", program.c_str(), in_url.c_str());
    return 3;
  }

  std::unique_ptr<FrameNode> node = make_node(out, run_id);
  in.subscribe(kChanRun, &FrameNode::on_run_raw, node.get());
  in.subscribe(kChanFrame, &FrameNode::on_chunk_raw, node.get())->setQueueCapacity(100000);
  in.subscribe(kChanSimStatus, &FrameNode::on_sim_status_raw, node.get());

  std::fprintf(stderr, "%s: ready, reading %s\n", program.c_str(), in_url.c_str());
  const auto start = FrameNode::Clock::now();
  auto last_turn = FrameNode::Clock::now();
  while (!node->finished()) {
    // A turn of this loop that took seconds: the process was stopped or
    // starved (frames lost meanwhile are then explained by it).
    const auto turn = FrameNode::Clock::now();
    node->loop_gap(std::chrono::duration<double>(turn - last_turn).count());
    last_turn = turn;
    if (in.handleTimeout(200) < 0) { // a replayed log has ended
      node->input_ended();
      break;
    }
    node->tick();
    if (!replay) node->check_sim_alive(sim_timeout);
    if (!node->has_run() && std::chrono::duration<double>(FrameNode::Clock::now() - start).count() > wait_run) {
      std::fprintf(stderr, "%s: no run info on %s within %g s\n", program.c_str(), in_url.c_str(), wait_run);
      return 4;
    }
  }
  return node->exit_code();
}

} // namespace dynhet
