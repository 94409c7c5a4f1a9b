#include "dynhet/analysis/timescales.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

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

std::vector<double> tau_alpha_per_origin_error(const std::vector<double>& t0, const std::vector<double>& tau_t0,
                                               const std::vector<double>& lag_time, double tau_alpha) {
  std::vector<double> err(tau_t0.size(), kNaN);
  // The window: the lag just past the run's crossing.
  const auto past = std::lower_bound(lag_time.begin(), lag_time.end(), tau_alpha);
  if (!std::isfinite(tau_alpha) || past == lag_time.end()) return err;
  const double window = *past;
  double sum2 = 0;
  int pairs = 0;
  for (size_t i = 0; i < tau_t0.size() && i < t0.size(); ++i) {
    size_t j = i + 1; // the nearest origin at least a window later
    while (j < t0.size() && t0[j] - t0[i] < window * (1 - 1e-12)) ++j;
    if (j >= tau_t0.size() || !std::isfinite(tau_t0[i]) || !std::isfinite(tau_t0[j])) continue;
    sum2 += (tau_t0[i] - tau_t0[j]) * (tau_t0[i] - tau_t0[j]);
    ++pairs;
  }
  if (pairs < kMinSpreadPairs) return err;
  const double sigma = std::sqrt(sum2 / (2.0 * pairs));
  for (size_t k = 0; k < tau_t0.size(); ++k)
    if (std::isfinite(tau_t0[k])) err[k] = sigma;
  return err;
}

namespace {
// The parabola in ln t through the largest point and its neighbours.
Peak three_point_peak(const std::vector<double>& t, const std::vector<double>& y, int best) {
  const int n = static_cast<int>(y.size());
  if (best == 0 || best == n - 1 || !std::isfinite(y[best - 1]) || !std::isfinite(y[best + 1]))
    return {t[best], y[best], best != 0 && best != n - 1, best, best};
  const double x0 = std::log(t[best - 1]), x1 = std::log(t[best]), x2 = std::log(t[best + 1]);
  const double y0 = y[best - 1], y1 = y[best], y2 = y[best + 1];
  const double d01 = (y1 - y0) / (x1 - x0), d12 = (y2 - y1) / (x2 - x1), c = (d12 - d01) / (x2 - x0);
  if (!(c < 0)) return {t[best], y1, true, best - 1, best + 1};
  const double b = d01 - c * (x0 + x1); // y = y0 + d01 (x - x0) + c (x - x0)(x - x1)
  const double xv = -b / (2 * c);
  return {std::exp(xv), y0 + d01 * (xv - x0) + c * (xv - x0) * (xv - x1), true, best - 1, best + 1};
}
} // namespace

Peak find_peak(const std::vector<double>& t, const std::vector<double>& y) {
  const int best = peak_index(y);
  if (best < 0) return {kNaN, kNaN, false};
  const int n = static_cast<int>(y.size());
  const double top = y[best], half = 0.5 * top;
  int lo = best, hi = best;
  while (lo > 0 && std::isfinite(y[lo - 1]) && y[lo - 1] > half) --lo;
  while (hi < n - 1 && std::isfinite(y[hi + 1]) && y[hi + 1] > half) ++hi;
  if (!(top > 0) || hi - lo < 2) return three_point_peak(t, y, best);
  // Weighted least squares for y = a + b u + c u^2, u = ln t - ln t[best].
  const double x_best = std::log(t[best]);
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (int j = lo; j <= hi; ++j) {
    const double u = std::log(t[j]) - x_best, w = (y[j] / top - 0.5) / 0.5;
    const Eigen::Vector3d p(1.0, u, u * u);
    normal += w * p * p.transpose();
    rhs += w * y[j] * p;
  }
  const Eigen::ColPivHouseholderQR<Eigen::Matrix3d> qr(normal);
  if (qr.rank() < 3) return three_point_peak(t, y, best);
  const Eigen::Vector3d abc = qr.solve(rhs);
  const double a = abc[0], b = abc[1], c = abc[2];
  const double u_lo = std::log(t[lo]) - x_best, u_hi = std::log(t[hi]) - x_best;
  const auto fit = [&](double u) { return a + b * u + c * u * u; };
  // The vertex, kept within the fitted lags; no maximum (c >= 0): the
  // higher end, the limit of the vertex as c -> 0 from below.
  const double u = c < 0 ? std::clamp(-b / (2 * c), u_lo, u_hi) : (fit(u_lo) >= fit(u_hi) ? u_lo : u_hi);
  return {std::exp(x_best + u), fit(u), best != 0 && best != n - 1, lo, hi};
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
