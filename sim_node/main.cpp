// sim_node: runs a scene's EDMD simulation and publishes, over LCM, the run
// info, a status at least once a second, and the frames the scene's
// observables need (in chunks).
// Usage: sim_node SCENE.toml [--lcm-url URL] [--checkpoint FILE.h5]
//        sim_node --resume FILE.h5 [--checkpoint FILE.h5]
// With --checkpoint, a checkpoint is written at every multiple of the
// scene's run.checkpoint_interval and at the end. SIGINT/SIGTERM: with
// checkpoint cuts (--checkpoint-dir), a cut of the whole engine as it is
// (at most one slice of events later) and exit; without them, run on to
// the next synchronised time, write the checkpoint and exit (status 128 +
// signal).
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <iostream>
#include <cstdio>
#include <map>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <unistd.h>

#include <lcm/lcm-cpp.hpp>

#include "checkpoint.hpp"
#include "options.hpp"
#include "frames.hpp"
#include "pacer.hpp"
#include "reporter.hpp"
#include "cut_coordinator.hpp"
#include "initial_state.hpp"
#include "scene_report.hpp"
#include "dynhet/bus.hpp"
#include "dynhet/bus_cli.hpp"
#include "dynhet/cut.hpp"
#include "dynhet/state_archive.hpp"
#include "dynhet/chunking.hpp"
#include "dynhet/engine/engine.hpp"
#include "dynhet/flow_control.hpp"
#include "dynhet/frame_chunk_t.hpp"
#include "dynhet/lcm_exit.hpp"
#include "dynhet/lcm_guard.hpp"
#include "dynhet/node_status_t.hpp"
#include "dynhet/lcm_url.hpp"
#include "dynhet/model.hpp"
#include "dynhet/run_info_t.hpp"
#include "dynhet/scene.hpp"
#include "dynhet/schedule.hpp"
#include "dynhet/sim_status_t.hpp"
#include "dynhet/stats.hpp"

namespace {

using dynhet::hms;
using dynhet::Pacer;
using dynhet::Reporter;
using dynhet::utime_now;

std::atomic<int> g_signal{0};
void on_signal(int s) { g_signal = s; }

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}


} // namespace

int main(int argc, char** argv) {
  dynhet::SimOptions o;
  if (const int rc = dynhet::parse_sim_options(argc, argv, o); rc >= 0) return rc;
  std::string &scene_path = o.scene_path, &url = o.url, &checkpoint_path = o.checkpoint_path,
              &resume_path = o.resume_path, &before_frames_path = o.before_frames_path,
              &prepare_path = o.prepare_path, &cut_root = o.cut_root;
  int64_t& run_id = o.run_id;
  const bool equilibrate = o.equilibrate, pace = o.pace, check = o.check, find_cut = o.find_cut;
  const int resume_cut = o.resume_cut;
  const double cut_wait = o.cut_wait, test_frame_delay = o.test_frame_delay;
  const dynhet::BusOptions& bus_options = o.bus;

  if (o.scene_reference) {
    std::fputs(dynhet::scene_reference_markdown().c_str(), stdout);
    return 0;
  }
  if (scene_path.empty() == resume_path.empty()) {
    std::fprintf(stderr, "sim_node: give either a scene file or --resume CHECKPOINT\n");
    return 2;
  }
  dynhet::Scene scene;
  dynhet::Checkpoint resumed;
  try {
    if (!resume_path.empty()) {
      resumed = dynhet::read_checkpoint(resume_path);
      scene = dynhet::parse_scene_text(resumed.scene_toml, resume_path + " (its scene)");
      run_id = resumed.run_id;
      scene_path = resume_path;
      if (resumed.kick_pairs != scene.kick_pairs)
        throw std::runtime_error(resume_path + ": the run drew kick pairs by the rule \"" + resumed.kick_pairs +
                                 "\", its scene now means \"" + scene.kick_pairs +
                                 "\" (a checkpoint from before driving.pairs): it cannot be resumed bit for bit; "
                                 "start the run again");
    } else if (scene_path == "-") {
      std::stringstream text;
      text << std::cin.rdbuf();
      scene = dynhet::parse_scene_text(text.str(), "<stdin>");
    } else {
      scene = dynhet::parse_scene_file(scene_path);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sim_node: %s\n", e.what());
    return 2;
  }
  if (find_cut) {
    if (cut_root.empty()) {
      std::fprintf(stderr, "sim_node: --find-cut needs --checkpoint-dir\n");
      return 2;
    }
    std::vector<std::string> refused;
    const auto c = dynhet::latest_whole_cut(cut_root, dynhet::scene_hash(scene.text), refused);
    for (const std::string& r : refused) std::fprintf(stderr, "sim_node: %s\n", r.c_str());
    if (!c) return 1;
    std::printf("cut %d frame %d time %.17g run_id %lld\n", c->cut, c->frame, c->sim_time,
                static_cast<long long>(c->run_id));
    return 0;
  }
  // A cut's sim part: the run id comes from it.
  std::vector<uint8_t> cut_part;
  if (resume_cut >= 0) {
    try {
      if (cut_root.empty()) throw std::runtime_error("--resume-cut needs --checkpoint-dir");
      dynhet::PartHeader h;
      cut_part = dynhet::read_part(dynhet::part_path(cut_root, resume_cut, "sim", 0), "sim", 0,
                                   dynhet::scene_hash(scene.text), &h);
      if (run_id != 0 && run_id != h.run_id)
        throw std::runtime_error("cut " + std::to_string(resume_cut) + " is of run " + std::to_string(h.run_id) +
                                 ", not --run-id " + std::to_string(run_id));
      run_id = h.run_id;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "sim_node: cannot resume: %s\n", e.what());
      return 2;
    }
  }
  if (check) return dynhet::report_check(scene, scene_path);
  if (o.resolved) return dynhet::report_resolved(scene);
  for (const auto& note : scene.notes) std::fprintf(stderr, "sim_node: note: %s\n", note.c_str());
  // Where a scene's initial_state is: relative to the scene file.
  if (!scene.initial_state.empty() && scene.initial_state[0] != '/' && resume_path.empty()) {
    const auto slash = scene_path.find_last_of('/');
    if (slash != std::string::npos) scene.initial_state = scene_path.substr(0, slash + 1) + scene.initial_state;
  }
  if (equilibrate && prepare_path.empty()) {
    std::fprintf(stderr, "sim_node: --equilibrate goes with --prepare-only FILE\n");
    return 2;
  }
  if (!prepare_path.empty()) {
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    return dynhet::prepare_only(scene, prepare_path, equilibrate, g_signal);
  }
  if (run_id == 0) run_id = static_cast<int64_t>(std::random_device{}() & 0x7fffffff) << 20 ^ getpid();

  const std::optional<dynhet::Bus> bus_or = dynhet::bus_or_say("sim_node", bus_options);
  if (!bus_or) return 2;
  const dynhet::Bus& bus = *bus_or;
  const std::string bus_url = dynhet::resolve_lcm_url(url);
  lcm::LCM lcm(bus_url);
  const bool tcpq = dynhet::is_tcpq_url(bus_url);
  if (dynhet::bus_unreachable(lcm, bus_url)) {
    std::fprintf(stderr, "sim_node: cannot open LCM at %s\n", bus_url.c_str());
    return 3;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  Reporter rep(lcm, bus, run_id, isatty(STDERR_FILENO));
  auto fail = [&](const std::string& why) {
    if (rep.msg().phase != "interrupted") rep.msg().phase = "failed";
    rep.msg().message = why;
    rep.msg().utime = utime_now();
    for (int i = 0; i < 3; ++i) bus.publish(lcm, dynhet::kChanSimStatus, rep.msg());
    std::fprintf(stderr, "\nsim_node: %s\n", why.c_str());
  };

  bool checkpoint_written = !resume_path.empty();
  int code = 0;
  try {
    const dynhet::engine::Params p = dynhet::engine_params(scene);
    dynhet::engine::Engine eng(p);
    std::fprintf(stderr,
                 "sim_node: run %lld (bus %s), N=%ld phi=%.4f eps=%.3f L=%.4f, kicks %s (%.4g per particle per "
                 "unit time, pairs: %s)\n",
                 static_cast<long long>(run_id), bus.describe(), eng.size(), scene.packing_fraction, scene.restitution,
                 eng.box_length(), p.driving && scene.restitution < 1 ? "on" : "off", p.kick_rate,
                 scene.kick_pairs == "any" ? "any two particles"
                                           : ("neighbours within " + std::to_string(scene.kick_reach)).c_str());

    // The pacer listens from here on (pacer.hpp), drained while the sim
    // compresses and equilibrates.
    std::vector<std::string> paced;
    if (pace) {
      for (const auto& n : dynhet::nodes_for(scene.observables)) paced.push_back(n.substr(0, n.size() - 5));
      if (scene.keep_frames) paced.push_back(dynhet::kRecorderNode); // it writes every frame
    }
    Pacer pacer(lcm, bus, run_id, paced, eng.size());

    // The run info first, and again every 2 s, also while compressing (which
    // takes minutes at N = 10^5 and more): nodes and recorder then know the
    // run from the start and watch the sim's status instead of waiting blind.
    const dynhet::FrameSchedule sched = dynhet::make_schedule(scene.schedule, scene.equilibration_time);
    const double t_end = scene.equilibration_time + scene.production_time;
    dynhet::run_info_t info = dynhet::make_run_info(scene, eng, sched, run_id);
    auto last_info = Clock::now();
    auto publish_info = [&] {
      info.utime = utime_now();
      bus.publish(lcm, dynhet::kChanRun, info);
      last_info = Clock::now();
    };
    publish_info();
    rep.msg().frames_total = info.n_frames;

    const auto t_wall = Clock::now();
    // A cut's sim part: next frame, the reporter's phase, the next
    // synchronised slot, whether it was taken between synchronised times,
    // the engine (its State at a synchronised time; between them, on a
    // signal, its whole Snapshot), then the reporter's blocks (applied
    // after that phase's reset below).
    std::string cut_phase;
    size_t cut_reporter_at = 0;
    uint8_t cut_between = 0;
    int64_t cut_next_slot = -1;
    if (!cut_part.empty()) {
      dynhet::StateIn in(cut_part.data(), cut_part.size(), dynhet::part_path(cut_root, resume_cut, "sim", 0));
      in(resumed.next_frame, cut_phase, cut_next_slot, cut_between);
      if (cut_between) {
        dynhet::engine::Snapshot snap;
        in(snap);
        eng.restore_snapshot(snap);
      } else {
        dynhet::engine::State st;
        in(st);
        eng.restore(st);
      }
      cut_reporter_at = in.offset();
      std::fprintf(stderr, "sim_node: resumed from checkpoint cut %d at t=%.10g, next frame %d (%s)\n", resume_cut,
                   eng.time(), resumed.next_frame, dynhet::cut_dir(cut_root, resume_cut).c_str());
    } else if (!resume_path.empty()) {
      eng.restore(resumed.state);
      std::fprintf(stderr, "sim_node: resumed at t=%.10g, frame %d, from %s\n", eng.time(),
                   resumed.next_frame, resume_path.c_str());
    } else if (!scene.initial_state.empty()) {
      dynhet::start_from(eng, scene);
      std::fprintf(stderr, "sim_node: started from %s (max overlap %.2g)\n", scene.initial_state.c_str(),
                   std::max(0.0, eng.max_overlap()));
    } else {
      // Compression to the scene's packing fraction.
      rep.msg().phase = "compress";
      rep.msg().phase_end_time = 0;
      eng.prepare([&](double) {
        rep.update(eng, -1);
        pacer.poll();
        if (seconds_since(last_info) > 2.0) publish_info();
        if (g_signal) throw std::runtime_error("interrupted by signal " + std::to_string(g_signal.load()));
      });
      std::fprintf(stderr, "\nsim_node: compressed to phi=%.4f in %.1f s, max overlap %.2g\n",
                   eng.packing_fraction(), seconds_since(t_wall), std::max(0.0, eng.max_overlap()));
    }

    rep.msg().frames_published = resumed.next_frame;
    publish_info();

    // Synchronised times k * interval (k counted from t = 0), the same in a
    // resumed run as in the uninterrupted one.
    const double interval = scene.checkpoint_interval;
    // (A cut between synchronised times says which slot comes next.)
    int64_t next_slot = cut_next_slot >= 0 ? cut_next_slot
                                           : static_cast<int64_t>(std::floor(eng.time() / interval + 0.5)) + 1;
    int next_frame = resumed.next_frame;
    auto checkpoint = [&] {
      const dynhet::Checkpoint c{scene.text, run_id, next_frame, scene.kick_pairs, eng.state()};
      dynhet::write_checkpoint(checkpoint_path, c);
      if (next_frame == 0 && !before_frames_path.empty()) dynhet::write_checkpoint(before_frames_path, c);
      checkpoint_written = true;
    };
    bool announced = false;
    // After a phase's reset: a resumed run's blocks, if its cut was taken in
    // this phase (a cut at the end of equilibration belongs to it: the
    // production starts afresh, as in the uninterrupted run).
    auto apply_cut_reporter = [&] {
      if (cut_part.empty()) return;
      if (cut_phase == rep.msg().phase) {
        dynhet::StateIn in(cut_part.data() + cut_reporter_at, cut_part.size() - cut_reporter_at, "the sim part");
        in(rep);
      }
      cut_part.clear();
    };
    // Checkpoint cuts of the whole pipeline: the sim, each node, the recorder.
    std::unique_ptr<dynhet::CutCoordinator> cuts;
    if (!cut_root.empty()) {
      std::vector<std::string> parts{"sim"};
      for (const auto& n : dynhet::nodes_for(scene.observables)) parts.push_back(n.substr(0, n.size() - 5));
      parts.push_back(dynhet::kRecorderNode);
      cuts = std::make_unique<dynhet::CutCoordinator>(lcm, bus, cut_root, run_id, scene.text, parts);
    }
    rep.count_unauthenticated([&] { return pacer.unauthenticated() + (cuts ? cuts->unauthenticated() : 0); });
    // A cut after the last frame published: at a synchronised time the
    // engine's State; between synchronised times (`between`, on a signal)
    // its whole Snapshot, from which the run goes on as if never stopped.
    auto take_cut = [&](bool stop, bool between = false) {
      const auto t0 = Clock::now();
      dynhet::StateOut out;
      std::string phase = rep.msg().phase;
      uint8_t kind = between ? 1 : 0;
      out(next_frame, phase, next_slot, kind);
      if (between) {
        dynhet::engine::Snapshot snap = eng.snapshot();
        out.reserve(snap.bytes() + 4096);
        out(snap);
      } else {
        dynhet::engine::State st = eng.state();
        out(st);
      }
      out(rep);
      const int c = cuts->take(next_frame - 1, eng.time(), out.bytes(), stop);
      if (c < 0) return c; // cuts are off (said once)
      std::fprintf(stderr, "%ssim_node: checkpoint: cut %d after frame %d at t=%.10g (sim part %.1f MB in %.2f s)\n",
                   isatty(STDERR_FILENO) ? "\n" : "", c, next_frame - 1, eng.time(), out.bytes().size() / 1e6,
                   seconds_since(t0));
      return c;
    };
    // While waiting for a cut to be whole the sim goes on publishing its
    // status (once a second): the nodes that have saved it wait for the sim,
    // and give up on one silent for their --sim-timeout (a slow or starved
    // node or recorder can take longer than that to catch up).
    auto keep_talking = [&] {
      rep.update(eng, t_end - eng.time());
      return false;
    };
    auto cut_due = [&] {
      return cuts && cuts->broken().empty() && (g_signal || scene.checkpoint_wall_interval <= 0 ||
                      cuts->seconds_since_take() >= scene.checkpoint_wall_interval);
    };
    // On a signal: the last cut, stop = true, then wait until it is whole and
    // end (throws). `between`: the engine stands between synchronised times
    // (after a slice of events, or at a frame's time), and its whole
    // snapshot is the sim's part: a stop takes seconds, not the wall time
    // to the next synchronised time (docs/checkpoints.md).
    auto stop_with_cut = [&](bool between) {
      checkpoint_written = true;
      int c = -1;
      try {
        c = take_cut(true, between);
      } catch (const std::exception& e) { // a full disk, say: the last whole cut stays the restart point
        std::fprintf(stderr, "\nsim_node: checkpoint cut not taken: %s\n", e.what());
      }
      const int before = cuts->last_whole();
      if (c >= 0 && cuts->wait_whole(c, cut_wait, keep_talking))
        throw std::runtime_error("interrupted by signal " + std::to_string(g_signal.load()) + "; checkpoint cut " +
                                 std::to_string(c) + " after frame " + std::to_string(next_frame - 1) +
                                 " (t=" + std::to_string(eng.time()) + ") is whole: the same command resumes the run");
      throw std::runtime_error("interrupted by signal " + std::to_string(g_signal.load()) +
                               "; the last cut was not whole within " + std::to_string(cut_wait) +
                               " s: the run resumes from cut " + std::to_string(before));
    };
    auto stop_between = [&] { return g_signal && cuts && cuts->broken().empty(); };

    // Advance to time t in slices, so that status and run info go out and
    // signals are seen at least once a second; synchronise (and checkpoint)
    // at every slot on the way.
    // Slices of a few N events (never more than 2e5): each is a sample of
    // the pressure blocks; stopping after a count of events leaves the
    // trajectory as it is.
    const int64_t slice_events = std::clamp<int64_t>(2 * eng.size(), 500, 200000);
    auto advance = [&](double t) {
      for (;;) {
        const double slot = next_slot * interval;
        const double target = std::min(t, slot);
        while (!eng.run_until(target, slice_events)) {
          rep.update(eng, t_end - eng.time());
          if (tcpq && dynhet::bus_lost(lcm)) throw std::runtime_error(dynhet::kBusLost);
          if (seconds_since(last_info) > 2.0) publish_info();
          pacer.poll();
          if (cuts) cuts->poll();
          if (g_signal && checkpoint_path.empty() && !cuts)
            throw std::runtime_error("interrupted by signal " + std::to_string(g_signal.load()));
          if (stop_between()) {
            std::fprintf(stderr, "\nsim_node: signal %d: a checkpoint cut at t=%.10g, between synchronised times\n",
                         g_signal.load(), eng.time());
            stop_with_cut(true);
          }
          if (g_signal && !announced) {
            std::fprintf(stderr, "\nsim_node: signal %d: running on to t=%g to write a checkpoint\n",
                         g_signal.load(), slot);
            announced = true;
          }
        }
        if (target == slot) {
          eng.synchronize();
          ++next_slot;
          if (!checkpoint_path.empty()) checkpoint();
          if (cut_due()) {
            if (g_signal) stop_with_cut(false);
            try {
              take_cut(false);
            } catch (const std::exception& e) { // a full disk, say: the last whole cut stays the restart point
              std::fprintf(stderr, "\nsim_node: checkpoint cut not taken: %s\n", e.what());
            }
          }
          if (g_signal) throw std::runtime_error("interrupted by signal " + std::to_string(g_signal.load()) +
                                                 (checkpoint_path.empty() ? "" : "; checkpoint at t=" +
                                                  std::to_string(eng.time()) + " in " + checkpoint_path +
                                                  ", continue with sim_node --resume " + checkpoint_path));
        }
        if (target == t) break;
      }
      rep.update(eng, t_end - eng.time());
    };

    // A cut taken between synchronised times in equilibration resumes it
    // (even if its last event fell on the phase's end exactly).
    if (eng.time() < scene.equilibration_time || (cut_between && cut_phase == "equilibrate")) {
      rep.msg().phase = "equilibrate";
      rep.msg().phase_end_time = scene.equilibration_time;
      rep.reset_rates(eng, scene.equilibration_time - eng.time());
      apply_cut_reporter();
      advance(scene.equilibration_time);
    }

    rep.msg().phase = "production";
    rep.msg().phase_end_time = t_end;
    rep.reset_rates(eng, t_end - eng.time());
    apply_cut_reporter();
    const auto ranges = dynhet::chunk_ranges(static_cast<int>(eng.size()), scene.chunk_particles);
    std::vector<double> xy;
    dynhet::frame_chunk_t chunk{};
    chunk.run_id = run_id;
    chunk.n_particles = static_cast<int32_t>(eng.size());
    chunk.chunk_count = static_cast<int32_t>(ranges.size());
    pacer.start_production();
    // Where the production's wall time goes (the last lines of the log;
    // bench/bench_bus.py reads them): simulating, waiting for paced nodes,
    // publishing frames.
    const auto t_production = Clock::now();
    const double sim_t_production = eng.time();
    double wait_seconds = 0, publish_seconds = 0, bytes_published = 0;
    for (int f = next_frame; f < info.n_frames; ++f) {
      for (double slept = 0; slept < test_frame_delay && !g_signal; slept += 0.01) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
        if (cuts) cuts->poll();
      }
      advance(sched.frame_time[f]);
      // A signal seen at frame f's time, f not yet published (at small N a
      // frame may come sooner than a slice ends): the cut after f - 1.
      auto stop_before_frame = [&] {
        std::fprintf(stderr, "\nsim_node: signal %d: a checkpoint cut at t=%.10g, before frame %d\n",
                     g_signal.load(), eng.time(), f);
        stop_with_cut(true);
      };
      if (stop_between()) stop_before_frame();
      const auto t_wait = Clock::now();
      pacer.before_frame(f, [&] {
        if (seconds_since(last_info) > 2.0) publish_info();
        if (cuts) cuts->poll();
        rep.update(eng, t_end - eng.time());
        if (stop_between()) stop_before_frame();
        if (g_signal) throw std::runtime_error("interrupted by signal " + std::to_string(g_signal.load()));
      });
      wait_seconds += seconds_since(t_wait);
      if (tcpq && dynhet::bus_lost(lcm)) throw std::runtime_error(dynhet::kBusLost);
      const auto t_publish = Clock::now();
      eng.unwrapped_positions(xy);
#ifndef NDEBUG
      // Debug builds: a full overlap scan at every frame.
      if (const double ov = eng.max_overlap(); ov > 1e-9)
        throw std::runtime_error("overlap " + std::to_string(ov) + " of a contact distance at t=" +
                                 std::to_string(eng.time()));
#endif
      dynhet::publish_frame(lcm, bus, chunk, ranges, f, sched.frame_time[f], xy);
      publish_seconds += seconds_since(t_publish);
      bytes_published += 16.0 * static_cast<double>(eng.size());
      rep.msg().frames_published = next_frame = f + 1;
    }
    advance(t_end);
    // The cuts still open are whole once the nodes have caught up: a run
    // that dies after the sim ends then loses nothing the sim did.
    if (cuts && cuts->newest_open() >= 0 &&
        !cuts->wait_whole(cuts->newest_open(), cut_wait, [&] { return keep_talking() || g_signal != 0; })) {
      if (g_signal) {
        checkpoint_written = true;
        throw std::runtime_error("interrupted by signal " + std::to_string(g_signal.load()) +
                                 " after the last frame; the run resumes from cut " +
                                 std::to_string(cuts->last_whole()));
      }
      std::fprintf(stderr, "\nsim_node: the last checkpoint cut was not whole within %g s (--cut-wait)\n", cut_wait);
    }
    const double production_seconds = seconds_since(t_production);
    if (!checkpoint_path.empty()) {
      eng.synchronize();
      checkpoint();
    }

    rep.msg().phase = "done";
    rep.msg().eta_seconds = 0;
    publish_info();
    for (int i = 0; i < 3; ++i) {
      rep.update(eng, 0, true);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    double px, py;
    eng.momentum(px, py);
    std::fprintf(stderr,
                 "\nsim_node: done in %.1f s: %lld collisions, %lld kicks (first particles drawn again %lld times, "
                 "%lld pairs from the whole system), %d frames, KE/N=%.4f, "
                 "total momentum (%.2g, %.2g), max overlap %.2g\n"
                 "sim_node: production: Z = %.5g +- %.2g, collisions per particle per unit time %.5g +- %.2g%s, "
                 "TC model acted %lld times\n",
                 seconds_since(t_wall), static_cast<long long>(eng.counters().collisions),
                 static_cast<long long>(eng.counters().kicks), static_cast<long long>(eng.counters().kick_redraws),
                 static_cast<long long>(eng.counters().kick_far), info.n_frames,
                 eng.kinetic_energy_per_particle(), px, py, std::max(0.0, eng.max_overlap()),
                 rep.msg().reduced_pressure, rep.msg().reduced_pressure_err, rep.msg().collision_frequency,
                 rep.msg().collision_frequency_err,
                 rep.blocks() < 2 ? " (no error: the production was shorter than two fine blocks)" : "",
                 static_cast<long long>(eng.counters().tc));
    std::fprintf(stderr,
                 "sim_node: production wall time %.2f s for %.6g time units: %.2f s waiting for paced nodes, "
                 "%.2f s publishing %.1f MB of frames (%.1f MB/s while publishing, copies and pauses between chunks included)\n",
                 production_seconds, t_end - sim_t_production, wait_seconds, publish_seconds, bytes_published / 1e6,
                 publish_seconds > 0 ? bytes_published / 1e6 / publish_seconds : 0.0);
  } catch (const std::exception& e) {
    if (g_signal && checkpoint_written) rep.msg().phase = "interrupted"; // nodes wait for --resume
    fail(e.what());
    code = g_signal ? 128 + g_signal : 1;
  }
  // The last frames and the "done" (or "failed") reach the bus before the
  // process ends (tcpq: dynhet/lcm_exit.hpp).
  if (const std::string why = dynhet::deliver_before_exit(lcm, bus_url); !why.empty())
    std::fprintf(stderr, "sim_node: %s\n", why.c_str());
  return code;
}
