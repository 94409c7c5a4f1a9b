#include "dynhet/analysis/timescales.hpp"

#include <cmath>
#include <limits>

namespace dynhet::analysis {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}

std::vector<double> tau_alpha_per_origin(const OverlapAccumulator& acc, const std::vector<double>& lag_time,
                                         int n_origins) {
  std::vector<double> tau(n_origins);
  std::vector<double> q(lag_time.size());
  for (int k = 0; k < n_origins; ++k) {
    for (size_t j = 0; j < lag_time.size(); ++j) q[j] = acc.q(k, static_cast<int>(j));
    tau[k] = crossing_time(lag_time, q, std::exp(-1.0)); // Q(tau_alpha; t0) = 1/e
  }
  return tau;
}

Peak find_peak(const std::vector<double>& t, const std::vector<double>& y) { return peak_at(t, y, peak_index(y)); }

Peak peak_at(const std::vector<double>& t, const std::vector<double>& y, int best) {
  const int n = static_cast<int>(y.size());
  if (best < 0 || best >= n || !std::isfinite(y[best])) return {kNaN, kNaN, false};
  if (best == 0 || best == n - 1 || !std::isfinite(y[best - 1]) || !std::isfinite(y[best + 1]))
    return {t[best], y[best], false};
  // Parabola through (ln t, y) at the three lags; its vertex.
  const double x0 = std::log(t[best - 1]), x1 = std::log(t[best]), x2 = std::log(t[best + 1]);
  const double y0 = y[best - 1], y1 = y[best], y2 = y[best + 1];
  const double d01 = (y1 - y0) / (x1 - x0), d12 = (y2 - y1) / (x2 - x1), c = (d12 - d01) / (x2 - x0);
  if (!(c < 0)) return {t[best], y1, true};
  const double b = d01 - c * (x0 + x1); // y = y0 + d01 (x - x0) + c (x - x0)(x - x1)
  const double xv = -b / (2 * c);
  const double yv = y0 + d01 * (xv - x0) + c * (xv - x0) * (xv - x1);
  return {std::exp(xv), yv, true};
}

int peak_index(const std::vector<double>& y) {
  int best = -1;
  for (size_t j = 0; j < y.size(); ++j)
    if (std::isfinite(y[j]) && (best < 0 || y[j] > y[best])) best = static_cast<int>(j);
  return best;
}

int nearest_lag(const std::vector<double>& lag_time, double t) {
  if (lag_time.empty() || !(t > 0)) return -1;
  int best = 0;
  for (size_t j = 1; j < lag_time.size(); ++j)
    if (std::abs(std::log(lag_time[j] / t)) < std::abs(std::log(lag_time[best] / t)))
      best = static_cast<int>(j);
  return best;
}

} // namespace dynhet::analysis
