// What the sim publishes besides its status (frames.cpp): the run info and
// the frames, in chunks.
#pragma once

#include <cstdint>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "dynhet/bus.hpp"
#include "dynhet/chunking.hpp"
#include "dynhet/engine/engine.hpp"
#include "dynhet/frame_chunk_t.hpp"
#include "dynhet/lcm_url.hpp"
#include "dynhet/run_info_t.hpp"
#include "dynhet/scene.hpp"
#include "dynhet/schedule.hpp"

namespace dynhet {

// The run info of a run of scene sc on engine e with frame schedule s.
run_info_t make_run_info(const Scene& sc, const engine::Engine& e, const FrameSchedule& s, int64_t run_id);

// Frame f at `time` (xy: 2 N unwrapped positions) in the chunks `ranges`
// (chunk holds the run's fields; its per-frame ones are set here), paced
// so that receivers' socket buffers keep up.
void publish_frame(lcm::LCM& lcm, const Bus& bus, frame_chunk_t& chunk, const std::vector<ChunkRange>& ranges, int f,
                   double time, const std::vector<double>& xy);

} // namespace dynhet
