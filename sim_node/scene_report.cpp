// What sim_node says about a scene without running it (scene_report.hpp).
#include "scene_report.hpp"

#include <cstdio>

#include "dynhet/schedule.hpp"
#include "initial_state.hpp"

namespace dynhet {

int report_check(const Scene& scene, const std::string& path) {
  engine::Params p;
  try {
    p = engine_params(scene);
    engine::Engine probe(p);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sim_node: invalid scene (1 problem):\n  %s: system: %s\n", path.c_str(), e.what());
    return 2;
  }
  const auto sched = make_schedule(scene.schedule, scene.equilibration_time);
  std::printf("scene %s: valid\n", path.c_str());
  for (const auto& note : scene.notes) std::printf("note: %s\n", note.c_str());
  std::printf("nodes:");
  for (const auto& n : nodes_for(scene.observables)) std::printf(" %s", n.c_str());
  std::printf("\nframes: %zu\nparticles: %lld\nsim_time: %g\nkick_rate: %.17g\n", sched.frame_time.size(),
              static_cast<long long>(scene.n_particles), scene.equilibration_time + scene.production_time,
              p.kick_rate);
  return 0;
}

int report_resolved(const Scene& scene) {
  std::printf("# %s: every key, the defaults filled in (sim_node --resolved); [model] is not a scene\n"
              "# table: what the simulator derives from the scene.\n%s\n%s",
              scene.path.c_str(), scene_toml(scene).c_str(), model_toml(scene).c_str());
  return 0;
}

} // namespace dynhet
