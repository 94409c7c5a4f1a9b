// The one-pass displacement kernel against brute force: Q_r on every grid,
// MSD of all and small particles, the x-displacement histogram, and the
// fastest/slowest subsets.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include "dynhet/analysis/displacement.hpp"

using namespace dynhet::analysis;

namespace {

struct System {
  long n;
  double box;
  std::vector<double> p0, pt;
  std::vector<std::uint8_t> species;
};

// Random positions in any periodic image, Gaussian displacements of width sd.
System random_system(long n, double box, double sd, unsigned seed) {
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g(0, sd);
  System s{n, box, std::vector<double>(2 * n), std::vector<double>(2 * n), std::vector<std::uint8_t>(n)};
  for (long i = 0; i < 2 * n; ++i) {
    s.p0[i] = box * u(gen) + box * std::floor(3 * u(gen) - 1);
    s.pt[i] = s.p0[i] + g(gen);
  }
  for (long i = 0; i < n; ++i) s.species[i] = i < n - n / 2 ? 0 : 1; // the project's layout
  return s;
}

DisplacementSpec spec_for(const System& s, const std::vector<int>& targets) {
  DisplacementSpec spec;
  for (int t : targets) spec.grids.push_back(make_subbox_grid(s.n, s.box, t));
  spec.cutoffs = {0.3, 0.6, 1.0};
  spec.hist_lo = -2.0, spec.hist_width = 0.1, spec.hist_bins = 40;
  return spec;
}

} // namespace

TEST(Displacement, SubboxOverlapEqualsOverlapKernelOnEveryGrid) {
  const System s = random_system(3000, 48.0, 0.5, 7);
  // Grids of 12 x 12, 5 x 5, 3 x 3 boxes and the whole system.
  const DisplacementSpec spec = spec_for(s, {20, 120, 333, 3000});
  const OriginIndex origin(s.p0.data(), s.n, spec);
  DisplacementResult r;
  displacement_pass(s.p0.data(), s.pt.data(), s.species.data(), s.n, origin, spec, r);
  const int nc = 3;
  for (size_t g = 0; g < spec.grids.size(); ++g) {
    std::vector<double> ref;
    overlap_subboxes(s.p0.data(), s.pt.data(), s.n, spec.grids[g], spec.cutoffs, ref);
    const int nb = spec.grids[g].per_side * spec.grids[g].per_side;
    for (int c = 0; c < nc; ++c)
      for (int b = 0; b < nb; ++b) EXPECT_DOUBLE_EQ(r.q_r[g * nc + c][b], ref[c * nb + b]) << g << " " << c;
  }
}

TEST(Displacement, MsdHistogramAndQMatchBruteForce) {
  const System s = random_system(5000, 60.0, 0.6, 11);
  const DisplacementSpec spec = spec_for(s, {50});
  const OriginIndex origin(s.p0.data(), s.n, spec);
  DisplacementResult r;
  std::vector<double> d2(s.n);
  displacement_pass(s.p0.data(), s.pt.data(), s.species.data(), s.n, origin, spec, r, d2.data());
  double all = 0, small = 0;
  long n_small = 0, out = 0;
  std::vector<long> hist[2] = {std::vector<long>(40, 0), std::vector<long>(40, 0)};
  std::vector<long> slow(3, 0);
  for (long i = 0; i < s.n; ++i) {
    const double dx = s.pt[2 * i] - s.p0[2 * i], dy = s.pt[2 * i + 1] - s.p0[2 * i + 1];
    EXPECT_EQ(d2[i], dx * dx + dy * dy);
    all += dx * dx + dy * dy;
    if (s.species[i] == 0) small += dx * dx + dy * dy, ++n_small;
    const double b = std::floor((dx + 2.0) / 0.1);
    if (b < 0 || b >= 40)
      ++out;
    else
      ++hist[s.species[i]][static_cast<int>(b)];
    for (int c = 0; c < 3; ++c) slow[c] += std::sqrt(dx * dx + dy * dy) < spec.cutoffs[c];
  }
  // Same sums in the same order: equal to rounding.
  EXPECT_NEAR(r.msd_all, all / s.n, 1e-12 * r.msd_all);
  EXPECT_NEAR(r.msd_small, small / n_small, 1e-12 * r.msd_small);
  EXPECT_EQ(r.n_small, n_small);
  EXPECT_EQ(r.hist_out, out);
  EXPECT_EQ(r.hist[0], hist[0]);
  EXPECT_EQ(r.hist[1], hist[1]);
  for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(r.q[c], double(slow[c]) / s.n);
  // The density integrates to the fraction inside the histogram.
  std::vector<long> both(40);
  for (int b = 0; b < 40; ++b) both[b] = hist[0][b] + hist[1][b];
  const DisplacementDensity d = displacement_density(spec, both, s.n);
  double integral = 0;
  for (double p : d.p) integral += p * spec.hist_width;
  EXPECT_NEAR(integral, 1.0 - double(out) / s.n, 1e-12);
}

TEST(Displacement, ManyGridsTakeTheGeneralPathWithTheSameAnswer) {
  // Sides m = 19, 17, 13, 11, 5, 4, 3 divide no other: seven indexed grids,
  // more than the unrolled cases; the whole box (m = 1) is summed. Each
  // grid alone must give the same chi4.
  const System s = random_system(4000, 50.0, 0.5, 3);
  const DisplacementSpec spec = spec_for(s, {11, 14, 24, 33, 160, 250, 444, 4000});
  const OriginIndex origin(s.p0.data(), s.n, spec);
  ASSERT_EQ(origin.indexed_grids(), 7);
  DisplacementResult all;
  displacement_pass(s.p0.data(), s.pt.data(), s.species.data(), s.n, origin, spec, all);
  for (size_t g = 0; g < spec.grids.size(); ++g) {
    DisplacementSpec one = spec;
    one.grids = {spec.grids[g]};
    const OriginIndex o1(s.p0.data(), s.n, one);
    DisplacementResult r1;
    displacement_pass(s.p0.data(), s.pt.data(), s.species.data(), s.n, o1, one, r1);
    for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(all.chi4[g * 3 + c], r1.chi4[c]);
  }
}

TEST(Displacement, NestedGridsShareOneIndex) {
  // m = 16, 8, 4, 2, 1: only the finest is indexed, the others are sums of
  // its boxes, and still equal the overlap kernel box by box.
  const System s = random_system(4096, 64.0, 0.5, 13);
  DisplacementSpec spec = spec_for(s, {16, 64, 256, 1024, 4096});
  spec.cutoffs = {0.2, 0.4, 0.6, 0.8, 1.0, 1.2}; // more than four cutoffs: the general rank loop
  const OriginIndex origin(s.p0.data(), s.n, spec);
  ASSERT_EQ(origin.indexed_grids(), 1);
  DisplacementResult r;
  displacement_pass(s.p0.data(), s.pt.data(), s.species.data(), s.n, origin, spec, r);
  for (size_t g = 0; g < spec.grids.size(); ++g) {
    std::vector<double> ref;
    overlap_subboxes(s.p0.data(), s.pt.data(), s.n, spec.grids[g], spec.cutoffs, ref);
    const int nb = spec.grids[g].per_side * spec.grids[g].per_side;
    for (int c = 0; c < 6; ++c)
      for (int b = 0; b < nb; ++b) EXPECT_DOUBLE_EQ(r.q_r[g * 6 + c][b], ref[c * nb + b]) << g << " " << c;
  }
}

TEST(Displacement, NestedGridsFromTargets) {
  // N = 10^5: ideal sides 63.2, 31.6, 15.8, 7.9, 3.95 and the whole box.
  const auto g = nested_subbox_grids(100000, 800.0, {400, 25, 100, 1600, 6400, 100000});
  const int want[] = {16, 64, 32, 8, 4, 1};
  for (int k = 0; k < 6; ++k) EXPECT_EQ(g[k].per_side, want[k]);
  EXPECT_DOUBLE_EQ(g[1].mean_particles, 100000.0 / 4096);
  DisplacementSpec spec;
  spec.grids = g;
  spec.cutoffs = {0.6};
  const std::vector<double> pos(200000, 1.0);
  EXPECT_EQ(OriginIndex(pos.data(), 100000, spec).indexed_grids(), 1);
}

TEST(Displacement, ExtremeSubsetsMatchASortedList) {
  const System s = random_system(2001, 40.0, 1.0, 5);
  std::vector<double> d2(s.n);
  for (long i = 0; i < s.n; ++i)
    d2[i] = std::pow(s.pt[2 * i] - s.p0[2 * i], 2) + std::pow(s.pt[2 * i + 1] - s.p0[2 * i + 1], 2);
  for (int which : {-1, 0}) {
    std::vector<double> v;
    for (long i = 0; i < s.n; ++i)
      if (which < 0 || s.species[i] == which) v.push_back(d2[i]);
    std::sort(v.begin(), v.end());
    const double f = which < 0 ? 0.1 : 0.2; // 10% of all, 20% of small ones
    const long k = std::lround(f * v.size());
    const ExtremeMsd e = msd_extremes(d2.data(), s.species.data(), s.n, f, which);
    EXPECT_EQ(e.count, k);
    EXPECT_NEAR(e.slow, std::accumulate(v.begin(), v.begin() + k, 0.0) / k, 1e-12);
    EXPECT_NEAR(e.fast, std::accumulate(v.end() - k, v.end(), 0.0) / k, 1e-12);
  }
}

TEST(Displacement, ExtremeSubsetsWithAReusedBufferMatchASortedList) {
  // One buffer for every call, as the node does: all, then small, then all
  // again; fractions from one particle to more than half (subsets overlap).
  const System s = random_system(1001, 30.0, 0.7, 9);
  std::vector<double> d2(s.n), buffer;
  for (long i = 0; i < s.n; ++i)
    d2[i] = std::pow(s.pt[2 * i] - s.p0[2 * i], 2) + std::pow(s.pt[2 * i + 1] - s.p0[2 * i + 1], 2);
  for (const double f : {0.1, 0.2, 0.001, 0.5, 0.7})
    for (int which : {-1, 0, 1, -1}) {
      std::vector<double> v;
      for (long i = 0; i < s.n; ++i)
        if (which < 0 || s.species[i] == which) v.push_back(d2[i]);
      std::sort(v.begin(), v.end());
      const long k = std::max(1L, std::lround(f * v.size()));
      const ExtremeMsd e = msd_extremes(d2.data(), s.species.data(), s.n, f, which, buffer);
      EXPECT_EQ(e.count, k);
      EXPECT_NEAR(e.slow, std::accumulate(v.begin(), v.begin() + k, 0.0) / k, 1e-12 * v.back());
      EXPECT_NEAR(e.fast, std::accumulate(v.end() - k, v.end(), 0.0) / k, 1e-12 * v.back());
    }
}

namespace {

// Fastest and slowest means of a set by a full sort: the reference.
ExtremeMsd sorted_extremes(const std::vector<double>& d2, const std::vector<std::uint8_t>& species,
                           double fraction, int which) {
  std::vector<double> v;
  for (size_t i = 0; i < d2.size(); ++i)
    if (which < 0 || species[i] == which) v.push_back(d2[i]);
  std::sort(v.begin(), v.end());
  const long m = static_cast<long>(v.size());
  if (m == 0) return {NAN, NAN, 0};
  const long k = std::min(m, std::max(1L, std::lround(fraction * m)));
  return {std::accumulate(v.end() - k, v.end(), 0.0) / k, std::accumulate(v.begin(), v.begin() + k, 0.0) / k, k};
}

// Both entry points (one set; all + small in one pass) against the sort,
// with one reused buffer. Returns the number of whole-set fallbacks.
int expect_extremes_match_sort(const std::vector<double>& d2, const std::vector<std::uint8_t>& species,
                               double f_all, double f_small, std::vector<double>& buffer, const char* what) {
  const long n = static_cast<long>(d2.size());
  const ExtremeMsd ref[2] = {sorted_extremes(d2, species, f_all, -1), sorted_extremes(d2, species, f_small, 0)};
  const ExtremeMsdAllSmall both = msd_extremes_all_small(d2.data(), species.data(), n, f_all, f_small, buffer);
  const ExtremeMsd one[2] = {msd_extremes(d2.data(), species.data(), n, f_all, -1, buffer),
                             msd_extremes(d2.data(), species.data(), n, f_small, 0, buffer)};
  const ExtremeMsd pair[2] = {both.all, both.small};
  int fallbacks = 0;
  for (int s = 0; s < 2; ++s)
    for (const ExtremeMsd& e : {pair[s], one[s]}) {
      const double tol = 1e-13 * std::max({std::abs(ref[s].fast), std::abs(ref[s].slow), 1e-300});
      EXPECT_EQ(e.count, ref[s].count) << what << " set " << s;
      if (ref[s].count == 0) {
        EXPECT_TRUE(std::isnan(e.fast) && std::isnan(e.slow)) << what;
        continue;
      }
      EXPECT_NEAR(e.fast, ref[s].fast, tol) << what << " set " << s;
      EXPECT_NEAR(e.slow, ref[s].slow, tol) << what << " set " << s;
      fallbacks += e.full_selections;
    }
  return fallbacks;
}

} // namespace

TEST(Displacement, SampledExtremesMatchASortOnTheNodesDistribution) {
  // Large enough for the sampled path; Gaussian displacements as in a run.
  const System s = random_system(30001, 120.0, 0.8, 11);
  std::vector<double> d2(s.n), buffer;
  for (long i = 0; i < s.n; ++i)
    d2[i] = std::pow(s.pt[2 * i] - s.p0[2 * i], 2) + std::pow(s.pt[2 * i + 1] - s.p0[2 * i + 1], 2);
  EXPECT_EQ(expect_extremes_match_sort(d2, s.species, 0.1, 0.2, buffer, "gaussian"), 0); // no fallback here
  for (const double f : {1e-6, 0.001, 0.3, 0.5, 0.7, 1.0}) // k = 1, k = n/2, overlapping subsets, k = n
    expect_extremes_match_sort(d2, s.species, f, f, buffer, "fractions");
}

TEST(Displacement, SampledExtremesFallBackWhereTheSampleMisleads) {
  std::vector<double> buffer;
  std::mt19937_64 gen(5);
  std::uniform_real_distribution<double> u(0, 1);
  for (const long n : {1L, 2L, 7L, 4095L, 4096L, 4097L, 20000L}) {
    std::vector<std::uint8_t> species(n);
    for (long i = 0; i < n; ++i) species[i] = i % 3 == 0; // small ones not in one block
    // All equal: every value is a tie of the bound.
    std::vector<double> d2(n, 0.25);
    expect_extremes_match_sort(d2, species, 0.1, 0.2, buffer, "all equal");
    // Few distinct values: wide runs of ties across the bounds.
    for (long i = 0; i < n; ++i) d2[i] = std::floor(4 * u(gen)) * 0.5;
    expect_extremes_match_sort(d2, species, 0.1, 0.2, buffer, "ties");
    expect_extremes_match_sort(d2, species, 1e-9, 0.5, buffer, "ties, k = 1 and n/2");
  }
  // Adversarial for a strided sample: values that the sampled positions see
  // as large (the rest tiny), or as tiny (the rest large), and a periodic
  // pattern; the bands then miss the bounds and the whole set is redone.
  const long n = 50000;
  const long samples = std::clamp(static_cast<long>(8 * std::sqrt(double(n))), 256L, 8192L);
  std::vector<std::uint8_t> species(n);
  for (long i = 0; i < n; ++i) species[i] = i < n / 2 ? 0 : 1;
  int fallbacks = 0;
  for (int pattern = 0; pattern < 3; ++pattern) {
    std::vector<double> d2(n);
    for (long i = 0; i < n; ++i) d2[i] = pattern == 2 ? (i % 97) * 0.01 : 1e-3 * u(gen);
    for (long j = 0; j < samples; ++j) {
      const long i = static_cast<long>((2 * j + 1) * static_cast<double>(n) / (2 * samples));
      if (pattern == 0) d2[i] = 10 + u(gen);
      if (pattern == 1) d2[i] = 1e-9 * u(gen);
    }
    if (pattern == 1)
      for (long i = 0; i < n; ++i) d2[i] = d2[i] < 1e-8 ? d2[i] : 5 + u(gen);
    fallbacks += expect_extremes_match_sort(d2, species, 0.1, 0.2, buffer, "adversarial");
  }
  EXPECT_GT(fallbacks, 0); // the fallback did run
  // Heavy tails (exponential in log), where a few values dominate the sums.
  std::vector<double> d2(n);
  for (long i = 0; i < n; ++i) d2[i] = std::exp(30 * (u(gen) - 0.5));
  expect_extremes_match_sort(d2, species, 0.1, 0.2, buffer, "heavy tail");
  // No small particles at all.
  std::vector<std::uint8_t> large(n, 1);
  expect_extremes_match_sort(d2, large, 0.1, 0.2, buffer, "no small");
}

TEST(Displacement, CollectiveModesCarryAFlowAndNothingElse) {
  // Independent displacements (sd 0.3) plus a shear flow A sin(2 pi y / L)
  // along x (transverse, n = (0, 1)) and a compression wave B cos(4 pi x / L)
  // along x (longitudinal, n = (2, 0)). 2 |u_k . e|^2 - MSD/N of each mode
  // is A^2 / 2 and B^2 / 2 there and 0 elsewhere, up to the noise of N
  // independent displacements (MSD / N per mode, about 2e-5 here) and, on
  // the two waves, the sampling of the wave by N random positions (relative
  // error of u_k about 1 / sqrt(N), so 3 x 2 / sqrt(N) of A^2 / 2 at most).
  System s = random_system(20000, 40.0, 0.3, 11);
  const double a = 0.5, b = 0.2, two_pi_l = 2 * M_PI / s.box;
  double msd = 0;
  for (long i = 0; i < s.n; ++i) {
    s.pt[2 * i] += a * std::sin(two_pi_l * s.p0[2 * i + 1]) + b * std::cos(2 * two_pi_l * s.p0[2 * i]);
    msd += (std::pow(s.pt[2 * i] - s.p0[2 * i], 2) + std::pow(s.pt[2 * i + 1] - s.p0[2 * i + 1], 2)) / s.n;
  }
  const WaveModes w = collective_modes(s.p0.data(), s.pt.data(), s.n, s.box, 3, msd);
  ASSERT_EQ(w.nx.size(), 14u); // 28 lattice points with 0 < |n| <= 3, one of each pair
  const double noise = 8 * msd / s.n; // 8 x the per-mode floor
  for (size_t k = 0; k < w.nx.size(); ++k) {
    const bool shear = w.nx[k] == 0 && w.ny[k] == 1, wave = w.nx[k] == 2 && w.ny[k] == 0;
    const double sampling = 6 / std::sqrt(double(s.n));
    EXPECT_NEAR(w.transverse[k], shear ? a * a / 2 : 0.0, noise + (shear ? sampling * a * a / 2 : 0))
        << w.nx[k] << "," << w.ny[k];
    EXPECT_NEAR(w.longitudinal[k], wave ? b * b / 2 : 0.0, noise + (wave ? sampling * b * b / 2 : 0))
        << w.nx[k] << "," << w.ny[k];
  }
}
