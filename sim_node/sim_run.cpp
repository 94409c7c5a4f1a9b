// One run of a scene on the bus (sim_run.hpp): SimRun's steps in the order
// run() takes them.
#include "sim_run.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <thread>

#include "cut_coordinator.hpp"
#include "dynhet/chunking.hpp"
#include "dynhet/cut.hpp"
#include "dynhet/engine/engine.hpp"
#include "dynhet/frame_chunk_t.hpp"
#include "dynhet/lcm_exit.hpp"
#include "dynhet/lcm_url.hpp"
#include "dynhet/run_info_t.hpp"
#include "dynhet/schedule.hpp"
#include "dynhet/state_archive.hpp"
#include "frames.hpp"
#include "initial_state.hpp"
#include "pacer.hpp"
#include "reporter.hpp"

namespace dynhet {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// The nodes a scene starts, by their short names ("overlap", ...).
std::vector<std::string> node_names(const Scene& scene) {
  std::vector<std::string> names;
  for (const auto& n : nodes_for(scene.observables)) names.push_back(n.substr(0, n.size() - 5));
  return names;
}

class SimRun {
public:
  SimRun(const SimOptions& o, RunStart& start, int64_t run_id, lcm::LCM& lcm, const Bus& bus, bool tcpq,
         Reporter& rep, const std::atomic<int>& signal, bool& checkpoint_written);
  void run();

private:
  std::string interrupted() const { return "interrupted by signal " + std::to_string(signal_.load()); }
  void say_start() const;
  void publish_info();
  void start_state();
  void restore_cut_part();
  void compress();
  void open_cuts();
  void write_checkpoint();
  void apply_cut_reporter();
  int take_cut(bool stop, bool between = false);
  bool keep_talking();
  bool cut_due() const;
  [[noreturn]] void stop_with_cut(bool between);
  bool stop_between() const { return signal_ && cuts_ && cuts_->broken().empty(); }
  void at_slot();
  void advance(double t);
  void equilibrate();
  void produce();
  void publish_frames();
  void publish_frame(int f);
  void wait_for_open_cuts();
  void say_done(double production_seconds, double production_sim_time) const;

  const SimOptions& o_;
  const Scene& scene_;
  Checkpoint& resumed_;
  std::vector<uint8_t>& cut_part_;
  const int64_t run_id_;
  lcm::LCM& lcm_;
  const Bus& bus_;
  const bool tcpq_;
  Reporter& rep_;
  const std::atomic<int>& signal_;
  bool& checkpoint_written_;

  const engine::Params params_;
  engine::Engine eng_;
  Pacer pacer_;
  const FrameSchedule sched_;
  const double t_end_;
  run_info_t info_;
  Clock::time_point last_info_, t_wall_;
  // A cut's sim part: next frame, the reporter's phase, the next
  // synchronised slot, whether it was taken between synchronised times,
  // the engine (its State at a synchronised time; between them, on a
  // signal, its whole Snapshot), then the reporter's blocks (applied
  // after that phase's reset).
  std::string cut_phase_;
  size_t cut_reporter_at_ = 0;
  uint8_t cut_between_ = 0;
  int64_t cut_next_slot_ = -1;
  // Synchronised times k * interval (k counted from t = 0), the same in a
  // resumed run as in the uninterrupted one.
  const double interval_;
  int64_t next_slot_ = 0;
  int next_frame_ = 0;
  bool announced_ = false;
  std::unique_ptr<CutCoordinator> cuts_; // checkpoint cuts of the whole pipeline
  // Slices of a few N events (never more than 2e5): each is a sample of the
  // pressure blocks; stopping after a count of events leaves the trajectory
  // as it is.
  const int64_t slice_events_;
  // A frame in chunks, and where the production's wall time goes (the last lines of the log;
  // bench/bench_bus.py reads them).
  const std::vector<ChunkRange> ranges_;
  std::vector<double> xy_;
  frame_chunk_t chunk_{};
  double wait_seconds_ = 0, publish_seconds_ = 0, bytes_published_ = 0;
};

// The pacer listens from construction on (pacer.hpp), drained while the sim
// compresses and equilibrates.
std::vector<std::string> paced_nodes(const SimOptions& o, const Scene& scene) {
  std::vector<std::string> paced;
  if (o.pace) {
    paced = node_names(scene);
    if (scene.keep_frames) paced.push_back(kRecorderNode); // it writes every frame
  }
  return paced;
}

SimRun::SimRun(const SimOptions& o, RunStart& start, int64_t run_id, lcm::LCM& lcm, const Bus& bus, bool tcpq,
               Reporter& rep, const std::atomic<int>& signal, bool& checkpoint_written)
    : o_(o), scene_(start.scene), resumed_(start.resumed), cut_part_(start.cut_part), run_id_(run_id), lcm_(lcm),
      bus_(bus), tcpq_(tcpq), rep_(rep), signal_(signal), checkpoint_written_(checkpoint_written),
      params_(engine_params(scene_)), eng_(params_), pacer_(lcm, bus, run_id, paced_nodes(o, scene_), eng_.size()),
      sched_(make_schedule(scene_.schedule, scene_.equilibration_time)),
      t_end_(scene_.equilibration_time + scene_.production_time),
      info_(make_run_info(scene_, eng_, sched_, run_id)), interval_(scene_.checkpoint_interval),
      slice_events_(std::clamp<int64_t>(2 * eng_.size(), 500, 200000)),
      ranges_(chunk_ranges(static_cast<int>(eng_.size()), scene_.chunk_particles)) {}

void SimRun::run() {
  say_start();
  // The run info first, and again every 2 s, also while compressing (which
  // takes minutes at N = 10^5 and more): nodes and recorder then know the
  // run from the start and watch the sim's status instead of waiting blind.
  publish_info();
  rep_.msg().frames_total = info_.n_frames;
  t_wall_ = Clock::now();
  start_state();
  rep_.msg().frames_published = resumed_.next_frame;
  publish_info();
  // (A cut between synchronised times says which slot comes next.)
  next_slot_ = cut_next_slot_ >= 0 ? cut_next_slot_
                                   : static_cast<int64_t>(std::floor(eng_.time() / interval_ + 0.5)) + 1;
  next_frame_ = resumed_.next_frame;
  open_cuts();
  equilibrate();
  produce();
}

void SimRun::say_start() const {
  std::fprintf(stderr,
               "sim_node: run %lld (bus %s), N=%ld phi=%.4f eps=%.3f L=%.4f, kicks %s (%.4g per particle per "
               "unit time, pairs: %s)\n",
               static_cast<long long>(run_id_), bus_.describe(), eng_.size(), scene_.packing_fraction,
               scene_.restitution, eng_.box_length(), params_.driving && scene_.restitution < 1 ? "on" : "off",
               params_.kick_rate,
               scene_.kick_pairs == "any" ? "any two particles"
                                          : ("neighbours within " + std::to_string(scene_.kick_reach)).c_str());
}

void SimRun::publish_info() {
  info_.utime = utime_now();
  bus_.publish(lcm_, kChanRun, info_);
  last_info_ = Clock::now();
}

// The state production starts from: a cut's sim part, a checkpoint, the
// scene's initial state, or compression to the scene's packing fraction.
void SimRun::start_state() {
  if (!cut_part_.empty()) {
    restore_cut_part();
  } else if (!o_.resume_path.empty()) {
    eng_.restore(resumed_.state);
    std::fprintf(stderr, "sim_node: resumed at t=%.10g, frame %d, from %s\n", eng_.time(), resumed_.next_frame,
                 o_.resume_path.c_str());
  } else if (!scene_.initial_state.empty()) {
    start_from(eng_, scene_);
    std::fprintf(stderr, "sim_node: started from %s (max overlap %.2g)\n", scene_.initial_state.c_str(),
                 std::max(0.0, eng_.max_overlap()));
  } else {
    compress();
  }
}

void SimRun::restore_cut_part() {
  StateIn in(cut_part_.data(), cut_part_.size(), part_path(o_.cut_root, o_.resume_cut, "sim", 0));
  in(resumed_.next_frame, cut_phase_, cut_next_slot_, cut_between_);
  if (cut_between_) {
    engine::Snapshot snap;
    in(snap);
    eng_.restore_snapshot(snap);
  } else {
    engine::State st;
    in(st);
    eng_.restore(st);
  }
  cut_reporter_at_ = in.offset();
  std::fprintf(stderr, "sim_node: resumed from checkpoint cut %d at t=%.10g, next frame %d (%s)\n", o_.resume_cut,
               eng_.time(), resumed_.next_frame, cut_dir(o_.cut_root, o_.resume_cut).c_str());
}

void SimRun::compress() {
  rep_.msg().phase = "compress";
  rep_.msg().phase_end_time = 0;
  eng_.prepare([&](double) {
    rep_.update(eng_, -1);
    pacer_.poll();
    if (seconds_since(last_info_) > 2.0) publish_info();
    if (signal_) throw std::runtime_error(interrupted());
  });
  std::fprintf(stderr, "\nsim_node: compressed to phi=%.4f in %.1f s, max overlap %.2g\n", eng_.packing_fraction(),
               seconds_since(t_wall_), std::max(0.0, eng_.max_overlap()));
}

// Checkpoint cuts of the whole pipeline: the sim, each node, the recorder.
void SimRun::open_cuts() {
  if (!o_.cut_root.empty()) {
    std::vector<std::string> parts{"sim"};
    for (const auto& n : node_names(scene_)) parts.push_back(n);
    parts.push_back(kRecorderNode);
    cuts_ = std::make_unique<CutCoordinator>(lcm_, bus_, o_.cut_root, run_id_, scene_.text, parts);
  }
  rep_.count_unauthenticated([this] { return pacer_.unauthenticated() + (cuts_ ? cuts_->unauthenticated() : 0); });
}

void SimRun::write_checkpoint() {
  const Checkpoint c{scene_.text, run_id_, next_frame_, scene_.kick_pairs, eng_.state()};
  dynhet::write_checkpoint(o_.checkpoint_path, c);
  if (next_frame_ == 0 && !o_.before_frames_path.empty()) dynhet::write_checkpoint(o_.before_frames_path, c);
  checkpoint_written_ = true;
}

// After a phase's reset: a resumed run's blocks, if its cut was taken in
// this phase (a cut at the end of equilibration belongs to it: the
// production starts afresh, as in the uninterrupted run).
void SimRun::apply_cut_reporter() {
  if (cut_part_.empty()) return;
  if (cut_phase_ == rep_.msg().phase) {
    StateIn in(cut_part_.data() + cut_reporter_at_, cut_part_.size() - cut_reporter_at_, "the sim part");
    in(rep_);
  }
  cut_part_.clear();
}

// A cut after the last frame published: at a synchronised time the
// engine's State; between synchronised times (`between`, on a signal) its
// whole Snapshot, from which the run goes on as if never stopped.
int SimRun::take_cut(bool stop, bool between) {
  const auto t0 = Clock::now();
  StateOut out;
  std::string phase = rep_.msg().phase;
  uint8_t kind = between ? 1 : 0;
  out(next_frame_, phase, next_slot_, kind);
  if (between) {
    engine::Snapshot snap = eng_.snapshot();
    out.reserve(snap.bytes() + 4096);
    out(snap);
  } else {
    engine::State st = eng_.state();
    out(st);
  }
  out(rep_);
  const double serialised = seconds_since(t0);
  const int c = cuts_->take(next_frame_ - 1, eng_.time(), out.bytes(), stop);
  if (c < 0) return c; // cuts are off (said once)
  std::fprintf(stderr, "%ssim_node: checkpoint: cut %d after frame %d at t=%.10g (sim part %.1f MB in %.2f s, "
               "%.2f s of it to serialise)\n",
               isatty(STDERR_FILENO) ? "\n" : "", c, next_frame_ - 1, eng_.time(), out.bytes().size() / 1e6,
               seconds_since(t0), serialised);
  return c;
}

// While waiting for a cut to be whole the sim goes on publishing its
// status (once a second): the nodes that have saved it wait for the sim,
// and give up on one silent for their --sim-timeout (a slow or starved
// node or recorder can take longer than that to catch up).
bool SimRun::keep_talking() {
  rep_.update(eng_, t_end_ - eng_.time());
  return false;
}

bool SimRun::cut_due() const {
  return cuts_ && cuts_->broken().empty() &&
         (signal_ || scene_.checkpoint_wall_interval <= 0 ||
          cuts_->seconds_since_take() >= scene_.checkpoint_wall_interval);
}

// On a signal: the last cut, stop = true, then wait until it is whole and
// end (throws). `between`: the engine stands between synchronised times
// (after a slice of events, or at a frame's time), and its whole snapshot
// is the sim's part: a stop takes seconds, not the wall time to the next
// synchronised time (docs/checkpoints.md).
void SimRun::stop_with_cut(bool between) {
  checkpoint_written_ = true;
  int c = -1;
  try {
    c = take_cut(true, between);
  } catch (const std::exception& e) { // a full disk, say: the last whole cut stays the restart point
    std::fprintf(stderr, "\nsim_node: checkpoint cut not taken: %s\n", e.what());
  }
  const int before = cuts_->last_whole();
  const auto t_wait = Clock::now();
  if (c >= 0 && cuts_->wait_whole(c, o_.cut_wait, [this] { return keep_talking(); })) {
    char waited[64];
    std::snprintf(waited, sizeof waited, "%.2f", seconds_since(t_wait));
    throw std::runtime_error(interrupted() + "; checkpoint cut " + std::to_string(c) + " after frame " +
                             std::to_string(next_frame_ - 1) + " (t=" + std::to_string(eng_.time()) +
                             ") is whole, " + waited + " s after the sim's part: the same command resumes the run");
  }
  throw std::runtime_error(interrupted() + "; the last cut was not whole within " + std::to_string(o_.cut_wait) +
                           " s: the run resumes from cut " + std::to_string(before));
}

// At a synchronised time: the checkpoint and the cut due there; on a
// signal, the end of the run.
void SimRun::at_slot() {
  eng_.synchronize();
  ++next_slot_;
  if (!o_.checkpoint_path.empty()) write_checkpoint();
  if (cut_due()) {
    if (signal_) stop_with_cut(false);
    try {
      take_cut(false);
    } catch (const std::exception& e) { // a full disk, say: the last whole cut stays the restart point
      std::fprintf(stderr, "\nsim_node: checkpoint cut not taken: %s\n", e.what());
    }
  }
  if (signal_)
    throw std::runtime_error(interrupted() + (o_.checkpoint_path.empty()
                                                  ? ""
                                                  : "; checkpoint at t=" + std::to_string(eng_.time()) + " in " +
                                                        o_.checkpoint_path + ", continue with sim_node --resume " +
                                                        o_.checkpoint_path));
}

// Advance to time t in slices, so that status and run info go out and
// signals are seen at least once a second; synchronise (and checkpoint) at
// every slot on the way.
void SimRun::advance(double t) {
  for (;;) {
    const double slot = next_slot_ * interval_;
    const double target = std::min(t, slot);
    while (!eng_.run_until(target, slice_events_)) {
      rep_.update(eng_, t_end_ - eng_.time());
      if (tcpq_ && bus_lost(lcm_)) throw std::runtime_error(kBusLost);
      if (seconds_since(last_info_) > 2.0) publish_info();
      pacer_.poll();
      if (cuts_) cuts_->poll();
      if (signal_ && o_.checkpoint_path.empty() && !cuts_) throw std::runtime_error(interrupted());
      if (stop_between()) {
        std::fprintf(stderr, "\nsim_node: signal %d: a checkpoint cut at t=%.10g, between synchronised times\n",
                     signal_.load(), eng_.time());
        stop_with_cut(true);
      }
      if (signal_ && !announced_) {
        std::fprintf(stderr, "\nsim_node: signal %d: running on to t=%g to write a checkpoint\n", signal_.load(),
                     slot);
        announced_ = true;
      }
    }
    if (target == slot) at_slot();
    if (target == t) break;
  }
  rep_.update(eng_, t_end_ - eng_.time());
}

void SimRun::equilibrate() {
  // A cut taken between synchronised times in equilibration resumes it
  // (even if its last event fell on the phase's end exactly).
  if (eng_.time() < scene_.equilibration_time || (cut_between_ && cut_phase_ == "equilibrate")) {
    rep_.msg().phase = "equilibrate";
    rep_.msg().phase_end_time = scene_.equilibration_time;
    rep_.reset_rates(eng_, scene_.equilibration_time - eng_.time());
    apply_cut_reporter();
    advance(scene_.equilibration_time);
  }
}

// The production: the frames, the rest of its time, and the end of the run.
void SimRun::produce() {
  rep_.msg().phase = "production";
  rep_.msg().phase_end_time = t_end_;
  rep_.reset_rates(eng_, t_end_ - eng_.time());
  apply_cut_reporter();
  chunk_.run_id = run_id_;
  chunk_.n_particles = static_cast<int32_t>(eng_.size());
  chunk_.chunk_count = static_cast<int32_t>(ranges_.size());
  pacer_.start_production();
  const auto t_production = Clock::now();
  const double sim_t_production = eng_.time();
  publish_frames();
  advance(t_end_);
  wait_for_open_cuts();
  const double production_seconds = seconds_since(t_production);
  if (!o_.checkpoint_path.empty()) {
    eng_.synchronize();
    write_checkpoint();
  }
  rep_.msg().phase = "done";
  rep_.msg().eta_seconds = 0;
  publish_info();
  for (int i = 0; i < 3; ++i) {
    rep_.update(eng_, 0, true);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  say_done(production_seconds, t_end_ - sim_t_production);
}

// The frames of the schedule still to come, each when the paced nodes have
// caught up.
void SimRun::publish_frames() {
  for (int f = next_frame_; f < info_.n_frames; ++f) {
    for (double slept = 0; slept < o_.test_frame_delay && !signal_; slept += 0.01) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      if (cuts_) cuts_->poll();
    }
    advance(sched_.frame_time[f]);
    // A signal seen at frame f's time, f not yet published (at small N a
    // frame may come sooner than a slice ends): the cut after f - 1.
    auto stop_before_frame = [&] {
      std::fprintf(stderr, "\nsim_node: signal %d: a checkpoint cut at t=%.10g, before frame %d\n", signal_.load(),
                   eng_.time(), f);
      stop_with_cut(true);
    };
    if (stop_between()) stop_before_frame();
    const auto t_wait = Clock::now();
    pacer_.before_frame(f, [&] {
      if (seconds_since(last_info_) > 2.0) publish_info();
      if (cuts_) cuts_->poll();
      rep_.update(eng_, t_end_ - eng_.time());
      if (stop_between()) stop_before_frame();
      if (signal_) throw std::runtime_error(interrupted());
    });
    wait_seconds_ += seconds_since(t_wait);
    if (tcpq_ && bus_lost(lcm_)) throw std::runtime_error(kBusLost);
    publish_frame(f);
  }
}

void SimRun::publish_frame(int f) {
  const auto t_publish = Clock::now();
  eng_.unwrapped_positions(xy_);
#ifndef NDEBUG
  // Debug builds: a full overlap scan at every frame.
  if (const double ov = eng_.max_overlap(); ov > 1e-9)
    throw std::runtime_error("overlap " + std::to_string(ov) + " of a contact distance at t=" +
                             std::to_string(eng_.time()));
#endif
  dynhet::publish_frame(lcm_, bus_, chunk_, ranges_, f, sched_.frame_time[f], xy_);
  publish_seconds_ += seconds_since(t_publish);
  bytes_published_ += 16.0 * static_cast<double>(eng_.size());
  rep_.msg().frames_published = next_frame_ = f + 1;
}

// The cuts still open are whole once the nodes have caught up: a run that
// dies after the sim ends then loses nothing the sim did.
void SimRun::wait_for_open_cuts() {
  if (cuts_ && cuts_->newest_open() >= 0 &&
      !cuts_->wait_whole(cuts_->newest_open(), o_.cut_wait, [this] { return keep_talking() || signal_ != 0; })) {
    if (signal_) {
      checkpoint_written_ = true;
      throw std::runtime_error(interrupted() + " after the last frame; the run resumes from cut " +
                               std::to_string(cuts_->last_whole()));
    }
    std::fprintf(stderr, "\nsim_node: the last checkpoint cut was not whole within %g s (--cut-wait)\n", o_.cut_wait);
  }
}

void SimRun::say_done(double production_seconds, double production_sim_time) const {
  double px, py;
  eng_.momentum(px, py);
  const auto& c = eng_.counters();
  std::fprintf(stderr,
               "\nsim_node: done in %.1f s: %lld collisions, %lld kicks (first particles drawn again %lld times, "
               "%lld pairs from the whole system), %d frames, KE/N=%.4f, "
               "total momentum (%.2g, %.2g), max overlap %.2g\n"
               "sim_node: production: Z = %.5g +- %.2g, collisions per particle per unit time %.5g +- %.2g%s, "
               "TC model acted %lld times\n",
               seconds_since(t_wall_), static_cast<long long>(c.collisions), static_cast<long long>(c.kicks),
               static_cast<long long>(c.kick_redraws), static_cast<long long>(c.kick_far), info_.n_frames,
               eng_.kinetic_energy_per_particle(), px, py, std::max(0.0, eng_.max_overlap()),
               rep_.msg().reduced_pressure, rep_.msg().reduced_pressure_err, rep_.msg().collision_frequency,
               rep_.msg().collision_frequency_err,
               rep_.blocks() < 2 ? " (no error: the production was shorter than two fine blocks)" : "",
               static_cast<long long>(c.tc));
  std::fprintf(stderr,
               "sim_node: production wall time %.2f s for %.6g time units: %.2f s waiting for paced nodes, "
               "%.2f s publishing %.1f MB of frames (%.1f MB/s while publishing, copies and pauses between chunks "
               "included)\n",
               production_seconds, production_sim_time, wait_seconds_, publish_seconds_, bytes_published_ / 1e6,
               publish_seconds_ > 0 ? bytes_published_ / 1e6 / publish_seconds_ : 0.0);
}

} // namespace

int run_on_bus(const SimOptions& o, RunStart& start, int64_t run_id, lcm::LCM& lcm, const Bus& bus,
               const std::string& bus_url, const std::atomic<int>& signal) {
  Reporter rep(lcm, bus, run_id, isatty(STDERR_FILENO));
  bool checkpoint_written = !o.resume_path.empty();
  int code = 0;
  try {
    SimRun(o, start, run_id, lcm, bus, is_tcpq_url(bus_url), rep, signal, checkpoint_written).run();
  } catch (const std::exception& e) {
    if (signal && checkpoint_written) rep.msg().phase = "interrupted"; // nodes wait for --resume
    if (rep.msg().phase != "interrupted") rep.msg().phase = "failed";
    rep.msg().message = e.what();
    rep.msg().utime = utime_now();
    for (int i = 0; i < 3; ++i) bus.publish(lcm, kChanSimStatus, rep.msg());
    std::fprintf(stderr, "\nsim_node: %s\n", e.what());
    code = signal ? 128 + signal : 1;
  }
  // The last frames and the "done" (or "failed") reach the bus before the
  // process ends (tcpq: dynhet/lcm_exit.hpp).
  if (const std::string why = deliver_before_exit(lcm, bus_url); !why.empty())
    std::fprintf(stderr, "sim_node: %s\n", why.c_str());
  return code;
}

} // namespace dynhet
