// One run of a scene on the bus (sim_run.cpp): the run info, the state
// (compressed, or from a prepared state, a checkpoint or a checkpoint cut),
// equilibration, the production's frames, checkpoints and cuts on the way,
// and the sim status throughout.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "checkpoint.hpp"
#include "dynhet/bus.hpp"
#include "dynhet/scene.hpp"
#include "options.hpp"

namespace dynhet {

// What a run starts from: its scene, the checkpoint it resumes (--resume;
// next_frame 0 otherwise) and the sim's part of the checkpoint cut it
// resumes (--resume-cut; empty otherwise).
struct RunStart {
  Scene scene;
  Checkpoint resumed;
  std::vector<uint8_t> cut_part;
};

// Runs the scene as run `run_id` on the bus (lcm open at bus_url). A
// non-zero `signal` (SIGINT, SIGTERM) stops it: with checkpoint cuts after
// a last cut, else at the next synchronised time with a checkpoint. Returns
// the exit code: 0 done, 1 failed, 128 + the signal when interrupted.
int run_on_bus(const SimOptions& o, RunStart& start, int64_t run_id, lcm::LCM& lcm, const Bus& bus,
               const std::string& bus_url, const std::atomic<int>& signal);

} // namespace dynhet
