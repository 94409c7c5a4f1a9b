// What sim_node says about a scene without running it (scene_report.cpp).
#pragma once

#include <string>

#include "dynhet/scene.hpp"

namespace dynhet {

// --check: the engine's own refusals (a box too small for its cells, ...)
// made now, then one line per fact for the launch scripts and for people
// (valid, notes, nodes, frames, particles, sim_time, kick_rate). Returns the
// exit code.
int report_check(const Scene& scene, const std::string& path);

// --resolved: the scene with every key written out, the defaults filled in
// (TOML that reads back as the same scene), then [model], what the
// simulator derives from it. Returns the exit code.
int report_resolved(const Scene& scene);

} // namespace dynhet
