// P(dx, t) pooled over blocks of origins (DisplacementTally) against brute
// force, and its fits on samples of known distributions.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "dynhet/analysis/displacement.hpp"
#include "dynhet/analysis/displacement_distribution.hpp"
#include "dynhet/analysis/fits.hpp"

using namespace dynhet::analysis;

namespace {

DisplacementSpec histogram_spec(double lo, double width, int bins) {
  DisplacementSpec spec;
  spec.hist_lo = lo, spec.hist_width = width, spec.hist_bins = bins;
  return spec;
}

// Counts of xs in the spec's bins, by the definition: bin b is [lo + b w, lo + (b+1) w).
std::vector<long> bin_counts(const DisplacementSpec& s, const std::vector<double>& xs) {
  std::vector<long> c(s.hist_bins, 0);
  for (double x : xs) {
    const double b = std::floor((x - s.hist_lo) / s.hist_width);
    if (b >= 0 && b < s.hist_bins) ++c[static_cast<int>(b)];
  }
  return c;
}

// sqrt((n-1)/n sum (x_k - mean)^2), written out.
double jackknife(const std::vector<double>& v) {
  double mean = 0, ss = 0;
  for (double x : v) mean += x / v.size();
  for (double x : v) ss += (x - mean) * (x - mean);
  return std::sqrt((v.size() - 1.0) / v.size() * ss);
}

} // namespace

TEST(DisplacementDistribution, TallyOverBlocksMatchesBruteForce) {
  // 6 origins in 3 blocks, 2 lags, through the real pass; the small set is species 0.
  const long n = 4000;
  const int n_origins = 6, blocks = 3, lags = 2;
  DisplacementSpec spec = histogram_spec(-3.0, 0.1, 60);
  spec.grids = {make_subbox_grid(n, 50.0, n)};
  spec.cutoffs = {0.6};
  std::mt19937_64 gen(3);
  std::uniform_real_distribution<double> u(0, 50);
  std::exponential_distribution<double> ex(1 / 0.4);
  std::uniform_int_distribution<int> sign(0, 1);
  std::vector<std::uint8_t> species(n);
  for (long i = 0; i < n; ++i) species[i] = i % 3 == 0;
  DisplacementTally tally(blocks, lags, 2, spec.hist_bins);
  // dx of every (origin, lag) and set, kept for the brute force: [lag][set][origin]
  std::vector<std::vector<std::vector<std::vector<double>>>> dx(
      lags, std::vector<std::vector<std::vector<double>>>(2, std::vector<std::vector<double>>(n_origins)));
  for (int k = 0; k < n_origins; ++k)
    for (int j = 0; j < lags; ++j) {
      std::vector<double> p0(2 * n), pt(2 * n);
      for (long i = 0; i < 2 * n; ++i) p0[i] = u(gen), pt[i] = p0[i] + (j + 1) * (sign(gen) ? 1 : -1) * ex(gen);
      const OriginIndex origin(p0.data(), n, spec);
      DisplacementResult r;
      displacement_pass(p0.data(), pt.data(), species.data(), n, origin, spec, r);
      std::vector<long> all(spec.hist_bins);
      for (int b = 0; b < spec.hist_bins; ++b) all[b] = r.hist[0][b] + r.hist[1][b];
      tally.add(k * blocks / n_origins, j, 0, all.data(), n);
      tally.add(k * blocks / n_origins, j, 1, r.hist[0].data(), r.n_small);
      for (long i = 0; i < n; ++i) {
        dx[j][0][k].push_back(pt[2 * i] - p0[2 * i]);
        if (species[i] == 0) dx[j][1][k].push_back(pt[2 * i] - p0[2 * i]);
      }
    }
  DistributionFitSpec fit;
  fit.tail_sigmas = 1.5, fit.min_count = 3;
  for (int j = 0; j < lags; ++j)
    for (int set = 0; set < 2; ++set) {
      const double t = j + 1.0;
      // Pooled, and leaving out each block (origins 2b, 2b+1).
      auto pooled = [&](int skip) {
        std::vector<double> xs;
        for (int k = 0; k < n_origins; ++k)
          if (k * blocks / n_origins != skip) xs.insert(xs.end(), dx[j][set][k].begin(), dx[j][set][k].end());
        return xs;
      };
      const std::vector<double> all_x = pooled(-1);
      const std::vector<long> count = bin_counts(spec, all_x);
      const DistributionEstimate e = tally.estimate(spec, j, set, t, fit);
      EXPECT_EQ(e.pairs, n_origins);
      EXPECT_EQ(e.samples, static_cast<long>(all_x.size()));
      EXPECT_EQ(e.count, count);
      std::vector<std::vector<double>> p_loo(spec.hist_bins);
      std::vector<double> d_loo, x0_loo;
      for (int skip = 0; skip < blocks; ++skip) {
        const std::vector<double> xs = pooled(skip);
        const std::vector<long> c = bin_counts(spec, xs);
        for (int b = 0; b < spec.hist_bins; ++b) p_loo[b].push_back(c[b] / (xs.size() * spec.hist_width));
        const DistributionFit f = fit_distribution(spec, c, static_cast<long>(xs.size()), t, fit);
        d_loo.push_back(f.gauss_d), x0_loo.push_back(f.tail_x0);
      }
      for (int b = 0; b < spec.hist_bins; ++b) {
        EXPECT_NEAR(e.p[b], count[b] / (all_x.size() * spec.hist_width), 1e-12);
        EXPECT_NEAR(e.p_err[b], jackknife(p_loo[b]), 1e-12);
      }
      const DistributionFit f = fit_distribution(spec, count, static_cast<long>(all_x.size()), t, fit);
      EXPECT_TRUE(std::isfinite(f.gauss_d) && std::isfinite(f.tail_x0));
      EXPECT_DOUBLE_EQ(e.fit.gauss_d, f.gauss_d);
      EXPECT_DOUBLE_EQ(e.fit.tail_x0, f.tail_x0);
      EXPECT_NEAR(e.gauss_d_err, jackknife(d_loo), 1e-12 * f.gauss_d);
      EXPECT_NEAR(e.tail_x0_err, jackknife(x0_loo), 1e-12 * f.tail_x0);
      EXPECT_GT(e.tail_x0_err, 0);
    }
}

TEST(DisplacementDistribution, FitsRecoverKnownDistributionsOverTheStatedRanges) {
  std::mt19937_64 gen(11);
  const DisplacementSpec spec = histogram_spec(-5.0, 0.05, 200);
  const int n = 400000;
  const double t = 2.0, d = 0.1, x0 = 0.4;
  DistributionFitSpec fit; // 2 sigma, at least 5 per bin
  // Gaussian of variance 2 D t: D within 1% (statistical error ~0.2%).
  std::normal_distribution<double> gauss(0, std::sqrt(2 * d * t));
  std::vector<double> xs(n);
  for (double& x : xs) x = gauss(gen);
  std::vector<long> c = bin_counts(spec, xs);
  DistributionFit f = fit_distribution(spec, c, n, t, fit);
  EXPECT_NEAR(f.gauss_d, d, 0.01 * d);
  int used = 0;
  for (long v : c) used += v >= fit.min_count;
  EXPECT_EQ(f.gauss_bins, used);
  // Laplace exp(-|x|/x0): x_min = 2 sqrt(<x^2>) with <x^2> at the bin
  // centres (2 x0^2 up to binning), x0 from the tail within 2% (the
  // statistical error of ~1e4 tail samples is ~1%).
  std::exponential_distribution<double> ex(1 / x0);
  std::uniform_int_distribution<int> sign(0, 1);
  for (double& x : xs) x = (sign(gen) ? 1 : -1) * ex(gen);
  c = bin_counts(spec, xs);
  f = fit_distribution(spec, c, n, t, fit);
  double inside = 0, m2 = 0;
  for (int b = 0; b < spec.hist_bins; ++b) {
    const double x = spec.hist_lo + (b + 0.5) * spec.hist_width;
    inside += c[b], m2 += c[b] * x * x;
  }
  EXPECT_DOUBLE_EQ(f.tail_x_min, 2 * std::sqrt(m2 / inside));
  EXPECT_NEAR(f.tail_x_min, 2 * std::sqrt(2.0) * x0, 0.02 * x0);
  EXPECT_NEAR(f.tail_x0, x0, 0.02 * x0);
  EXPECT_GE(f.tail_x_max, f.tail_x_min);
  EXPECT_GE(f.tail_bins, 3);
  // Too few bins: NaN, not a guess.
  f = fit_distribution(spec, std::vector<long>(spec.hist_bins, 1), spec.hist_bins, t, fit);
  EXPECT_TRUE(std::isnan(f.gauss_d) && std::isnan(f.tail_x0));
  // A flat or rising "tail" does not decay: no x0 (a Gaussian is still fitted).
  std::vector<long> flat(spec.hist_bins, 100);
  f = fit_distribution(spec, flat, 100 * spec.hist_bins, t, fit);
  EXPECT_TRUE(std::isfinite(f.gauss_d));
  EXPECT_TRUE(std::isnan(f.tail_x0) && std::isnan(f.tail_x_max));
  for (int b = 0; b < spec.hist_bins; ++b) flat[b] = 100 + std::abs(b - spec.hist_bins / 2);
  EXPECT_TRUE(std::isnan(fit_distribution(spec, flat, 100 * spec.hist_bins, t, fit).tail_x0));
}
