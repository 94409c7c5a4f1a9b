// Fits recovering known parameters: Q(t) (eq. 8), OZ forms (eqs. 18, 20),
// D from the MSD, Gaussian and exponential-tail fits of P(dx, t).
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "dynhet/analysis/fits.hpp"

using namespace dynhet::analysis;

namespace {
std::vector<double> log_lags(double t0, double t1, int per_decade) {
  std::vector<double> t;
  const int n = static_cast<int>(std::round(std::log10(t1 / t0) * per_decade));
  for (int j = 0; j <= n; ++j) t.push_back(t0 * std::pow(10.0, double(j) / per_decade));
  return t;
}
} // namespace

TEST(Fits, StraightLine) {
  const LinearFit f = linear_fit({1, 2, 3, 4}, {3, 5, 7, 9});
  EXPECT_NEAR(f.slope, 2.0, 1e-12);
  EXPECT_NEAR(f.intercept, 1.0, 1e-12);
  EXPECT_NEAR(f.chi2, 0.0, 1e-20);
}

TEST(Fits, OverlapFormRecoversBetaAndTau0) {
  const std::vector<double> t = log_lags(0.05, 200.0, 8);
  std::vector<double> q;
  for (double x : t) q.push_back(1 / (std::pow(x / 2.7, 1.3) + 1));
  const OverlapFit f = fit_overlap(t, q);
  EXPECT_NEAR(f.beta, 1.3, 1e-6);
  EXPECT_NEAR(f.tau0, 2.7, 1e-6);
}

TEST(Fits, OverlapFormWithNoiseWithinItsErrors) {
  // Gaussian noise of sd 0.005 on every lag, passed as the errors: the fit
  // must land within 4 of its own standard deviations.
  std::mt19937_64 gen(3);
  std::normal_distribution<double> g(0, 0.005);
  const std::vector<double> t = log_lags(0.05, 200.0, 8);
  std::vector<double> q, e(t.size(), 0.005);
  for (double x : t) q.push_back(1 / (std::pow(x / 5.0, 0.8) + 1) + g(gen));
  const OverlapFit f = fit_overlap(t, q, e);
  EXPECT_NEAR(f.beta, 0.8, 4 * f.beta_err);
  EXPECT_NEAR(f.tau0, 5.0, 4 * f.tau0_err);
  EXPECT_LT(f.beta_err, 0.02);
}

TEST(Fits, OverlapFormIgnoresLagsWithoutSpread) {
  // At the shortest lags every origin gives Q = 1 exactly, so the error over
  // origins is 0 up to roundoff (4e-16 in an N = 10^5 run). Weighted by
  // 1/err^2 those lags would own the fit (it ran off to beta = -4e5, tau0 = 0
  // there); they must count like the best-measured of the other lags.
  // Data: a short-time plateau Q = 1 the form does not have, then the form.
  const std::vector<double> t = log_lags(0.05, 20.0, 6);
  std::vector<double> q, e;
  for (double x : t) {
    const bool plateau = x < 0.12;
    q.push_back(plateau ? 1.0 : 1 / (std::pow(x / 2.5, 1.4) + 1));
    e.push_back(plateau ? 4e-16 : 0.002);
  }
  const OverlapFit f = fit_overlap(t, q, e);
  EXPECT_NEAR(f.beta, 1.4, 0.05);
  EXPECT_NEAR(f.tau0, 2.5, 0.05);
}

TEST(Fits, OrnsteinZernikeOnExactData) {
  std::vector<double> q, s, s2;
  for (int k = 1; k <= 40; ++k) {
    q.push_back(0.025 * k);
    s.push_back(30.0 / (1 + std::pow(q.back() * 6.0, 2)));
    const double x2 = std::pow(q.back() * 6.0, 2);
    s2.push_back(30.0 / (1 + x2 + 0.09 * x2 * x2)); // A = 0.3
  }
  const OzFit f = fit_oz(q, s);
  EXPECT_NEAR(f.xi, 6.0, 1e-6);
  EXPECT_NEAR(f.chi0, 30.0, 1e-5);
  EXPECT_TRUE(f.range_ok);
  EXPECT_LE(f.q_fit_max * f.xi, 1.0 + 1e-9);
  EXPECT_EQ(f.n, 6); // q = 0.025 k with q xi <= 1: k = 1 .. 6
  const OzFit g = fit_oz_a2(q, s2);
  EXPECT_NEAR(g.xi, 6.0, 1e-5);
  EXPECT_NEAR(g.a, 0.3, 1e-4);
  EXPECT_NEAR(g.chi0, 30.0, 1e-5);
}

TEST(Fits, DiffusionCoefficientFromTheLongTimeMsd) {
  // Ornstein-Uhlenbeck MSD: 4 D (t - tau (1 - e^{-t/tau})): ballistic, then 4 D t - 4 D tau.
  const double d = 0.05, tau = 0.3;
  const std::vector<double> t = log_lags(0.01, 1000.0, 8);
  std::vector<double> msd;
  for (double x : t) msd.push_back(4 * d * (x - tau * (1 - std::exp(-x / tau))));
  const double onset = diffusive_onset(t, msd, 0.05);
  // Brute force: local slopes of the exact curve from the onset on are within 0.05 of 1.
  EXPECT_GT(onset, 1.0);
  EXPECT_LT(onset, 10.0);
  const DiffusionFit f = fit_diffusion(t, msd, onset, 1000.0);
  // Beyond the onset the curve is 4 D t - 4 D tau up to e^{-t/tau} < e^{-3}.
  EXPECT_NEAR(f.d, d, 1e-3 * d);
  EXPECT_NEAR(f.offset, -4 * d * tau, 0.05 * 4 * d * tau);
}

TEST(Fits, GaussianAndExponentialTailsOfDisplacements) {
  std::mt19937_64 gen(5);
  const double t = 2.0, d = 0.1, x0 = 0.4;
  const double lo = -4, w = 0.05;
  const int bins = 160, n = 400000;
  auto histogram = [&](auto&& draw) {
    std::vector<long> c(bins, 0);
    for (int k = 0; k < n; ++k) {
      const int b = static_cast<int>(std::floor((draw() - lo) / w));
      if (b >= 0 && b < bins) ++c[b];
    }
    return c;
  };
  std::vector<double> x;
  for (int b = 0; b < bins; ++b) x.push_back(lo + (b + 0.5) * w);
  auto density = [&](const std::vector<long>& c) {
    std::vector<double> p;
    for (long v : c) p.push_back(v / (double(n) * w));
    return p;
  };
  // Gaussian samples of variance 2 D t: the fit gives D within 4 sigma.
  std::normal_distribution<double> gauss(0, std::sqrt(2 * d * t));
  const std::vector<long> cg = histogram([&] { return gauss(gen); });
  const GaussianFit fg = fit_gaussian_displacement(x, density(cg), cg, t);
  EXPECT_NEAR(fg.d, d, 4 * fg.d_err + 1e-3 * d); // + bin-width bias (w/sigma)^2/24 < 1e-3
  // Laplace samples exp(-|x|/x0): the tail fit beyond 2 x0 gives x0 within 4 sigma.
  std::exponential_distribution<double> ex(1 / x0);
  std::uniform_int_distribution<int> sign(0, 1);
  const std::vector<long> cl = histogram([&] { return (sign(gen) ? 1 : -1) * ex(gen); });
  const ExpTailFit fe = fit_exponential_tail(x, density(cl), cl, 2 * x0);
  EXPECT_NEAR(fe.x0, x0, 4 * fe.x0_err);
  EXPECT_LT(fe.x0_err, 0.01 * x0);
}

TEST(Fits, JackknifeOfTheMeanIsItsStandardError) {
  // For the mean, the leave-one-out estimates are (n mean - x_b)/(n - 1) and
  // the jackknife error is exactly s / sqrt(n).
  const std::vector<double> x{1.0, 4.0, 2.5, 7.0, 3.0, 5.5};
  const double n = double(x.size());
  double mean = 0, s2 = 0;
  for (double v : x) mean += v / n;
  for (double v : x) s2 += (v - mean) * (v - mean);
  std::vector<double> loo;
  for (double v : x) loo.push_back((n * mean - v) / (n - 1));
  EXPECT_NEAR(jackknife_error(loo), std::sqrt(s2 / (n - 1) / n), 1e-12);
  EXPECT_TRUE(std::isnan(jackknife_error({1.0})));
  EXPECT_TRUE(std::isnan(jackknife_error({1.0, NAN})));
}

TEST(Fits, OriginBlocksSpanTheLongestLag) {
  EXPECT_EQ(origin_block(3.0, 1.0, 24), 3);
  EXPECT_EQ(origin_block(2.5, 1.0, 24), 3);
  EXPECT_EQ(origin_block(4.0, 1.0, 8), 2); // capped: 4 blocks of the 8 origins
  EXPECT_EQ(origin_block(0.5, 1.0, 24), 1);
  EXPECT_EQ(origin_block(NAN, 1.0, 24), 1);
  EXPECT_EQ(origin_block(3.0, 0.0, 24), 1);
  // Whether those blocks span the lag: tau_B of 8 spacings over 8 origins
  // does not (the run quotes no error of it), 2 spacings over 8 does.
  EXPECT_FALSE(origin_blocks_span(8.0, 1.0, 8));
  EXPECT_FALSE(origin_blocks_span(2.5, 1.0, 8));
  EXPECT_TRUE(origin_blocks_span(2.0, 1.0, 8));
  EXPECT_TRUE(origin_blocks_span(6.0, 1.0, 24));
  EXPECT_FALSE(origin_blocks_span(6.5, 1.0, 24));
  EXPECT_TRUE(origin_blocks_span(0.5, 1.0, 3)); // one origin per block
  EXPECT_TRUE(origin_blocks_span(NAN, 1.0, 8));
  EXPECT_TRUE(origin_blocks_span(3.0, 0.0, 8));
}

TEST(Fits, OriginJackknifeWithBlocksAsLongAsTheCorrelationMatchesTheSpread) {
  // Origin k measures the mean of white noise over the window [k, k + 4):
  // origins closer than 4 share noise, as Q(t; t0) of origins closer than
  // the lag does. The error of the mean over 48 origins, by brute force over
  // 4000 realisations, against the jackknife's with blocks of 4 and of 1:
  // blocks spanning the window catch most of the correlation, not all (the
  // neighbouring blocks' covariance), blocks of 1 half of it.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g;
  const int n = 48, w = 4, reps = 4000;
  double sum = 0, sum2 = 0, e4 = 0, e1 = 0;
  for (int r = 0; r < reps; ++r) {
    std::vector<double> noise(n + w), table(n);
    for (double& v : noise) v = g(rng);
    for (int k = 0; k < n; ++k) {
      for (int i = 0; i < w; ++i) table[k] += noise[k + i] / w;
    }
    double mean = 0;
    for (double v : table) mean += v / n;
    sum += mean, sum2 += mean * mean;
    auto est = [](const std::vector<double>& m) { return std::vector<double>{m[0]}; };
    e4 += origin_jackknife(table, n, 1, est, 4)[0] / reps;
    e1 += origin_jackknife(table, n, 1, est, 1)[0] / reps;
  }
  const double sd = std::sqrt(sum2 / reps - (sum / reps) * (sum / reps));
  // The correlation of two origins d apart is C(d) = (4 - |d|) / 16. Blocks
  // of b treated as independent see S_b = sum_{i,j < b} C(i - j) per block
  // against S_b + 2 c_b with c_b the covariance of neighbouring blocks
  // (10 / 16 for b >= 3): blocks of 4 give sqrt(2.75 / 4) = 0.83 of the
  // spread, blocks of 1 sqrt(0.25) = 0.5 (the sampling noise of 4000
  // realisations and the jackknife's own bias: +- 0.06).
  EXPECT_NEAR(e4 / sd, std::sqrt(2.75 / 4.0), 0.06);
  EXPECT_NEAR(e1 / sd, 0.5, 0.06);
}

TEST(Fits, OzRangeScanIsFlatOnOzDataAndDriftsWithAQuarticTerm) {
  std::vector<double> q, s, s2;
  for (int k = 1; k <= 80; ++k) {
    q.push_back(0.025 * k);
    const double x2 = std::pow(q.back() * 6.0, 2);
    s.push_back(30.0 / (1 + x2));
    s2.push_back(30.0 / (1 + x2 + 0.25 * x2 * x2)); // A = 0.5
  }
  const OzRangeScan a = scan_oz_range(q, s);
  ASSERT_EQ(a.xi.size(), kOzRangeScan.size());
  EXPECT_LT(half_range(a.xi), 1e-5); // exact OZ: every range gives xi = 6
  EXPECT_LT(half_range(a.chi0), 1e-4);
  const OzRangeScan b = scan_oz_range(q, s2);
  // The OZ form misses the quartic term: its xi moves with the range by a
  // good part of A^2 (q xi)^2 relative (several percent of xi here), the
  // form with A^2 does not.
  EXPECT_GT(half_range(b.xi), 0.05 * 6.0);
  EXPECT_LT(half_range(b.xi_a2), 1e-3);
  // Too few shells: q = 0.025 k with q xi <= 0.5 holds 3 shells at xi = 6
  // (k <= 3), so all ranges are finite; a coarse q grid leaves NaN.
  std::vector<double> qc{0.2, 0.4, 0.6}, sc;
  for (double x : qc) sc.push_back(30.0 / (1 + std::pow(x * 6.0, 2)));
  const OzRangeScan c = scan_oz_range(qc, sc);
  EXPECT_TRUE(std::isnan(c.xi.front()));
  EXPECT_TRUE(std::isnan(half_range({1.0, NAN})));
}
