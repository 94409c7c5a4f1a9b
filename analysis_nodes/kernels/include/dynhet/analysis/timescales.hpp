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

// The error of each origin's tau_alpha(t0) (tau_alpha_per_origin). Each is
// one origin's crossing, and every origin of a steady run draws from the
// same distribution, so the error of each is that distribution's standard
// deviation: how far the same origin of independent runs scatters. It is
// estimated from pairs of origins whose windows do not overlap (t0 at
// least the lag just past the run's tau_alpha apart, the window the
// crossing reads and the span of tau_alpha's jackknife blocks; closer
// origins measure the same stretch of trajectory and differ less), each
// origin with its nearest such partner later in the run:
//   sigma^2 = sum over pairs (tau_i - tau_j)^2 / (2 n_pairs).
// The nearest partner keeps a slow drift of tau_alpha(t0) (ageing, which the
// figure is there to show) out of the estimate but for (drift over one
// window)^2 / 2, where the variance of all origins would hold all of it.
// One value for every origin with a tau_alpha(t0); all NaN where tau_alpha
// is not known or fewer than kMinSpreadPairs pairs exist (origins spanning
// too few windows to say).
constexpr int kMinSpreadPairs = 3;
std::vector<double> tau_alpha_per_origin_error(const std::vector<double>& t0, const std::vector<double>& tau_t0,
                                               const std::vector<double>& lag_time, double tau_alpha);

// The peak of y(t), such as chi4^P at tau4: the vertex of the parabola in
// ln t fitted by weighted least squares to the peak above its half maximum
// (the lags around the largest point where y > y_max / 2, each weighted by
// its height above half the maximum, (y / y_max - 1/2) / (1/2)); the vertex
// is kept within those lags. Fewer than three such lags: the parabola
// through the largest point and its two neighbours.
// Why not the largest point and its neighbours alone: on a broad top the
// largest point moves between lags from run to run, so that estimate jumps,
// is biased up by the noise it selects (chi4^P by up to one seed-to-seed
// standard deviation), and its jackknife error varied 50-fold between seeds
// of one scene (docs/analysis.md, "Seed benchmark"). The weights go to zero
// at half maximum, so this estimate is continuous in the data.
struct Peak {
  double t, y;
  bool interior; // false: the largest point at the first or last lag, so only a bound
  int first = -1, last = -1; // the lags the estimate reads
};
Peak find_peak(const std::vector<double>& t, const std::vector<double>& y);

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
