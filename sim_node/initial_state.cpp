// Where a run's state comes from: the scene's engine parameters, a prepared
// or equilibrated state or H5MD positions (system.initial_state), and
// sim_node --prepare-only (initial_state.hpp).
#include "initial_state.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "checkpoint.hpp"
#include "dynhet/model.hpp"

namespace dynhet {
namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
} // namespace

engine::Params engine_params(const Scene& scene) {
  engine::Params p;
  p.n_particles = scene.n_particles;
  p.packing_fraction = scene.packing_fraction;
  p.restitution = scene.restitution;
  p.radius_ratio = scene.radius_ratio;
  p.seed = scene.seed;
  p.driving = scene.driving;
  p.tc = scene.tc_time;
  p.kick_rate = scene_kick_rate(scene);
  p.kick_pairs = scene.kick_pairs == "any" ? engine::KickPairs::any : engine::KickPairs::neighbours;
  p.kick_reach = scene.kick_reach;
  return p;
}

// The first key of the dynamics (engine parameters) in which two scenes
// differ, or "" if a run of one continues a state of the other exactly.
std::string dynamics_difference(const Scene& a, const Scene& b) {
  if (a.n_particles != b.n_particles) return "system.n_particles";
  if (a.packing_fraction != b.packing_fraction) return "system.packing_fraction";
  if (a.radius_ratio != b.radius_ratio) return "system.radius_ratio";
  if (a.seed != b.seed) return "system.seed";
  if (a.restitution != b.restitution) return "system.restitution";
  if (a.tc_time != b.tc_time) return "the TC model";
  if (a.driving != b.driving) return "driving";
  if (scene_kick_rate(a) != scene_kick_rate(b)) return "the kick rate (driving)";
  if (a.kick_pairs != b.kick_pairs) return "driving.pairs";
  if (a.kick_reach != b.kick_reach) return "driving.reach";
  return "";
}

// system.initial_state: a prepared state of the same system (N, phi,
// radius ratio, seed), an equilibrated state of the same dynamics (sim_node
// --prepare-only --equilibrate), or positions from an H5MD file (velocities
// drawn).
void start_from(engine::Engine& eng, const Scene& scene) {
  const std::string& path = scene.initial_state;
  if (access(path.c_str(), R_OK) != 0) throw std::runtime_error(path + ": no such file (system.initial_state)");
  if (is_checkpoint(path)) {
    const Checkpoint c = read_checkpoint(path);
    const Scene made = parse_scene_text(c.scene_toml, path + " (its scene)");
    if (c.next_frame != 0)
      throw std::runtime_error(path + ": a checkpoint taken after frame " + std::to_string(c.next_frame - 1) +
                               ", not a prepared state (resume a run's checkpoint with --resume)");
    if (c.state.time != 0.0) {
      // An equilibrated state: the run continues it, as a resumed run would.
      const std::string d = dynamics_difference(made, scene);
      if (!d.empty())
        throw std::runtime_error(path + ": equilibrated with another " + d +
                                 " than the scene's (an equilibrated state serves only runs of the same dynamics)");
      if (c.kick_pairs != scene.kick_pairs)
        throw std::runtime_error(path + ": equilibrated with kick pairs \"" + c.kick_pairs + "\"");
      if (c.state.time > scene.equilibration_time)
        throw std::runtime_error(path + ": equilibrated to t = " + std::to_string(c.state.time) +
                                 ", beyond the scene's run.equilibration_time = " +
                                 std::to_string(scene.equilibration_time));
      eng.restore(c.state);
      return;
    }
    auto differs = [&](const char* key, const std::string& was, const std::string& is) {
      if (was != is)
        throw std::runtime_error(path + ": prepared for system." + key + " = " + was + ", the scene has " + is);
    };
    differs("n_particles", std::to_string(made.n_particles), std::to_string(scene.n_particles));
    differs("packing_fraction", std::to_string(made.packing_fraction), std::to_string(scene.packing_fraction));
    differs("radius_ratio", std::to_string(made.radius_ratio), std::to_string(scene.radius_ratio));
    differs("seed", std::to_string(made.seed), std::to_string(scene.seed));
    if (made.packing_fraction != scene.packing_fraction || made.radius_ratio != scene.radius_ratio)
      throw std::runtime_error(path + ": prepared for another packing fraction or radius ratio (they differ "
                               "beyond the digits shown)");
    eng.start_prepared(c.state);
    return;
  }
  std::vector<double> x, y;
  read_h5md_positions(path, eng.size(), eng.box_length(), x, y);
  try {
    eng.place(x, y);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  eng.thermalize(1.0);
  eng.begin();
}

// --prepare-only: compression and velocities, written as a checkpoint at
// t = 0. With --equilibrate: then the scene's dynamics up to the last
// checkpoint slot (a multiple of run.checkpoint_interval) at or before
// run.equilibration_time, synchronised at every slot as a run is, and the
// state there: a run of the same dynamics from it equals, bit for bit, the
// run that equilibrates itself. The scene's own initial_state (a prepared
// or a shorter equilibrated state) is the start if it has one.
int prepare_only(const Scene& scene, const std::string& path, bool equilibrate, const std::atomic<int>& signal) {
  try {
    engine::Engine eng(engine_params(scene));
    const auto t0 = Clock::now();
    const bool tty = isatty(STDERR_FILENO);
    if (!equilibrate) {
      eng.compress([&](double phi) {
        if (tty) std::fprintf(stderr, "\rsim_node: compressing, phi = %.4f", phi);
      });
      eng.thermalize(1.0);
      write_checkpoint(path, {scene.text, 0, 0, scene.kick_pairs, eng.state()});
      std::fprintf(stderr, "\nsim_node: prepared state (N=%ld, phi=%.4f, seed %llu) in %.1f s -> %s\n", eng.size(),
                   eng.packing_fraction(), static_cast<unsigned long long>(scene.seed), seconds_since(t0),
                   path.c_str());
      return 0;
    }
    if (!scene.initial_state.empty()) {
      start_from(eng, scene);
    } else {
      eng.prepare([&](double phi) {
        if (tty) std::fprintf(stderr, "\rsim_node: compressing, phi = %.4f", phi);
      });
    }
    const double interval = scene.checkpoint_interval;
    const double t_end = std::floor(scene.equilibration_time / interval + 1e-9) * interval;
    const double t_start = eng.time();
    for (int64_t slot = static_cast<int64_t>(std::floor(t_start / interval + 0.5)) + 1; slot * interval <= t_end + 1e-12 * interval;
         ++slot) {
      while (!eng.run_until(slot * interval, 1000000)) {
        if (signal) throw std::runtime_error("interrupted by signal " + std::to_string(signal.load()));
        if (tty)
          std::fprintf(stderr, "\rsim_node: equilibrating, t = %.6g of %.6g (%.1f s)", eng.time(), t_end,
                       seconds_since(t0));
      }
      eng.synchronize();
    }
    if (eng.time() == 0.0)
      throw std::runtime_error("run.equilibration_time = " + std::to_string(scene.equilibration_time) +
                               " is shorter than one run.checkpoint_interval: nothing to equilibrate");
    write_checkpoint(path, {scene.text, 0, 0, scene.kick_pairs, eng.state()});
    std::fprintf(stderr, "\nsim_node: equilibrated state (N=%ld, phi=%.4f, eps=%.3f, seed %llu) from t = %.6g to "
                 "%.6g in %.1f s -> %s\n", eng.size(), eng.packing_fraction(), scene.restitution,
                 static_cast<unsigned long long>(scene.seed), t_start, eng.time(), seconds_since(t0), path.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "\nsim_node: %s\n", e.what());
    return 1;
  }
}

} // namespace dynhet
