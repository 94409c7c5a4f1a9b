// A quantity at a time t between computed lags (t = tau_alpha: the paper
// takes clusters and S4 at tau_alpha, the schedule only has log-spaced
// lags): linear in ln t between the two lags that bracket t, with the
// interpolation's own error estimated from a third, neighbouring lag.
#pragma once

#include <functional>
#include <vector>

namespace dynhet::analysis {

// A value and its error.
struct ValueErr {
  double value, err;
};

// Where t lies among the lags: t_lo <= t <= t_hi (adjacent lags, both with
// data), w = ln(t/t_lo)/ln(t_hi/t_lo) in [0, 1], and the third lag of the
// quadratic (the neighbour of the pair nearer t in ln t that has data, -1 if
// neither has). lo = -1 when t is not bracketed: t not finite, outside the
// lags, or one of the two lags without data.
struct LagBracket {
  int lo = -1, hi = -1, third = -1;
  double w = 0;
  double x = 0, x_lo = 0, x_hi = 0, x_third = 0; // ln t of t and of the three lags
  bool ok() const { return lo >= 0; }
};
LagBracket bracket_lag(const std::vector<double>& lag_time, double t, const std::function<bool(int)>& has_data);

// (1 - w) v_lo + w v_hi.
double interpolate(const LagBracket& b, double v_lo, double v_hi);

// The quadratic in ln t through the three lags minus the linear
// interpolation, at t: the second divided difference times
// (x - x_lo)(x - x_hi) (zero at either lag). 0 without a third lag or where
// v_third is not finite: then no interpolation error is estimated.
double quadratic_minus_linear(const LagBracket& b, double v_lo, double v_hi, double v_third);

// A result with errors at t from the results at the lags: the value
// interpolated, the errors interpolated as fully correlated ((1 - w) e_lo +
// w e_hi: the lags share their origins) and |quadratic - linear| added in
// quadrature.
ValueErr interpolate_correlated(const LagBracket& b, ValueErr lo, ValueErr hi, double v_third);

} // namespace dynhet::analysis
