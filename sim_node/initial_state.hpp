// Where a run's state comes from (initial_state.cpp): the engine
// parameters of a scene, the scene's system.initial_state, and sim_node
// --prepare-only (with --equilibrate).
#pragma once

#include <atomic>
#include <string>

#include "dynhet/engine/engine.hpp"
#include "dynhet/scene.hpp"

namespace dynhet {

engine::Params engine_params(const Scene& scene);

// The first key of the dynamics (engine parameters) in which two scenes
// differ, or "" if a run of one continues a state of the other exactly.
std::string dynamics_difference(const Scene& a, const Scene& b);

// Starts eng from scene.initial_state: a prepared state of the same system,
// an equilibrated state of the same dynamics, or H5MD positions. Throws
// std::runtime_error naming the file and what does not fit.
void start_from(engine::Engine& eng, const Scene& scene);

// --prepare-only PATH (--equilibrate): writes the state and returns the
// exit code (0, or 1 with the reason on stderr); a signal (non-zero
// `signal`) stops the equilibration.
int prepare_only(const Scene& scene, const std::string& path, bool equilibrate, const std::atomic<int>& signal);

} // namespace dynhet
