#include "dynhet/analysis/lag_interpolation.hpp"

#include <cmath>

namespace dynhet::analysis {

LagBracket bracket_lag(const std::vector<double>& lag_time, double t, const std::function<bool(int)>& has_data) {
  LagBracket b;
  const int n = static_cast<int>(lag_time.size());
  if (!(t > 0) || !std::isfinite(t) || n < 2 || t < lag_time[0] || t > lag_time[n - 1]) return b;
  int lo = 0;
  while (lo + 2 < n && lag_time[lo + 1] <= t) ++lo; // t_lo <= t <= t_hi, t_hi the last lag if t is
  const int hi = lo + 1;
  if (!has_data(lo) || !has_data(hi)) return b;
  b.lo = lo, b.hi = hi;
  b.x = std::log(t), b.x_lo = std::log(lag_time[lo]), b.x_hi = std::log(lag_time[hi]);
  b.w = (b.x - b.x_lo) / (b.x_hi - b.x_lo);
  // The third lag: the neighbour on t's side first.
  const int below = lo - 1 >= 0 && has_data(lo - 1) ? lo - 1 : -1;
  const int above = hi + 1 < n && has_data(hi + 1) ? hi + 1 : -1;
  const int near = b.w < 0.5 ? below : above, far = b.w < 0.5 ? above : below;
  b.third = near >= 0 ? near : far;
  if (b.third >= 0) b.x_third = std::log(lag_time[b.third]);
  return b;
}

double interpolate(const LagBracket& b, double v_lo, double v_hi) { return (1 - b.w) * v_lo + b.w * v_hi; }

double quadratic_minus_linear(const LagBracket& b, double v_lo, double v_hi, double v_third) {
  if (b.third < 0 || !std::isfinite(v_third)) return 0;
  // Newton form through (x_lo, x_hi, x_third): the quadratic term is
  // f[lo, hi, third] (x - x_lo)(x - x_hi).
  const double d_lh = (v_hi - v_lo) / (b.x_hi - b.x_lo), d_h3 = (v_third - v_hi) / (b.x_third - b.x_hi);
  const double d_l3 = (v_third - v_lo) / (b.x_third - b.x_lo);
  const double second = b.third > b.hi ? (d_h3 - d_lh) / (b.x_third - b.x_lo) : (d_lh - d_l3) / (b.x_hi - b.x_third);
  return second * (b.x - b.x_lo) * (b.x - b.x_hi);
}

ValueErr interpolate_correlated(const LagBracket& b, ValueErr lo, ValueErr hi, double v_third) {
  const double e = (1 - b.w) * lo.err + b.w * hi.err;
  return {interpolate(b, lo.value, hi.value), std::hypot(e, quadratic_minus_linear(b, lo.value, hi.value, v_third))};
}

} // namespace dynhet::analysis
