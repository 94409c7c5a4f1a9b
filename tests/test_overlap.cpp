// Q_r(t;t0), Q(t), tau_alpha against brute force and known answers.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "dynhet/analysis/overlap.hpp"

using namespace dynhet::analysis;

TEST(Overlap, SubboxesMatchBruteForce) {
  std::mt19937_64 gen(5);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g(0, 0.5);
  const long n = 2000;
  const double L = 40.0;
  std::vector<double> p0(2 * n), pt(2 * n);
  for (long i = 0; i < 2 * n; ++i) {
    p0[i] = L * u(gen) + L * std::floor(3 * u(gen) - 1); // unwrapped: any image
    pt[i] = p0[i] + g(gen);
  }
  const auto grid = make_subbox_grid(n, L, 125); // 4 x 4 boxes of N = 125
  ASSERT_EQ(grid.per_side, 4);
  EXPECT_DOUBLE_EQ(grid.mean_particles, 125.0);
  const std::vector<double> cutoffs{0.3, 0.6};
  std::vector<double> q;
  overlap_subboxes(p0.data(), pt.data(), n, grid, cutoffs, q);
  ASSERT_EQ(q.size(), 32u);
  for (int c = 0; c < 2; ++c)
    for (int bx = 0; bx < 4; ++bx)
      for (int by = 0; by < 4; ++by) {
        // Brute force: count the slow particles whose folded t0 position lies in the box.
        int slow = 0;
        for (long i = 0; i < n; ++i) {
          const double x = std::fmod(std::fmod(p0[2 * i], L) + L, L), y = std::fmod(std::fmod(p0[2 * i + 1], L) + L, L);
          if (x < bx * 10.0 || x >= (bx + 1) * 10.0 || y < by * 10.0 || y >= (by + 1) * 10.0) continue;
          if (std::hypot(pt[2 * i] - p0[2 * i], pt[2 * i + 1] - p0[2 * i + 1]) < cutoffs[c]) ++slow;
        }
        EXPECT_DOUBLE_EQ(q[c * 16 + by * 4 + bx], slow / 125.0);
      }
}

TEST(Overlap, CrossingTimeOfAnExponentialIsItsTime) {
  std::vector<double> t, q;
  for (int j = 0; j <= 200; ++j) t.push_back(0.01 * std::pow(10.0, j / 50.0));
  for (double x : t) q.push_back(std::exp(-x / 3.0));
  // Linear interpolation in ln t over 1/50 decade: relative error < 1e-3.
  EXPECT_NEAR(crossing_time(t, q, std::exp(-1.0)), 3.0, 3e-3);
  EXPECT_TRUE(std::isnan(crossing_time(t, std::vector<double>(t.size(), 0.9), std::exp(-1.0))));
}

TEST(Overlap, AccumulatorAveragesOverOriginsWithStandardError) {
  const std::vector<double> lags{1.0, 2.0, 4.0};
  OverlapAccumulator acc(3, lags);
  // Sub-box values for 3 origins at lag 0: means 0.5, 0.7, 0.9.
  const double a[] = {0.4, 0.6}, b[] = {0.7, 0.7}, c[] = {1.0, 0.8};
  acc.add(0, 0, a, 2);
  acc.add(1, 0, b, 2);
  acc.add(2, 0, c, 2);
  const auto r = acc.result();
  EXPECT_DOUBLE_EQ(r.q[0], 0.7);
  EXPECT_NEAR(r.q_err[0], std::sqrt(0.04 / 3), 1e-15); // sample sd 0.2, n = 3
  EXPECT_NEAR(r.qr_var[0], (0.01 + 0.0 + 0.01) / 3, 1e-15);
  EXPECT_EQ(r.n_origins[0], 3);
  EXPECT_EQ(r.n_origins[1], 0);
  EXPECT_TRUE(std::isnan(r.q[1]));
  EXPECT_TRUE(std::isnan(r.tau_alpha));
}

TEST(Overlap, TauAlphaAndJackknifeOnSyntheticOrigins) {
  // Origin k decays as exp(-t / tau_k): tau_alpha of the mean lies between,
  // and the jackknife error reflects the spread of the tau_k.
  std::vector<double> lags;
  for (int j = 0; j <= 100; ++j) lags.push_back(0.1 * std::pow(10.0, j / 40.0));
  const std::vector<double> taus{2.0, 2.2, 1.8, 2.1, 1.9};
  OverlapAccumulator acc(5, lags);
  for (int k = 0; k < 5; ++k)
    for (size_t j = 0; j < lags.size(); ++j) {
      const double v = std::exp(-lags[j] / taus[k]);
      acc.add(k, static_cast<int>(j), &v, 1);
    }
  const auto r = acc.result();
  EXPECT_NEAR(r.tau_alpha, 2.0, 0.02);
  // Spread of tau_k: sd 0.158, standard error 0.071; the jackknife of a smooth
  // function of the means agrees to within tens of percent.
  EXPECT_GT(r.tau_alpha_err, 0.05);
  EXPECT_LT(r.tau_alpha_err, 0.09);
}

// tau_alpha's error is quoted only where jackknife blocks spanning the lag
// beyond the crossing fit four times into the origins; with origins closer
// than that (tau_alpha^CR of a run whose origins are one standard
// tau_alpha apart) the capped blocks are correlated and the run quotes none.
TEST(Overlap, NoTauAlphaErrorWhereTheBlocksCannotSpanIt) {
  std::vector<double> lags;
  for (int j = 0; j <= 100; ++j) lags.push_back(0.1 * std::pow(10.0, j / 40.0));
  const std::vector<double> taus{2.0, 2.2, 1.8, 2.1, 1.9, 2.05, 1.95, 2.15};
  auto run = [&](double spacing) {
    OverlapAccumulator acc(8, lags, spacing);
    for (int k = 0; k < 8; ++k)
      for (size_t j = 0; j < lags.size(); ++j) {
        const double v = std::exp(-lags[j] / taus[k]);
        acc.add(k, static_cast<int>(j), &v, 1);
      }
    return acc.result();
  };
  const auto near = run(1.1);  // tau_alpha ~ 2 spans 2 spacings: 4 blocks of 2 origins fit
  const auto close = run(0.5); // 5 spacings: blocks of at most 2 cannot span it
  EXPECT_NEAR(near.tau_alpha, 2.0, 0.03);
  EXPECT_TRUE(std::isfinite(near.tau_alpha_err) && near.tau_alpha_err > 0);
  EXPECT_NEAR(close.tau_alpha, near.tau_alpha, 1e-12);
  EXPECT_TRUE(std::isnan(close.tau_alpha_err));
}
