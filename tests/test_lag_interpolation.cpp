// Results at t = tau_alpha between computed lags (lag_interpolation.hpp,
// s4_average.hpp): the bracket, linear interpolation in ln t exact for data
// linear in ln t, and for data quadratic in ln t an interpolation error
// equal to the linear interpolation's actual error (the quadratic through
// three lags is then exact); the jackknife over origins of interpolated S4
// keeps the correlation of the two lags.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "dynhet/analysis/lag_interpolation.hpp"
#include "dynhet/analysis/s4_average.hpp"

using namespace dynhet::analysis;

namespace {

const std::vector<double> kLags = {0.1, 0.13, 0.17, 0.22, 0.29, 0.38}; // about 1.3 apart, as the schedule's
auto all = [](int) { return true; };

// Shells q = 0, dq, 2 dq, ... (as s4_shells gives them).
S4Accumulator make_acc(int n_origins, int n_shells, double dq) {
  std::vector<double> q{0.0};
  std::vector<int> nv{1};
  for (int s = 1; s < n_shells; ++s) q.push_back(s * dq), nv.push_back(8 * s);
  return S4Accumulator(n_origins, static_cast<int>(kLags.size()), q, nv);
}

// Origin k at every lag: chi0(ln t) / (1 + (q xi)^2) (1 + eps_k), eps_k the
// same at every lag (an origin's fluctuation persists over neighbouring lags).
template <class F> void fill(S4Accumulator& acc, F chi0, double xi, const std::vector<double>& eps) {
  for (int k = 0; k < acc.n_origins(); ++k)
    for (size_t j = 0; j < kLags.size(); ++j) {
      S4Shells s;
      for (double q : acc.q()) s.s4.push_back(chi0(std::log(kLags[j])) / (1 + q * q * xi * xi) * (1 + eps[k]));
      acc.add(k, static_cast<int>(j), s);
    }
}

} // namespace

TEST(LagInterpolation, BracketWeightAndThirdLag) {
  const double t = 0.2; // between 0.17 and 0.22, nearer 0.22
  const LagBracket b = bracket_lag(kLags, t, all);
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(b.lo, 2);
  EXPECT_EQ(b.hi, 3);
  EXPECT_NEAR(b.w, std::log(t / 0.17) / std::log(0.22 / 0.17), 1e-15);
  EXPECT_EQ(b.third, 4); // the neighbour on t's side
  EXPECT_EQ(bracket_lag(kLags, 0.18, all).third, 1);
  EXPECT_EQ(bracket_lag(kLags, 0.35, all).third, 3); // no lag above: the one below
  EXPECT_EQ(bracket_lag(kLags, 0.35, [](int j) { return j >= 4; }).third, -1);
  // At a lag: w = 0 (or 1 at the last); outside or without data: not bracketed.
  EXPECT_EQ(bracket_lag(kLags, 0.22, all).lo, 3);
  EXPECT_EQ(bracket_lag(kLags, 0.22, all).w, 0.0);
  EXPECT_EQ(bracket_lag(kLags, 0.38, all).w, 1.0);
  EXPECT_FALSE(bracket_lag(kLags, 0.09, all).ok());
  EXPECT_FALSE(bracket_lag(kLags, 0.39, all).ok());
  EXPECT_FALSE(bracket_lag(kLags, NAN, all).ok());
  EXPECT_FALSE(bracket_lag(kLags, t, [](int j) { return j != 3; }).ok());
}

TEST(LagInterpolation, LinearInLnTIsExactQuadraticErrorIsTheTrueError) {
  for (double t : {0.105, 0.2, 0.25, 0.37}) {
    const LagBracket b = bracket_lag(kLags, t, all);
    auto at = [&](auto f, int j) { return f(std::log(kLags[j])); };
    const auto lin = [](double x) { return 3 - 2 * x; };
    const auto quad = [](double x) { return 1 + 0.5 * x + 4 * x * x; };
    EXPECT_NEAR(interpolate(b, at(lin, b.lo), at(lin, b.hi)), lin(std::log(t)), 1e-13);
    EXPECT_NEAR(quadratic_minus_linear(b, at(lin, b.lo), at(lin, b.hi), at(lin, b.third)), 0.0, 1e-13);
    const double v = interpolate(b, at(quad, b.lo), at(quad, b.hi));
    const double d = quadratic_minus_linear(b, at(quad, b.lo), at(quad, b.hi), at(quad, b.third));
    EXPECT_GT(std::abs(d), 1e-4);
    EXPECT_NEAR(v + d, quad(std::log(t)), 1e-12); // the quadratic through three lags is exact
    const ValueErr x = interpolate_correlated(b, {at(quad, b.lo), 0.1}, {at(quad, b.hi), 0.3}, at(quad, b.third));
    EXPECT_NEAR(x.err, std::hypot((1 - b.w) * 0.1 + b.w * 0.3, quad(std::log(t)) - v), 1e-12);
    EXPECT_EQ(quadratic_minus_linear(b, 1, 2, NAN), 0.0); // no third value: none estimated
  }
}

TEST(LagInterpolation, S4LinearInLnTExactWithCorrelatedJackknife) {
  const double xi = 4.0, dq = 0.045, t = 0.2;
  std::mt19937_64 gen(5);
  std::normal_distribution<double> g(0, 0.05);
  std::vector<double> eps(20);
  for (double& e : eps) e = g(gen);
  S4Accumulator acc = make_acc(20, 13, dq);
  const auto chi0 = [](double x) { return 10 + 3 * x; }; // linear in ln t
  fill(acc, chi0, xi, eps);
  const LagBracket b = bracket_lag(kLags, t, all);
  const S4AtTime r = fit_s4_at_time(acc, b);
  double mean_eps = 0;
  for (double e : eps) mean_eps += e / eps.size();
  ASSERT_EQ(r.mean.n_origins, 20);
  for (size_t s = 0; s < acc.q().size(); ++s) {
    const double exact = chi0(std::log(t)) / (1 + acc.q()[s] * acc.q()[s] * xi * xi) * (1 + mean_eps);
    EXPECT_NEAR(r.mean.s4[s], exact, 1e-12 * exact);
  }
  EXPECT_NEAR(r.fit.oz.chi0, chi0(std::log(t)) * (1 + mean_eps), 1e-6 * chi0(std::log(t)));
  EXPECT_NEAR(r.fit.oz.xi, xi, 1e-6 * xi);
  // Every origin's S4 at t is its S4 at lo times chi0(t)/chi0(lo): so is the
  // jackknife error of chi0 (lags treated as independent would give less).
  const S4FitAtLag at_lo = fit_s4_at_lag(acc, b.lo);
  const double scale = chi0(std::log(t)) / chi0(std::log(kLags[b.lo]));
  EXPECT_NEAR(r.fit.oz.chi0_err, at_lo.oz.chi0_err * scale, 1e-6 * r.fit.oz.chi0_err);
  // And it is chi0(t) times the standard error of eps over origins (the
  // leave-one-out chi0 is chi0(t) times the leave-one-out mean of 1 + eps).
  double ss = 0;
  for (double e : eps) ss += (e - mean_eps) * (e - mean_eps);
  EXPECT_NEAR(r.fit.oz.chi0_err, chi0(std::log(t)) * std::sqrt(ss / (eps.size() - 1) / eps.size()), 1e-6 * r.fit.oz.chi0_err);
}

TEST(LagInterpolation, S4QuadraticInLnTFlagsTheInterpolationError) {
  const double xi = 4.0, dq = 0.045, t = 0.2;
  S4Accumulator acc = make_acc(20, 13, dq);
  const auto chi0 = [](double x) { return 10 + 3 * x + 20 * x * x; }; // curved in ln t
  fill(acc, chi0, xi, std::vector<double>(20, 0.0)); // no noise: the error is the interpolation's alone
  const S4AtTime r = fit_s4_at_time(acc, bracket_lag(kLags, t, all));
  const double truth = chi0(std::log(t)), miss = std::abs(r.fit.oz.chi0 - truth);
  EXPECT_GT(miss, 1e-3 * truth); // the linear interpolation is off ...
  EXPECT_NEAR(r.fit.oz.chi0_err, miss, 1e-6 * miss); // ... and says by how much
  for (size_t s = 0; s < acc.q().size(); ++s) {
    const double exact = truth / (1 + acc.q()[s] * acc.q()[s] * xi * xi);
    EXPECT_NEAR(r.mean.s4_err[s], std::abs(r.mean.s4[s] - exact), 1e-9 * exact);
  }
  EXPECT_NEAR(r.fit.oz.xi, xi, 1e-6 * xi); // the shape in q does not change with t
}

TEST(LagInterpolation, WholeBoxChi4InterpolatesTheVariance) {
  // Q_k(t) = 0.3 + s(t) u_k with s^2 = 1 + x^2: chi4 = N var(u) (1 + x^2), quadratic in x = ln t.
  std::mt19937_64 gen(9);
  std::normal_distribution<double> g(0, 0.02);
  std::vector<double> u(15);
  for (double& v : u) v = g(gen);
  auto q_at = [&](int j) {
    const double x = std::log(kLags[j]);
    std::vector<double> q;
    for (double v : u) q.push_back(0.3 + std::sqrt(1 + x * x) * v);
    return q;
  };
  const double n = 1000, t = 0.2;
  LagBracket b = bracket_lag(kLags, t, all);
  const ValueErr r = whole_box_chi4_at_time(q_at(b.lo), q_at(b.hi), q_at(b.third), b, n);
  const double lo = whole_box_chi4(q_at(b.lo), n).value, hi = whole_box_chi4(q_at(b.hi), n).value;
  EXPECT_NEAR(r.value, interpolate(b, lo, hi), 1e-12 * r.value);
  const double truth = whole_box_chi4(u, n).value * (1 + std::log(t) * std::log(t));
  b.third = -1;
  const double jack = whole_box_chi4_at_time(q_at(b.lo), q_at(b.hi), {}, b, n).err;
  EXPECT_GT(jack, 0.0);
  EXPECT_NEAR(r.err * r.err, jack * jack + std::pow(r.value - truth, 2), 1e-9 * r.err * r.err);
}
