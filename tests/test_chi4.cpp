// chi4(t), eq. (14), against a direct two-loop computation and known
// answers: the pooled estimator unbiased where eq. (14) as written is low
// (few, correlated sub-boxes), its error against the spread of independent
// runs; chi4^P and tau4; tau_alpha per waiting time.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "dynhet/analysis/chi4.hpp"
#include "dynhet/analysis/displacement.hpp"
#include "dynhet/analysis/fits.hpp"
#include "dynhet/analysis/timescales.hpp"

using namespace dynhet::analysis;

namespace {

// Positions in [0, box) and their displacements: slow (|dr| = 0.1) with
// probability p_slow, else fast (|dr| = 2), independently.
void bernoulli_frames(long n, double box, double p_slow, std::mt19937_64& gen, std::vector<double>& p0,
                      std::vector<double>& pt) {
  std::uniform_real_distribution<double> u(0, 1);
  p0.resize(2 * n), pt.resize(2 * n);
  for (long i = 0; i < n; ++i) {
    p0[2 * i] = box * u(gen), p0[2 * i + 1] = box * u(gen);
    const double step = u(gen) < p_slow ? 0.1 : 2.0;
    pt[2 * i] = p0[2 * i] + step, pt[2 * i + 1] = p0[2 * i + 1];
  }
}

} // namespace

TEST(Chi4, MatchesTwoLoopComputation) {
  std::mt19937_64 gen(17);
  std::normal_distribution<double> g(0, 0.6);
  std::uniform_real_distribution<double> u(0, 1);
  const long n = 2500;
  const double box = 50.0;
  std::vector<double> p0(2 * n), pt(2 * n);
  for (long i = 0; i < 2 * n; ++i) p0[i] = box * (3 * u(gen) - 1), pt[i] = p0[i] + g(gen);
  const std::vector<std::uint8_t> species(n, 0);
  DisplacementSpec spec;
  for (int target : {25, 100, 400}) spec.grids.push_back(make_subbox_grid(n, box, target));
  spec.cutoffs = {0.4, 0.8};
  const OriginIndex origin(p0.data(), n, spec);
  DisplacementResult r;
  displacement_pass(p0.data(), pt.data(), species.data(), n, origin, spec, r);
  for (size_t gi = 0; gi < spec.grids.size(); ++gi) {
    const SubboxGrid& grid = spec.grids[gi];
    const int m = grid.per_side;
    const double w = box / m;
    for (int c = 0; c < 2; ++c) {
      // Loop over the sub-boxes, and inside over all particles.
      double s1 = 0, s2 = 0;
      for (int bx = 0; bx < m; ++bx)
        for (int by = 0; by < m; ++by) {
          long slow = 0;
          for (long i = 0; i < n; ++i) {
            const double x = std::fmod(std::fmod(p0[2 * i], box) + box, box);
            const double y = std::fmod(std::fmod(p0[2 * i + 1], box) + box, box);
            if (x < bx * w || x >= (bx + 1) * w || y < by * w || y >= (by + 1) * w) continue;
            slow += std::hypot(pt[2 * i] - p0[2 * i], pt[2 * i + 1] - p0[2 * i + 1]) < spec.cutoffs[c];
          }
          const double q = slow / grid.mean_particles;
          s1 += q, s2 += q * q;
        }
      const double nb = m * m, chi4 = grid.mean_particles * (s2 / nb - (s1 / nb) * (s1 / nb));
      // Both sum the same integers in different orders: equal to rounding.
      EXPECT_NEAR(r.chi4[gi * 2 + c], chi4, 1e-12 * chi4) << "grid " << m << " cutoff " << c;
      EXPECT_NEAR(r.q_r_sum[gi * 2 + c], s1, 1e-12 * s1);
    }
  }
}

TEST(Chi4, IndependentMobilityGivesQTimesOneMinusOneOverBoxes) {
  // Particles slow independently with probability p: the slow count of a
  // sub-box is multinomial, so E[chi4] = p (1 - 1/n_boxes) (whatever N);
  // the origin average must agree within 4 standard errors.
  std::mt19937_64 gen(23);
  const long n = 4096;
  const double box = 64.0, p = 0.3;
  const int origins = 60;
  const SubboxGrid grid = make_subbox_grid(n, box, 64); // 8 x 8
  DisplacementSpec spec;
  spec.grids = {grid};
  spec.cutoffs = {0.6};
  Chi4Accumulator acc(origins, {1.0}, grid);
  const std::vector<std::uint8_t> species(n, 0);
  std::vector<double> p0, pt;
  for (int k = 0; k < origins; ++k) {
    bernoulli_frames(n, box, p, gen, p0, pt);
    const OriginIndex origin(p0.data(), n, spec);
    DisplacementResult r;
    displacement_pass(p0.data(), pt.data(), species.data(), n, origin, spec, r);
    acc.add(k, 0, r.q_r_sum[0], r.q_r_sum2[0]);
  }
  const auto res = acc.result();
  EXPECT_EQ(res.n_origins[0], origins);
  EXPECT_NEAR(res.chi4_per_origin[0], p * (1 - 1.0 / 64), 4 * res.chi4_per_origin_err[0]);
  // Pooled over all boxes of all origins, n_r is Binomial(n, p/n_boxes):
  // N var(Q_r) = p (1 - p/n_boxes).
  EXPECT_NEAR(res.chi4[0], p * (1 - p / 64), 4 * res.chi4_err[0]);
}

namespace {
// Synthetic sub-box overlaps of a 3 x 3 grid: Q_r = m_k + e_r, a part m_k
// common to the nine boxes of origin k (variance var_m: the boxes are
// correlated, as neighbouring boxes of a real system are) and a part of
// each box (variance var_e). The true chi4 = N (var_m + var_e); eq. (14)
// as written expects N var_e (1 - 1/9).
Chi4Accumulator correlated_boxes(int origins, double var_m, double var_e, std::mt19937_64& gen) {
  const SubboxGrid grid = make_subbox_grid(4096, 64.0, 455);
  std::normal_distribution<double> m(0, std::sqrt(var_m)), e(0, std::sqrt(var_e));
  Chi4Accumulator acc(origins, {1.0}, grid, 1.0);
  for (int k = 0; k < origins; ++k) {
    const double mk = 0.4 + m(gen);
    double s1 = 0, s2 = 0;
    for (int b = 0; b < 9; ++b) {
      const double q = mk + e(gen);
      s1 += q, s2 += q * q;
    }
    acc.add(k, 0, s1, s2);
  }
  return acc;
}
} // namespace

TEST(Chi4, FewCorrelatedSubboxesBiasEq14LowAndThePooledEstimatorIsUnbiased) {
  std::mt19937_64 gen(41);
  const double var_m = 2e-3, var_e = 6e-3;
  const Chi4Accumulator acc = correlated_boxes(20000, var_m, var_e, gen);
  const auto r = acc.result();
  const double n_r = make_subbox_grid(4096, 64.0, 455).mean_particles;
  ASSERT_NEAR(n_r, 4096 / 9.0, 1e-9);
  const double truth = n_r * (var_m + var_e), eq14 = n_r * var_e * 8 / 9;
  EXPECT_NEAR(r.chi4[0], truth, 4 * r.chi4_err[0]);
  EXPECT_NEAR(r.chi4_per_origin[0], eq14, 4 * r.chi4_per_origin_err[0]);
  // The bias is real, far outside the errors: a third of chi4 here.
  EXPECT_GT(truth - r.chi4_per_origin[0], 10 * r.chi4_per_origin_err[0]);
}

TEST(Chi4, PooledErrorMatchesTheSpreadOfIndependentRuns) {
  // 300 runs of 40 independent origins: the jackknife error of each run's
  // chi4, on average, against the standard deviation of chi4 over the
  // runs (within 15%: the spread of 300 values is known to about 4%).
  std::mt19937_64 gen(43);
  std::vector<double> values, errors;
  for (int run = 0; run < 300; ++run) {
    const auto r = correlated_boxes(40, 2e-3, 6e-3, gen).result();
    values.push_back(r.chi4[0]), errors.push_back(r.chi4_err[0]);
  }
  double mean = 0, sd = 0, err = 0;
  for (double v : values) mean += v / values.size();
  for (double v : values) sd += (v - mean) * (v - mean) / (values.size() - 1);
  for (double e : errors) err += e / errors.size();
  sd = std::sqrt(sd);
  EXPECT_NEAR(err / sd, 1.0, 0.15) << "mean error " << err << " spread " << sd;
}

TEST(Chi4, WholeBoxUsesTheVarianceOverOrigins) {
  // One sub-box: the within-origin variance is zero, the pooled one is the
  // variance of Q over origins times N_tot, here set by hand.
  const SubboxGrid whole = make_subbox_grid(100, 10.0, 100);
  ASSERT_EQ(whole.per_side, 1);
  Chi4Accumulator acc(3, {1.0, 2.0, 4.0}, whole);
  const double q[3] = {0.5, 0.6, 0.7};
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j) acc.add(k, j, q[k] * (j + 1) / 3, std::pow(q[k] * (j + 1) / 3, 2));
  const auto r = acc.result();
  for (int j = 0; j < 3; ++j) {
    EXPECT_NEAR(r.chi4_per_origin[j], 0.0, 1e-12);
    const double f = (j + 1) / 3.0; // sample variance of {0.5, 0.6, 0.7} f is 0.01 f^2
    EXPECT_NEAR(r.chi4[j], 100 * 0.01 * f * f, 1e-12);
    // Jackknife by hand: leaving out 0.5, 0.6 or 0.7 leaves sample variances
    // 0.005, 0.02, 0.005 (times f^2), so N var = 0.5, 2, 0.5 f^2; their mean
    // is f^2 and sqrt((n-1)/n sum (x - mean)^2) = sqrt(2/3 * 1.5) f^2 = f^2.
    EXPECT_NEAR(r.chi4_err[j], f * f, 1e-12);
  }
  EXPECT_FALSE(r.tau4_interior); // the largest value at the last lag: a bound
  EXPECT_FALSE(std::isnan(r.chi4_peak));
  EXPECT_DOUBLE_EQ(r.tau4, 4.0); // grows to the last lag: the peak is at the end
}

TEST(Chi4, PeakOfAParabolaInLnTIsExact) {
  std::vector<double> t, y;
  for (int j = 0; j <= 24; ++j) t.push_back(0.1 * std::pow(10.0, j / 8.0));
  const double ln_tau4 = std::log(3.3);
  for (double x : t) y.push_back(12.0 - 2.0 * std::pow(std::log(x) - ln_tau4, 2));
  const Peak p = find_peak(t, y);
  EXPECT_TRUE(p.interior);
  EXPECT_NEAR(p.t, 3.3, 1e-10);
  EXPECT_NEAR(p.y, 12.0, 1e-10);
}

TEST(Chi4, PeakIsContinuousWhenTheLargestPointMovesToTheNextLag) {
  // A flat top, lags 10 and 11 equal to 1e-6: the largest point moves from
  // lag 10 to lag 11 when y[11] rises by 2e-6, and the fit over the half
  // maximum moves by about as much (the three-point vertex jumped by 0.02
  // in ln t, from the parabola through lags 9-11 to the one through 10-12).
  std::vector<double> t, y;
  for (int j = 0; j <= 20; ++j) t.push_back(std::pow(10.0, j / 8.0));
  const double xm = std::log(t[10]) + 0.1;
  for (double x : t) y.push_back(5.0 * std::exp(-std::pow(std::log(x) - xm, 2) / 2));
  y[11] = y[10] - 1e-6;
  ASSERT_EQ(peak_index(y), 10);
  const Peak a = find_peak(t, y);
  y[11] += 2e-6;
  ASSERT_EQ(peak_index(y), 11);
  const Peak b = find_peak(t, y);
  EXPECT_NEAR(std::log(b.t), std::log(a.t), 1e-5);
  EXPECT_NEAR(b.y, a.y, 1e-5);
  EXPECT_TRUE(a.interior);
  EXPECT_EQ(a.last - a.first, b.last - b.first);
  // Only the first lag above half maximum: a bound, not a peak.
  std::vector<double> falling(t.size());
  for (size_t j = 0; j < t.size(); ++j) falling[j] = 10.0 - j;
  const Peak f = find_peak(t, falling);
  EXPECT_FALSE(f.interior);
  EXPECT_EQ(f.first, 0);
  EXPECT_LE(f.t, t[f.last]);
  EXPECT_TRUE(std::isnan(find_peak(t, std::vector<double>(t.size(), NAN)).y));
}

TEST(Chi4, PeakErrorFromTheOriginJackknifeMatchesTheSpreadAndTheNoiseAddsNoBias) {
  // 24 origins, each a Gaussian peak in ln t whose height and position vary
  // from origin to origin, plus independent noise at every lag: the
  // per-origin terms of eq. (14) on a sub-box grid. Over 3000 realisations,
  // the spread of chi4^P and ln tau4 from the mean curve against the mean
  // jackknife error (origins independent: blocks of 1), and the mean
  // estimate against the estimate of the expected mean curve.
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g;
  std::vector<double> t;
  for (int j = 0; j <= 20; ++j) t.push_back(std::pow(10.0, j / 8.0));
  const int n = 24, nl = static_cast<int>(t.size()), reps = 3000;
  const double x0 = std::log(t[12]) + 0.1, width = 0.8;
  auto shape = [&](double x, double h, double c) { return h * std::exp(-std::pow(x - c, 2) / (2 * width * width)); };
  // The expected mean curve: the position's spread 0.3 broadens the peak.
  const double w2 = width * width + 0.09, top = 3.0 * width / std::sqrt(w2);
  std::vector<double> truth(nl);
  for (int j = 0; j < nl; ++j) truth[j] = top * std::exp(-std::pow(std::log(t[j]) - x0, 2) / (2 * w2));
  const Peak clean = find_peak(t, truth);
  double sp = 0, sp2 = 0, st = 0, st2 = 0, ep = 0, et = 0;
  for (int r = 0; r < reps; ++r) {
    std::vector<double> table(size_t(n) * nl), mean(nl, 0.0);
    for (int k = 0; k < n; ++k) {
      const double h = 3.0 * (1 + 0.3 * g(rng)), c = x0 + 0.3 * g(rng);
      for (int j = 0; j < nl; ++j) {
        table[size_t(k) * nl + j] = shape(std::log(t[j]), h, c) + 0.3 * g(rng);
        mean[j] += table[size_t(k) * nl + j] / n;
      }
    }
    const Peak p = find_peak(t, mean);
    sp += p.y, sp2 += p.y * p.y, st += std::log(p.t), st2 += std::log(p.t) * std::log(p.t);
    const auto e = origin_jackknife(table, n, nl, [&](const std::vector<double>& m) {
      const Peak q = find_peak(t, m);
      return std::vector<double>{q.y, std::log(q.t)};
    }, 1);
    ep += e[0] / reps, et += e[1] / reps;
  }
  const double mp = sp / reps, mt = st / reps;
  const double sdp = std::sqrt(sp2 / reps - mp * mp), sdt = std::sqrt(st2 / reps - mt * mt);
  // The sampling noise of 3000 realisations on a standard deviation is
  // 1.3%; the jackknife's own bias at 24 origins a few %.
  EXPECT_NEAR(ep / sdp, 1.0, 0.08);
  EXPECT_NEAR(et / sdt, 1.0, 0.08);
  // No bias from the noise beyond 4 standard errors of the mean (the
  // three-point vertex of the largest point was 1.4 sd of one run high).
  EXPECT_NEAR(mp, clean.y, 4 * sdp / std::sqrt(reps));
  EXPECT_NEAR(mt, std::log(clean.t), 4 * sdt / std::sqrt(reps));
  // The fit's own bias on a Gaussian top: the vertex height within 1.5%.
  EXPECT_NEAR(clean.y, top, 0.015 * top);
  EXPECT_NEAR(std::log(clean.t), x0, 0.02);
}

TEST(Chi4, TauAlphaPerWaitingTime) {
  // Origin k decays as exp(-t/tau_k): its own tau_alpha is tau_k, to the
  // accuracy of linear interpolation in ln t over 1/40 decade (< 1e-3 relative).
  std::vector<double> lags;
  for (int j = 0; j <= 100; ++j) lags.push_back(0.1 * std::pow(10.0, j / 40.0));
  const std::vector<double> taus{2.0, 2.5, 1.5, 4.0};
  OverlapAccumulator acc(4, lags);
  for (int k = 0; k < 4; ++k)
    for (size_t j = 0; j < lags.size(); ++j) {
      const double v = std::exp(-lags[j] / taus[k]);
      acc.add(k, static_cast<int>(j), &v, 1);
    }
  const auto tau = tau_alpha_per_origin(acc, lags, 4);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(tau[k], taus[k], 1e-3 * taus[k]);
  EXPECT_EQ(nearest_lag(lags, 2.0), 52); // 0.1 * 10^(52/40) = 1.995
}

// The error of each origin's tau_alpha(t0) against the spread of that
// origin over independent runs. Origin k (t0 = k) has tau_alpha(t0) =
// 2 + drift t0 + sigma e_k, the noise e_k the mean of the w = 4 normals
// k .. k + 3 (unit variance): origins closer than the window share noise,
// as origins whose windows overlap share trajectory. The lag just past the
// run's tau_alpha is the window w, so each origin's partner is 4 later and
// independent of it: the estimate has the variance sigma^2 +
// (drift w)^2 / 2. The standard deviation over all origins would hold the
// whole drift, and adjacent origins would see a quarter of the noise.
TEST(Chi4, TauAlphaPerOriginErrorIsTheSpreadOfOneOriginOverRuns) {
  const int n = 24, w = 4, runs = 2000;
  const double sigma = 0.3, drift = 0.01;
  const std::vector<double> lags{0.5, 1.0, 2.0, 4.0, 8.0}; // the run's tau_alpha 2.5: window 4
  std::vector<double> t0(n);
  for (int k = 0; k < n; ++k) t0[k] = k;
  std::mt19937_64 rng(23);
  std::normal_distribution<double> g;
  double sum_err2 = 0;
  std::vector<double> sum(n, 0.0), sum2(n, 0.0);
  for (int r = 0; r < runs; ++r) {
    std::vector<double> white(n + w), tau(n);
    for (double& v : white) v = g(rng);
    for (int k = 0; k < n; ++k) {
      double e = 0;
      for (int i = 0; i < w; ++i) e += white[k + i] / std::sqrt(double(w));
      tau[k] = 2.0 + drift * t0[k] + sigma * e;
      sum[k] += tau[k], sum2[k] += tau[k] * tau[k];
    }
    const std::vector<double> err = tau_alpha_per_origin_error(t0, tau, lags, 2.5);
    for (int k = 1; k < n; ++k) ASSERT_EQ(err[k], err[0]); // one value for every origin
    sum_err2 += err[0] * err[0] / runs;
  }
  // The spread of each origin over the runs, pooled over the origins.
  double spread2 = 0;
  for (int k = 0; k < n; ++k) spread2 += (sum2[k] / runs - sum[k] * sum[k] / (double(runs) * runs)) / n;
  const double expected = std::sqrt(sigma * sigma + drift * drift * w * w / 2);
  // The mean of 2000 squared estimates (each of ~20 pairs) is uncertain by
  // under 1%, the pooled spread by about 2% (correlated origins): 4% of
  // the variance.
  EXPECT_NEAR(std::sqrt(sum_err2) / std::sqrt(spread2), expected / sigma, 0.04);
  EXPECT_NEAR(std::sqrt(spread2), sigma, 0.02 * sigma);
  // Nothing to say where tau_alpha is unknown or beyond the lags, or with
  // too few pairs (6 origins a unit apart: (0, 4) and (1, 5) only); an
  // origin without a crossing has no error, and equal values have none.
  std::vector<double> tau(n, 2.0);
  tau[3] = NAN;
  EXPECT_TRUE(std::isnan(tau_alpha_per_origin_error(t0, tau, lags, NAN)[0]));
  EXPECT_TRUE(std::isnan(tau_alpha_per_origin_error(t0, tau, lags, 9.0)[0]));
  const std::vector<double> few_t0(t0.begin(), t0.begin() + 6), few(6, 2.0);
  EXPECT_TRUE(std::isnan(tau_alpha_per_origin_error(few_t0, few, lags, 2.5)[0]));
  const std::vector<double> e = tau_alpha_per_origin_error(t0, tau, lags, 2.5);
  EXPECT_EQ(e[0], 0.0);
  EXPECT_TRUE(std::isnan(e[3]));
}
