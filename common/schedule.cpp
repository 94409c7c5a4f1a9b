#include "dynhet/schedule.hpp"

#include <algorithm>
#include <cmath>

namespace dynhet {

std::vector<double> log_spaced_lags(double lag_min, double lag_max, int per_decade) {
  std::vector<double> lags;
  const double decades = std::log10(lag_max / lag_min);
  const int n = static_cast<int>(std::floor(decades * per_decade + 1e-9));
  for (int j = 0; j <= n; ++j) lags.push_back(lag_min * std::pow(10.0, double(j) / per_decade));
  if (lags.back() < lag_max * (1 - 1e-9))
    lags.push_back(lag_max);
  else
    lags.back() = lag_max;
  return lags;
}

FrameSchedule make_schedule(const ScheduleSpec& spec, double t_start) {
  FrameSchedule s;
  s.lag_time = log_spaced_lags(spec.lag_min, spec.lag_max, spec.lags_per_decade);
  // Extra lags join the list in order; one within 1e-9 (relative) of a
  // log-spaced lag is that lag.
  for (double t : spec.extra_lags) {
    bool have = false;
    for (double l : s.lag_time) have = have || std::abs(l - t) <= 1e-9 * t;
    if (!have) s.lag_time.insert(std::upper_bound(s.lag_time.begin(), s.lag_time.end(), t), t);
  }
  const int nk = spec.origins, nj = s.n_lags();

  // Every wanted time, then the distinct ones in order.
  std::vector<double> origin(nk), wanted;
  for (int k = 0; k < nk; ++k) {
    origin[k] = t_start + k * spec.origin_spacing;
    wanted.push_back(origin[k]);
    for (int j = 0; j < nj; ++j) wanted.push_back(origin[k] + s.lag_time[j]);
  }
  std::sort(wanted.begin(), wanted.end());
  auto same = [](double a, double b) { return std::abs(a - b) <= 1e-9 * std::max(1.0, std::abs(b)); };
  for (double t : wanted)
    if (s.frame_time.empty() || !same(s.frame_time.back(), t)) s.frame_time.push_back(t);

  auto index_of = [&](double t) {
    auto it = std::lower_bound(s.frame_time.begin(), s.frame_time.end(),
                               t - 1e-9 * std::max(1.0, std::abs(t)));
    return static_cast<int>(it - s.frame_time.begin());
  };
  s.origin_frame.resize(nk);
  s.pair_frame.resize(static_cast<size_t>(nk) * nj);
  for (int k = 0; k < nk; ++k) {
    s.origin_frame[k] = index_of(origin[k]);
    for (int j = 0; j < nj; ++j)
      s.pair_frame[static_cast<size_t>(k) * nj + j] = index_of(origin[k] + s.lag_time[j]);
  }
  return s;
}

} // namespace dynhet
