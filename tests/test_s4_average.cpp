// S4 over origins (s4_average.hpp): the origin mean and its standard error
// against the definition, the fits at a lag recovering xi and chi0 with
// jackknife errors that match the spread over independent repeats, and the
// whole-box chi4 as N_tot times the variance over origins.
#include <cstdio>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "dynhet/analysis/s4_average.hpp"

using namespace dynhet::analysis;

namespace {

// Shells q = dq, 2 dq, ... (and q = 0 first, as s4_shells gives them).
S4Accumulator make_acc(int n_origins, int n_lags, int n_shells, double dq) {
  std::vector<double> q{0.0};
  std::vector<int> nv{1};
  for (int s = 1; s < n_shells; ++s) q.push_back(s * dq), nv.push_back(8 * s);
  return S4Accumulator(n_origins, n_lags, q, nv);
}

// Per origin: S4 = OZ(q) (1 + rel_noise g), g standard normal, independent
// per shell and origin (what origins far apart in time give).
void fill_oz(S4Accumulator& acc, int j, double chi0, double xi, double rel_noise, std::mt19937_64& gen) {
  std::normal_distribution<double> g(0, 1);
  for (int k = 0; k < acc.n_origins(); ++k) {
    S4Shells s;
    for (double q : acc.q()) s.s4.push_back(chi0 / (1 + q * q * xi * xi) * (1 + rel_noise * g(gen)));
    s.q = acc.q(), s.n_vectors = acc.n_vectors();
    acc.add(k, j, s);
  }
}

} // namespace

TEST(S4Average, MeanAndErrorOverOriginsAreTheDefinition) {
  S4Accumulator acc = make_acc(5, 2, 4, 0.1);
  std::vector<std::vector<double>> v = {{1, 2, 3, 4}, {2, 2, 5, 4}, {4, 2, 1, 7}};
  for (int k = 0; k < 3; ++k) { // origins 0..2 at lag 1; origins 3, 4 not measured
    S4Shells s;
    s.s4 = v[k];
    acc.add(k, 1, s);
  }
  EXPECT_TRUE(acc.has(2, 1));
  EXPECT_FALSE(acc.has(3, 1));
  EXPECT_FALSE(acc.has(0, 0));
  const auto m = acc.mean(1);
  EXPECT_EQ(m.n_origins, 3);
  for (int s = 0; s < 4; ++s) {
    const double mean = (v[0][s] + v[1][s] + v[2][s]) / 3;
    double ss = 0;
    for (int k = 0; k < 3; ++k) ss += std::pow(v[k][s] - mean, 2);
    EXPECT_NEAR(m.s4[s], mean, 1e-14);
    EXPECT_NEAR(m.s4_err[s], std::sqrt(ss / 2 / 3), 1e-14); // sample sd / sqrt(n)
  }
  const auto loo = acc.mean(1, 0); // without origin 0
  EXPECT_EQ(loo.n_origins, 2);
  EXPECT_NEAR(loo.s4[2], (5.0 + 1.0) / 2, 1e-14);
  EXPECT_EQ(acc.mean(0).n_origins, 0);
  EXPECT_TRUE(std::isnan(acc.mean(0).s4[0]));
}

TEST(S4Average, FitRecoversXiWithJackknifeErrorsThatMatchTheSpread) {
  // 20 origins, 5% noise per shell; shells up to q xi = 2.2, so the OZ fit
  // (q xi <= 1) uses 5 of them.
  const double chi0 = 12.0, xi = 4.0, dq = 0.045; // q xi = 0.9 and 1.08 straddle the range end
  std::mt19937_64 gen(11);
  std::vector<double> xi_fit, xi_jk, chi0_fit, chi0_jk;
  const int repeats = 150;
  for (int r = 0; r < repeats; ++r) {
    S4Accumulator acc = make_acc(20, 1, 13, dq);
    fill_oz(acc, 0, chi0, xi, 0.05, gen);
    const S4FitAtLag f = fit_s4_at_lag(acc, 0);
    ASSERT_EQ(f.n_origins, 20);
    ASSERT_TRUE(f.oz.range_ok);
    EXPECT_LE(f.oz.q_fit_max * f.oz.xi, 1.0);
    xi_fit.push_back(f.oz.xi), xi_jk.push_back(f.oz.xi_err);
    chi0_fit.push_back(f.oz.chi0), chi0_jk.push_back(f.oz.chi0_err);
    // The A^2 form on pure OZ data: A near 0, xi and chi0 near the truth.
    EXPECT_NEAR(f.oz_a2.xi, xi, 0.25 * xi);
    EXPECT_NEAR(f.oz_a2.chi0, chi0, 0.1 * chi0);
  }
  auto mean = [](const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x / v.size();
    return s;
  };
  auto sd = [&](const std::vector<double>& v) {
    const double m = mean(v);
    double s = 0;
    for (double x : v) s += (x - m) * (x - m);
    return std::sqrt(s / (v.size() - 1));
  };
  // Unbiased to within 3 standard errors of the mean over the repeats.
  EXPECT_NEAR(mean(xi_fit), xi, 3 * sd(xi_fit) / std::sqrt(repeats));
  EXPECT_NEAR(mean(chi0_fit), chi0, 3 * sd(chi0_fit) / std::sqrt(repeats));
  // The jackknife error estimates the spread over independent repeats; the
  // mean of 150 jackknife estimates has a few % statistical error, 20%
  // covers it and the jackknife's small-sample bias at n = 20.
  EXPECT_NEAR(mean(xi_jk), sd(xi_fit), 0.2 * sd(xi_fit));
  EXPECT_NEAR(mean(chi0_jk), sd(chi0_fit), 0.2 * sd(chi0_fit));
}

TEST(S4Average, WholeBoxChi4IsNTimesTheVarianceOverOrigins) {
  std::mt19937_64 gen(3);
  const double sigma = 0.02, n_total = 1000;
  std::normal_distribution<double> g(0.4, sigma);
  std::vector<double> q(400);
  for (double& x : q) x = g(gen);
  q.push_back(std::nan("")); // an origin not measured
  const ValueErr c = whole_box_chi4(q, n_total);
  double m = 0, s = 0;
  for (int k = 0; k < 400; ++k) m += q[k] / 400;
  for (int k = 0; k < 400; ++k) s += (q[k] - m) * (q[k] - m);
  EXPECT_NEAR(c.value, n_total * s / 399, 1e-12 * c.value);
  // Gaussian Q: the variance has standard error sigma^2 sqrt(2/(n-1)); the
  // jackknife estimate of it is itself uncertain by ~sqrt(2/n) ~ 7% (x 2 for the fourth moment): 25%.
  EXPECT_NEAR(c.err, n_total * sigma * sigma * std::sqrt(2.0 / 399), 0.25 * n_total * sigma * sigma * std::sqrt(2.0 / 399));
  EXPECT_TRUE(std::isnan(whole_box_chi4({0.5}, n_total).value));
  EXPECT_TRUE(std::isnan(whole_box_chi4({0.5, 0.4}, n_total).err));
}

namespace {

// Per origin: S4 = OZ(q) (1 + rel_noise g_k(q)), the noise of origin k the
// mean of w independent normals k .. k + w - 1 (times sqrt(w): unit
// variance), so origins closer than w share noise, as origins closer than
// the lag share the trajectory they measure.
void fill_oz_correlated(S4Accumulator& acc, int j, double chi0, double xi, double rel_noise, int w,
                        std::mt19937_64& gen) {
  std::normal_distribution<double> g(0, 1);
  const size_t ns = acc.q().size();
  std::vector<double> white((acc.n_origins() + w) * ns);
  for (double& v : white) v = g(gen);
  for (int k = 0; k < acc.n_origins(); ++k) {
    S4Shells s;
    for (size_t v = 0; v < ns; ++v) {
      double e = 0;
      for (int i = 0; i < w; ++i) e += white[(k + i) * ns + v];
      const double q = acc.q()[v];
      s.s4.push_back(chi0 / (1 + q * q * xi * xi) * (1 + rel_noise * e / std::sqrt(double(w))));
    }
    acc.add(k, j, s);
  }
}

double mean_of(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x / v.size();
  return s;
}
double sd_of(const std::vector<double>& v) {
  const double m = mean_of(v);
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / (v.size() - 1));
}

} // namespace

// xi(t) at every lag with its error: single origins left out (a lag below
// the origin spacing) give exactly the error fit_s4_at_lag gives at t_s4.
TEST(S4Average, LagFitOfIndependentOriginsIsTheFitAtTs4) {
  std::mt19937_64 gen(5);
  S4Accumulator acc = make_acc(20, 2, 13, 0.045);
  fill_oz(acc, 1, 12.0, 4.0, 0.05, gen);
  const S4LagFit f = fit_s4_lag(acc, 1, 0.5, 1.0);
  const S4FitAtLag ref = fit_s4_at_lag(acc, 1);
  EXPECT_EQ(f.block, 1);
  EXPECT_EQ(f.rule, 0);
  EXPECT_EQ(f.oz.xi, ref.oz.xi);
  EXPECT_EQ(f.oz.chi0, ref.oz.chi0);
  EXPECT_NEAR(f.oz.xi_err, ref.oz.xi_err, 1e-12 * ref.oz.xi_err);
  EXPECT_NEAR(f.oz.chi0_err, ref.oz.chi0_err, 1e-12 * ref.oz.chi0_err);
  // No data at lag 0: no fit (rule 3), no errors.
  const S4LagFit none = fit_s4_lag(acc, 0, 0.5, 1.0);
  EXPECT_EQ(none.rule, 3);
  EXPECT_TRUE(std::isnan(none.oz.xi) && std::isnan(none.oz.xi_err) && std::isnan(none.oz.chi0_err));
}

// Origins closer than the lag share noise (here over w = 4 origins): the
// error of xi(t) from blocks of origins spanning the lag matches the spread
// of xi over independent repeats, blocks of one origin fall short by about
// half; where blocks spanning the lag do not fit four times into the
// origins, no error is quoted.
TEST(S4Average, LagErrorFromBlocksSpanningTheLagMatchesTheSpreadOfCorrelatedOrigins) {
  const double chi0 = 12.0, xi = 4.0, dq = 0.045;
  const int n = 48, w = 4, repeats = 300;
  std::mt19937_64 gen(17);
  std::vector<double> xi_fit, chi0_fit, xi_blocks, chi0_blocks, xi_single;
  for (int r = 0; r < repeats; ++r) {
    S4Accumulator acc = make_acc(n, 1, 13, dq);
    fill_oz_correlated(acc, 0, chi0, xi, 0.1, w, gen);
    const S4LagFit f = fit_s4_lag(acc, 0, 4.0, 1.0); // lag 4 origin spacings: blocks of 4
    ASSERT_EQ(f.block, 4);
    ASSERT_EQ(f.rule, 0);
    xi_fit.push_back(f.oz.xi), chi0_fit.push_back(f.oz.chi0);
    xi_blocks.push_back(f.oz.xi_err), chi0_blocks.push_back(f.oz.chi0_err);
    xi_single.push_back(fit_s4_lag(acc, 0, 0.5, 1.0).oz.xi_err); // as if the origins were independent
    if (r == 0) { // a lag of 13 spacings: blocks of 13 do not fit 4 times into 48 origins
      const S4LagFit far = fit_s4_lag(acc, 0, 13.0, 1.0);
      EXPECT_EQ(far.oz.xi, f.oz.xi);
      EXPECT_TRUE(std::isnan(far.oz.xi_err) && std::isnan(far.oz.chi0_err));
    }
  }
  // Independent noise per shell, correlated over w origins: blocks of 4
  // leave out whole correlated stretches but for the covariance of
  // neighbouring blocks, 0.83 of the spread in the toy of
  // Fits.OriginJackknifeWithBlocksAsLongAsTheCorrelationMatchesTheSpread;
  // single origins 0.5. The sd of 300 repeats is uncertain by 4%, the mean
  // jackknife error by 2%: +- 0.1.
  const double r_xi = mean_of(xi_blocks) / sd_of(xi_fit), r_chi0 = mean_of(chi0_blocks) / sd_of(chi0_fit);
  const double r_single = mean_of(xi_single) / sd_of(xi_fit);
  std::printf("xi(t) error over the spread of 300 repeats: blocks of 4 %.3f (chi0 %.3f), single origins %.3f\n",
              r_xi, r_chi0, r_single);
  EXPECT_NEAR(r_xi, 0.83, 0.1);
  EXPECT_NEAR(r_chi0, 0.83, 0.1);
  EXPECT_NEAR(r_single, 0.5, 0.1);
}
