// What the sim publishes besides its status: the run info and the frames,
// in chunks.
#include "frames.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

#include "dynhet/model.hpp"
#include "dynhet/run_info_scene.hpp"
#include "dynhet/stats.hpp"

namespace dynhet {

run_info_t make_run_info(const Scene& sc, const engine::Engine& e, const FrameSchedule& s, int64_t run_id) {
  run_info_t m{};
  m.run_id = run_id;
  m.n_particles = static_cast<int32_t>(e.size());
  m.box_length = e.box_length();
  m.packing_fraction = sc.packing_fraction;
  m.restitution = sc.restitution;
  for (int k = 0; k < 2; ++k) m.radius[k] = e.radius(k), m.mass[k] = e.mass(k);
  m.n_small = static_cast<int32_t>(small_count(e.size()));
  m.frame_time = s.frame_time;
  m.n_frames = static_cast<int32_t>(m.frame_time.size());
  m.origin_frame = s.origin_frame;
  m.n_origins = static_cast<int32_t>(m.origin_frame.size());
  m.lag_time = s.lag_time;
  m.n_lags = static_cast<int32_t>(m.lag_time.size());
  m.pair_frame = s.pair_frame;
  m.n_pairs = static_cast<int32_t>(m.pair_frame.size());
  set_analysis_fields(m, sc);
  m.keep_frames = sc.keep_frames;
  m.chunk_particles = sc.chunk_particles;
  m.scene_toml = sc.text;
  return m;
}


void publish_frame(lcm::LCM& lcm, const Bus& bus, frame_chunk_t& chunk, const std::vector<ChunkRange>& ranges, int f,
                   double time, const std::vector<double>& xy) {
  chunk.utime = utime_now();
  chunk.frame_index = f;
  chunk.time = time;
  for (size_t c = 0; c < ranges.size(); ++c) {
    chunk.chunk_index = static_cast<int32_t>(c);
    chunk.first_particle = ranges[c].first;
    chunk.count = ranges[c].count;
    chunk.n_values = 2 * ranges[c].count;
    chunk.position.assign(xy.begin() + 2 * ranges[c].first,
                          xy.begin() + 2 * (ranges[c].first + ranges[c].count));
    bus.publish(lcm, kChanFrame, chunk);
    // Pace multi-chunk frames so receivers' socket buffers keep up:
    // 300 us after a chunk of up to 8192 particles (an unpaced
    // lcm-logger keeps up with small chunks at that pace: at 5 us per
    // 128-particle chunk it lost 4 of 56 frames), and in proportion
    // beyond, about 440 MB/s (300 us per chunk whatever its size let 1
    // MB chunks go out at 3 GB/s, and a receiver on a busy core lost
    // datagrams at N = 10^6).
    if (ranges.size() > 1)
      std::this_thread::sleep_for(std::chrono::microseconds(300 * std::max(1, ranges[c].count / 8192)));
  }
}

} // namespace dynhet
