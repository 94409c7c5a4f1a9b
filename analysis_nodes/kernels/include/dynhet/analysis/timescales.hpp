// Times read off the measured curves: tau_alpha per waiting time (the aging
// check of paper fig. Q-t-t_0), the peak of a curve such as chi4(t)
// (chi4^P at tau4), and the scheduled lag nearest a time (the lag used for
// clusters at t = tau_alpha).
#pragma once

#include <vector>

#include "dynhet/analysis/overlap.hpp"

namespace dynhet::analysis {

// tau_alpha(t0): Q(tau_alpha; t0) = 1/e for each origin k separately, by the
// same interpolation as crossing_time; NaN where Q(t;t0) does not cross.
std::vector<double> tau_alpha_per_origin(const OverlapAccumulator& acc, const std::vector<double>& lag_time,
                                         int n_origins);

// Maximum of y(t) over the finite values, refined by the parabola in ln t
// through the three lags around it (if the maximum is not at an end).
struct Peak {
  double t, y;
  bool interior; // false: at the first or last lag, so only a bound
};
Peak find_peak(const std::vector<double>& t, const std::vector<double>& y);

// The same with the three lags centred on lag `best` (the vertex of the
// parabola through them), whatever y's largest point.
Peak peak_at(const std::vector<double>& t, const std::vector<double>& y, int best);

// Index of the largest finite y (-1 if none).
int peak_index(const std::vector<double>& y);

// Index of the lag closest to t in ln t (-1 if lags is empty or t <= 0).
// Clusters at t = tau_alpha: tau_alpha is known only once Q(t) has crossed
// 1/e, so cluster statistics are gathered at every scheduled lag (about
// 20 ms per (origin, lag) at N = 10^5) and the ones reported are those of
// nearest_lag(lags, tau_alpha), within half a lag step (15% in t for 8 lags
// per decade) of tau_alpha.
int nearest_lag(const std::vector<double>& lag_time, double t);

} // namespace dynhet::analysis
