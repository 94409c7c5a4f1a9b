// The frame schedule: the sim publishes a frame only at the times some
// observable needs, the union of origins t0_k and pairs t0_k + tau_j.
#pragma once

#include <vector>

#include "dynhet/scene.hpp"

namespace dynhet {

struct FrameSchedule {
  std::vector<double> frame_time; // sorted, distinct
  std::vector<int> origin_frame;  // [origin k] -> frame index
  std::vector<double> lag_time;   // [lag j]
  std::vector<int> pair_frame;    // [k * n_lags + j] -> frame index

  int n_origins() const { return static_cast<int>(origin_frame.size()); }
  int n_lags() const { return static_cast<int>(lag_time.size()); }
  int pair(int k, int j) const { return pair_frame[static_cast<size_t>(k) * lag_time.size() + j]; }
};

// lag_min * 10^(j / per_decade) up to lag_max; lag_max itself is the last lag.
std::vector<double> log_spaced_lags(double lag_min, double lag_max, int per_decade);

// Origins at t_start + k * origin_spacing. Times closer than 1e-9 (relative)
// are one frame.
FrameSchedule make_schedule(const ScheduleSpec& spec, double t_start);

} // namespace dynhet
