// Clusters of slow/fast particles (sec. 3.3): g_ab(r) and its first
// minimum, neighbour pairs, clusters and R_g across the periodic boundary,
// P(N_c) with its power-law and log-normal fits, and d_f.
#include <cmath>
#include <map>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include "dynhet/analysis/clusters.hpp"

using namespace dynhet::analysis;

namespace {

constexpr double kPi = 3.14159265358979323846;

double fold(double x, double box) { return x - box * std::floor(x / box); }
double min_image(double d, double box) { return d - box * std::round(d / box); }

struct Layout {
  std::vector<double> pos;
  std::vector<std::uint8_t> species, selected;
  void add(double x, double y, bool sel = true, int s = 0) {
    pos.push_back(x), pos.push_back(y), species.push_back(s), selected.push_back(sel);
  }
  long n() const { return static_cast<long>(species.size()); }
};

// The cluster holding particle i.
const Cluster& cluster_of(const ClusterSet& c, long i) { return c.clusters.at(c.label.at(i)); }

} // namespace

TEST(Clusters, HandBuiltLayoutAcrossThePeriodicBoundary) {
  const double box = 20.0;
  Layout l;
  // A: a chain of 5 crossing x = 0 (one given unwrapped, at 20.5): unwrapped
  // x = 17.5..21.5, so R_g^2 = (4+1+0+1+4)/5 = 2 and the centre is x = 19.5.
  for (double x : {17.5, 18.5, 19.5, 20.5, 1.5}) l.add(x, 5.0);
  // B: a square of side 0.8 around the corner: R_g^2 = 2 * 0.4^2, centre (0, 0).
  for (double x : {19.6, 0.4})
    for (double y : {19.6, 0.4}) l.add(x, y);
  // C: a row all around the box at y = 12: joined to its own image, it spans.
  for (int k = 0; k < 20; ++k) l.add(0.5 + k, 12.0);
  // D: two selected particles bridged only by an unselected one stay apart.
  l.add(10.0, 2.0), l.add(11.0, 2.0, false), l.add(12.0, 2.0);
  const NeighbourCutoffs cut{{1.2, 1.2, 1.2}};
  const NeighbourPairs nb = neighbour_pairs(l.pos.data(), l.species.data(), l.n(), box, cut);
  const ClusterSet c = find_clusters(nb, l.pos.data(), box, l.selected.data());
  ASSERT_EQ(c.clusters.size(), 5u);
  const Cluster& a = cluster_of(c, 0);
  EXPECT_EQ(a.size, 5);
  EXPECT_FALSE(a.spans);
  EXPECT_NEAR(a.radius_of_gyration, std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(a.cx, 19.5, 1e-12);
  EXPECT_NEAR(a.cy, 5.0, 1e-12);
  const Cluster& b = cluster_of(c, 5);
  EXPECT_EQ(b.size, 4);
  EXPECT_NEAR(b.radius_of_gyration, std::sqrt(2 * 0.16), 1e-12);
  EXPECT_NEAR(min_image(b.cx, box), 0.0, 1e-12);
  EXPECT_NEAR(min_image(b.cy, box), 0.0, 1e-12);
  const Cluster& row = cluster_of(c, 9);
  EXPECT_EQ(row.size, 20);
  EXPECT_TRUE(row.spans);
  EXPECT_TRUE(std::isnan(row.radius_of_gyration));
  EXPECT_EQ(c.label[30], -1); // the unselected bridge
  EXPECT_NE(c.label[29], c.label[31]);
  EXPECT_EQ(cluster_of(c, 29).size, 1);
  EXPECT_EQ(cluster_of(c, 29).radius_of_gyration, 0.0);
}

TEST(Clusters, NeighbourCutoffDependsOnTheSpeciesPair) {
  Layout l;
  l.add(5.0, 5.0, true, 0), l.add(6.1, 5.0, true, 1);   // small-large at 1.1: r12 = 1.0, apart
  l.add(5.0, 9.0, true, 1), l.add(6.1, 9.0, true, 1);   // large-large at 1.1: r22 = 1.5, neighbours
  l.add(5.0, 13.0, true, 0), l.add(6.1, 13.0, true, 0); // small-small at 1.1: r11 = 1.0, apart
  const NeighbourPairs nb = neighbour_pairs(l.pos.data(), l.species.data(), l.n(), 20.0, {{1.0, 1.0, 1.5}});
  ASSERT_EQ(nb.pairs.size(), 1u);
  EXPECT_EQ(nb.pairs[0][0], 2);
  EXPECT_EQ(nb.pairs[0][1], 3);
}

TEST(Clusters, RandomLayoutMatchesBruteForce) {
  std::mt19937_64 gen(31);
  std::uniform_real_distribution<double> u(0, 1);
  const long n = 1500;
  const double box = 40.0;
  Layout l;
  for (long i = 0; i < n; ++i)
    l.add(box * (3 * u(gen) - 1), box * (3 * u(gen) - 1), u(gen) < 0.5, u(gen) < 0.5);
  const NeighbourCutoffs cut{{1.0, 1.2, 1.4}};
  const ClusterSet c = find_clusters(neighbour_pairs(l.pos.data(), l.species.data(), n, box, cut),
                                     l.pos.data(), box, l.selected.data());
  // Brute force: union-find over all selected pairs.
  std::vector<long> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](long i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (long i = 0; i < n; ++i)
    for (long j = i + 1; j < n; ++j) {
      if (!l.selected[i] || !l.selected[j]) continue;
      const double dx = min_image(l.pos[2 * j] - l.pos[2 * i], box),
                   dy = min_image(l.pos[2 * j + 1] - l.pos[2 * i + 1], box);
      if (std::hypot(dx, dy) < cut.r[l.species[i] + l.species[j]]) parent[root(i)] = root(j);
    }
  // Same partition: label <-> root is one to one.
  std::map<long, int> root_to_label;
  std::map<int, long> label_to_root;
  for (long i = 0; i < n; ++i) {
    if (!l.selected[i]) {
      EXPECT_EQ(c.label[i], -1);
      continue;
    }
    const long r = root(i);
    EXPECT_EQ(root_to_label.emplace(r, c.label[i]).first->second, c.label[i]);
    EXPECT_EQ(label_to_root.emplace(c.label[i], r).first->second, r);
  }
  EXPECT_EQ(root_to_label.size(), c.clusters.size());
  // R_g: move the cluster's centre to the middle of the box, fold, and take
  // R_g of the folded positions directly (the clusters here are far smaller
  // than box/2, so none crosses the boundary once centred).
  int checked = 0;
  for (size_t k = 0; k < c.clusters.size(); ++k) {
    const Cluster& cl = c.clusters[k];
    if (cl.size < 2) continue;
    ASSERT_FALSE(cl.spans);
    double sx = 0, sy = 0, s2 = 0;
    for (long i = 0; i < n; ++i) {
      if (c.label[i] != static_cast<int>(k)) continue;
      const double x = fold(l.pos[2 * i] - cl.cx + box / 2, box),
                   y = fold(l.pos[2 * i + 1] - cl.cy + box / 2, box);
      sx += x, sy += y, s2 += x * x + y * y;
    }
    const double m = double(cl.size);
    EXPECT_NEAR(cl.radius_of_gyration, std::sqrt(s2 / m - (sx / m) * (sx / m) - (sy / m) * (sy / m)), 1e-9);
    EXPECT_NEAR(sx / m, box / 2, 1e-9); // the centre was right
    ++checked;
  }
  EXPECT_GT(checked, 50);
}

TEST(Clusters, PairDistributionMatchesBruteForce) {
  std::mt19937_64 gen(37);
  std::uniform_real_distribution<double> u(0, 1);
  const long n = 800;
  const double box = 30.0, r_max = 6.0, dr = 0.2;
  std::vector<double> pos(2 * n);
  std::vector<std::uint8_t> sp(n);
  for (long i = 0; i < n; ++i) pos[2 * i] = box * u(gen), pos[2 * i + 1] = box * u(gen), sp[i] = i % 2;
  const PairDistribution g = pair_distribution(pos.data(), sp.data(), n, box, r_max, dr);
  ASSERT_EQ(g.r.size(), 30u);
  std::vector<std::vector<double>> count(3, std::vector<double>(30, 0.0));
  for (long i = 0; i < n; ++i)
    for (long j = i + 1; j < n; ++j) {
      const double r = std::hypot(min_image(pos[2 * j] - pos[2 * i], box),
                                  min_image(pos[2 * j + 1] - pos[2 * i + 1], box));
      if (r < r_max) ++count[sp[i] + sp[j]][static_cast<int>(r / dr)];
    }
  const double na = n / 2.0, pairs[3] = {na * (na - 1) / 2, na * na, na * (na - 1) / 2};
  double total = 0, expected = 0;
  for (int p = 0; p < 3; ++p)
    for (int k = 0; k < 30; ++k) {
      const double ideal = pairs[p] * kPi * dr * dr * ((k + 1.0) * (k + 1) - double(k) * k) / (box * box);
      EXPECT_NEAR(g.g[p][k], count[p][k] / ideal, 1e-12);
      total += count[p][k], expected += ideal;
    }
  // Uncorrelated positions: g = 1 on average, to Poisson accuracy (4 sigma).
  EXPECT_NEAR(total, expected, 4 * std::sqrt(expected));
}

TEST(Clusters, FirstMinimumOfASmoothedNoisyCurve) {
  // g = 1 + 1.5 e^{-x} cos(2 pi x), x = r - 2, beyond a core: first peak at
  // x = -0.0251, first minimum at x = 1/2 - atan(1/(2 pi))/(2 pi) = 0.474874.
  std::mt19937_64 gen(41);
  std::normal_distribution<double> noise(0, 0.02);
  std::vector<double> r, g;
  for (int k = 0; k < 500; ++k) {
    r.push_back(0.005 + 0.01 * k);
    const double x = r.back() - 2;
    g.push_back(r.back() < 1.75 ? 0.0 : 1 + 1.5 * std::exp(-x) * std::cos(2 * kPi * x) + noise(gen));
  }
  // Smoothed noise (sd ~0.005) shifts the minimum by ~0.003, the smoothing
  // itself by less than 0.005: 0.02 is over 4 sigma.
  EXPECT_NEAR(first_minimum(r, g, 0.05), 2.474874, 0.02);
}

TEST(Clusters, PowerLawSizesGiveKappa) {
  // Sizes drawn from P(n) ~ n^-1.8, n = 1..10^5, by the inverse CDF.
  std::mt19937_64 gen(43);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<double> cdf(100001, 0.0);
  for (int k = 1; k <= 100000; ++k) cdf[k] = cdf[k - 1] + std::pow(double(k), -1.8);
  std::vector<long> sizes;
  for (int s = 0; s < 200000; ++s)
    sizes.push_back(std::lower_bound(cdf.begin(), cdf.end(), u(gen) * cdf.back()) - cdf.begin());
  const SizeHistogram h = cluster_size_distribution(sizes, 5);
  EXPECT_EQ(h.total, 200000);
  double norm = 0;
  for (size_t b = 0; b < h.p.size(); ++b) norm += h.p[b] * (h.hi[b] - h.lo[b] + 1);
  EXPECT_NEAR(norm, 1.0, 1e-12); // P(N_c) sums to one over sizes
  const PowerLawFit f = fit_power_law(h, 1, 10000);
  EXPECT_LT(f.kappa_err, 0.02);
  EXPECT_NEAR(f.kappa, 1.8, 4 * f.kappa_err); // statistical: 4 sigma of the fit
}

TEST(Clusters, LogNormalSizesGiveN0AndSigma) {
  std::mt19937_64 gen(47);
  std::normal_distribution<double> g(std::log(100.0), 1.0);
  std::vector<long> sizes;
  for (int s = 0; s < 100000; ++s) sizes.push_back(std::max(1L, std::lround(std::exp(g(gen)))));
  const LogNormalFit f = fit_log_normal(cluster_size_distribution(sizes, 5));
  EXPECT_NEAR(f.sigma, 1.0, 4 * f.sigma_err);
  EXPECT_NEAR(f.n0, 100.0, 4 * f.n0_err);
  EXPECT_NEAR(f.n_sigma, f.n0 * std::exp(-f.sigma * f.sigma), 1e-9 * f.n0);
  EXPECT_LT(f.sigma_err, 0.02);
}

namespace {

// Selected particles on lattice sites filling given shapes, far apart, in a
// box of side `box`; returns the clusters (cutoff 1.1: lattice neighbours).
ClusterSet lattice_shapes(double box, const std::vector<std::vector<std::array<int, 2>>>& shapes) {
  Layout l;
  int slot = 0;
  const int per_row = static_cast<int>(box / 100);
  for (const auto& sh : shapes) {
    const double ox = 100.0 * (slot % per_row) + 3.5, oy = 100.0 * (slot / per_row) + 3.5; // some cross x = 0
    for (const auto& p : sh) l.add(ox + p[0], oy + p[1]);
    ++slot;
  }
  const NeighbourPairs nb = neighbour_pairs(l.pos.data(), l.species.data(), l.n(), box, {{1.1, 1.1, 1.1}});
  return find_clusters(nb, l.pos.data(), box, l.selected.data());
}

} // namespace

TEST(Clusters, FractalDimensionOfDisksAndRods) {
  std::vector<std::vector<std::array<int, 2>>> disks, rods;
  for (int rad = 2; rad <= 40; rad = rad * 5 / 4 + 1) {
    std::vector<std::array<int, 2>> d;
    for (int x = -rad; x <= rad; ++x)
      for (int y = -rad; y <= rad; ++y)
        if (x * x + y * y <= rad * rad) d.push_back({x, y});
    disks.push_back(d);
  }
  for (int len = 5; len <= 90; len = len * 5 / 4 + 1) {
    std::vector<std::array<int, 2>> r;
    for (int x = 0; x < len; ++x) r.push_back({x - len / 2, 0});
    rods.push_back(r);
  }
  // Filled disks: R_g^2 = N / (2 pi) up to the lattice boundary (Gauss circle
  // error, relative ~R^(-4/3)): d_f = 2 within 3%. Rods: R_g^2 = (n^2-1)/12,
  // slope n^2/(n^2-1) > 1 by < 1% for n >= 10: d_f = 1 within 2%.
  const FractalFit fd = fit_fractal_dimension(lattice_shapes(1000.0, disks).clusters, 10, 5);
  EXPECT_NEAR(fd.d_f, 2.0, 0.06);
  const FractalFit fr = fit_fractal_dimension(lattice_shapes(1000.0, rods).clusters, 10, 5);
  EXPECT_NEAR(fr.d_f, 1.0, 0.02);
  EXPECT_GE(fr.n_bins, 3);
}

TEST(Clusters, NeighboursAtT0AndRadiusOfGyrationAtT) {
  // Random disks, a random half selected; the frame at t moves every particle
  // by up to 3 (some across the boundary, positions unwrapped). Clusters are
  // those of the t0 frame; R_g is that of the members' positions at t.
  std::mt19937_64 gen(53);
  std::uniform_real_distribution<double> u(0, 1);
  const long n = 1200;
  const double box = 40.0;
  Layout l;
  for (long i = 0; i < n; ++i) l.add(box * u(gen), box * u(gen), u(gen) < 0.5, u(gen) < 0.5);
  std::vector<double> pt(l.pos);
  for (double& x : pt) x += 6 * u(gen) - 3;
  const NeighbourCutoffs cut{{1.0, 1.2, 1.4}};
  const NeighbourPairs nb = neighbour_pairs(l.pos.data(), l.species.data(), n, box, cut);
  NeighbourGraph g;
  g.build(nb);
  ClusterFinder finder;
  const ClusterSet at_t0 = find_clusters(nb, l.pos.data(), box, l.selected.data());
  const ClusterSet c = finder.find(g, l.pos.data(), pt.data(), box, l.selected.data());
  EXPECT_EQ(c.label, at_t0.label); // the same partition, found the same way
  ASSERT_EQ(c.clusters.size(), at_t0.clusters.size());
  // Brute force: members unwrapped at t0 around the first member by the
  // minimum image (the clusters here are far smaller than box/2), plus
  // their displacements.
  int checked = 0;
  for (size_t k = 0; k < c.clusters.size(); ++k) {
    const Cluster& cl = c.clusters[k];
    EXPECT_EQ(cl.size, at_t0.clusters[k].size);
    if (cl.size < 2) continue;
    ASSERT_FALSE(cl.spans);
    long first = -1;
    double sx = 0, sy = 0, s2 = 0;
    for (long i = 0; i < n; ++i) {
      if (c.label[i] != static_cast<int>(k)) continue;
      if (first < 0) first = i;
      const double x = min_image(l.pos[2 * i] - l.pos[2 * first], box) + pt[2 * i] - l.pos[2 * i];
      const double y = min_image(l.pos[2 * i + 1] - l.pos[2 * first + 1], box) + pt[2 * i + 1] - l.pos[2 * i + 1];
      sx += x, sy += y, s2 += x * x + y * y;
    }
    const double m = double(cl.size), mx = sx / m, my = sy / m;
    EXPECT_NEAR(cl.radius_of_gyration, std::sqrt(s2 / m - mx * mx - my * my), 1e-9);
    EXPECT_NEAR(min_image(cl.cx - (l.pos[2 * first] + mx), box), 0.0, 1e-9);
    EXPECT_NEAR(min_image(cl.cy - (l.pos[2 * first + 1] + my), box), 0.0, 1e-9);
    ++checked;
  }
  EXPECT_GT(checked, 50);
}

TEST(Clusters, SpanningSurvivesTheDisplacements) {
  // A row all around the box at t0 spans, wherever its particles are at t.
  const double box = 20.0;
  Layout l;
  for (int k = 0; k < 20; ++k) l.add(0.5 + k, 12.0);
  std::vector<double> pt(l.pos);
  for (int k = 0; k < 20; ++k) pt[2 * k] += 7.0 * k, pt[2 * k + 1] -= 3.0 * (k % 3);
  const NeighbourPairs nb = neighbour_pairs(l.pos.data(), l.species.data(), l.n(), box, {{1.2, 1.2, 1.2}});
  NeighbourGraph g;
  g.build(nb);
  ClusterFinder finder;
  const ClusterSet& c = finder.find(g, l.pos.data(), pt.data(), box, l.selected.data());
  ASSERT_EQ(c.clusters.size(), 1u);
  EXPECT_TRUE(c.clusters[0].spans);
  EXPECT_TRUE(std::isnan(c.clusters[0].radius_of_gyration));
}

TEST(Clusters, TallyAddsUpToTheWholeList) {
  // Two cluster sets (random disks, two selections) tallied apart and
  // merged give what the pooled cluster list gives: P(N_c) and d_f.
  std::mt19937_64 gen(59);
  std::uniform_real_distribution<double> u(0, 1);
  const long n = 4000;
  const double box = 60.0;
  Layout l;
  for (long i = 0; i < n; ++i) l.add(box * u(gen), box * u(gen), true, u(gen) < 0.5);
  const NeighbourPairs nb = neighbour_pairs(l.pos.data(), l.species.data(), n, box, {{1.6, 1.8, 2.0}});
  std::vector<Cluster> all;
  std::vector<long> sizes;
  ClusterTally a(n, 5, 3), b(n, 5, 3);
  for (int s = 0; s < 2; ++s) {
    std::vector<std::uint8_t> sel(n);
    for (auto& x : sel) x = u(gen) < (s ? 0.42 : 0.35); // near percolation: sizes over decades
    const ClusterSet c = find_clusters(nb, l.pos.data(), box, sel.data());
    (s ? b : a).add(c);
    all.insert(all.end(), c.clusters.begin(), c.clusters.end());
    for (long z : cluster_sizes(c)) sizes.push_back(z);
  }
  ClusterTally t(n, 5, 3);
  t.add(a), t.add(b);
  EXPECT_EQ(t.sets, 2);
  EXPECT_EQ(t.clusters, static_cast<long>(all.size()));
  long particles = 0;
  for (long z : sizes) particles += z;
  EXPECT_DOUBLE_EQ(t.mean_size(), double(particles) / sizes.size());
  const SizeHistogram h = t.histogram(), ref = cluster_size_distribution(sizes, 5);
  EXPECT_EQ(h.count, ref.count);
  EXPECT_EQ(h.lo, ref.lo);
  EXPECT_EQ(h.hi, ref.hi);
  for (size_t k = 0; k < h.p.size(); ++k) EXPECT_DOUBLE_EQ(h.p[k], ref.p[k]);
  const FractalFit ft = fit_fractal_dimension(t), fl = fit_fractal_dimension(all, 3, 5);
  EXPECT_GE(ft.n_bins, 3);
  EXPECT_NEAR(ft.d_f, fl.d_f, 1e-12 * fl.d_f); // sums in another order: rounding only
  EXPECT_NEAR(ft.d_f_err, fl.d_f_err, 1e-9 * fl.d_f_err);
  EXPECT_EQ(ft.n_clusters, fl.n_clusters);
}
