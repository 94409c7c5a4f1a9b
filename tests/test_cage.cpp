// Cages (dynhet/analysis/cage.hpp): the Voronoi neighbours of a periodic
// configuration equal the Delaunay neighbours found by brute force (every
// triangle with an empty circumcircle among the points and their images);
// a uniform translation has no cage-relative displacement; a sinusoidal
// shear of a triangular lattice has the one computed by hand.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <stdexcept>
#include <vector>

#include "dynhet/analysis/cage.hpp"

using namespace dynhet::analysis;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Points with a minimum separation (a fluid-like configuration), folded.
std::vector<double> random_points(int n, double box, double min_sep, unsigned seed) {
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> u(0, box);
  std::vector<double> p;
  while (static_cast<int>(p.size()) < 2 * n) {
    const double x = u(gen), y = u(gen);
    bool ok = true;
    for (size_t j = 0; j < p.size(); j += 2) {
      double dx = std::fabs(x - p[j]), dy = std::fabs(y - p[j + 1]);
      dx = std::min(dx, box - dx), dy = std::min(dy, box - dy);
      ok = ok && dx * dx + dy * dy >= min_sep * min_sep;
    }
    if (ok) p.push_back(x), p.push_back(y);
  }
  return p;
}

// Delaunay neighbours by brute force: the points and their 8 images; an
// edge (i, j') belongs to the triangulation if some third point k' makes a
// triangle whose circumcircle holds no other point.
std::vector<std::set<int>> brute_delaunay(const std::vector<double>& p, double box) {
  const int n = static_cast<int>(p.size() / 2);
  std::vector<double> x, y;
  std::vector<int> id;
  for (int sx = -1; sx <= 1; ++sx)
    for (int sy = -1; sy <= 1; ++sy)
      for (int i = 0; i < n; ++i) x.push_back(p[2 * i] + sx * box), y.push_back(p[2 * i + 1] + sy * box), id.push_back(i);
  const int m = static_cast<int>(x.size());
  std::vector<std::set<int>> nb(n);
  for (int i = 0; i < n; ++i) {    // originals are the first... no: sx = -1 first; find i's own copy
    const int a = 4 * n + i;       // (sx, sy) = (0, 0) is the fifth block
    for (int b = 0; b < m; ++b) {
      if (b == a) continue;
      for (int c = b + 1; c < m; ++c) {
        if (c == a) continue;
        const double ax = x[a], ay = y[a], bx = x[b], by = y[b], cx = x[c], cy = y[c];
        const double d = 2 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by));
        if (std::fabs(d) < 1e-12) continue;
        const double ux = ((ax * ax + ay * ay) * (by - cy) + (bx * bx + by * by) * (cy - ay) + (cx * cx + cy * cy) * (ay - by)) / d;
        const double uy = ((ax * ax + ay * ay) * (cx - bx) + (bx * bx + by * by) * (ax - cx) + (cx * cx + cy * cy) * (bx - ax)) / d;
        const double r2 = (ax - ux) * (ax - ux) + (ay - uy) * (ay - uy);
        if (r2 > 0.2 * box * box) continue; // a circle this large is not empty in a fluid this dense
        bool empty = true;
        for (int k = 0; k < m && empty; ++k)
          if (k != a && k != b && k != c) empty = (x[k] - ux) * (x[k] - ux) + (y[k] - uy) * (y[k] - uy) > r2 * (1 + 1e-12);
        if (empty) nb[i].insert(id[b]), nb[i].insert(id[c]);
      }
    }
  }
  return nb;
}

} // namespace

TEST(Cage, VoronoiNeighboursAreTheDelaunayNeighboursByBruteForce) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const double box = 10.0;
    const auto p = random_points(40, box, 0.8, seed);
    // Some positions outside the box: the kernel folds them.
    auto q = p;
    q[0] += 3 * box, q[3] -= 2 * box;
    const Neighbours v = voronoi_neighbours(q.data(), 40, box);
    const auto bf = brute_delaunay(p, box);
    ASSERT_EQ(v.size(), 40);
    long edges = 0;
    for (int i = 0; i < 40; ++i) {
      const std::set<int> got(v.list.begin() + v.offset[i], v.list.begin() + v.offset[i + 1]);
      EXPECT_EQ(got, bf[i]) << "particle " << i << ", seed " << seed;
      EXPECT_EQ(static_cast<long>(got.size()), v.count(i)); // no duplicates
      EXPECT_FALSE(got.count(i));
      edges += v.count(i);
    }
    EXPECT_EQ(edges, 2 * 3 * 40); // a periodic triangulation of n points has 3n edges (Euler on the torus)
  }
}

TEST(Cage, UniformTranslationHasNoCageRelativeDisplacement) {
  const double box = 12.0;
  const auto p = random_points(60, box, 0.9, 7);
  const Neighbours v = voronoi_neighbours(p.data(), 60, box);
  std::vector<double> dr(120), cr(120);
  for (int i = 0; i < 60; ++i) dr[2 * i] = 37.25, dr[2 * i + 1] = -3.5; // far beyond L/2: unwrapped
  cage_relative(dr.data(), v, cr.data());
  for (double c : cr) EXPECT_EQ(c, 0.0);
}

// What the overlap node hands its cage-relative measures: positions whose
// displacements from pos0 are dr^CR, to rounding; a translation by far
// more than L/2 leaves every particle where it started.
TEST(Cage, CageRelativePositionsAreThoseOfTheCageRelativeDisplacements) {
  const double box = 12.0;
  const long n = 60;
  const auto p0 = random_points(n, box, 0.9, 11);
  const Neighbours v = voronoi_neighbours(p0.data(), n, box);
  std::mt19937_64 gen(3);
  std::normal_distribution<double> g(0.0, 0.7);
  std::vector<double> pos(2 * n), dr(2 * n), cr(2 * n), out(2 * n), buffer;
  for (long i = 0; i < 2 * n; ++i) pos[i] = p0[i] + 40.0 + g(gen), dr[i] = pos[i] - p0[i];
  cage_relative(dr.data(), v, cr.data());
  cage_relative_positions(p0.data(), pos.data(), v, buffer, out.data());
  for (long i = 0; i < 2 * n; ++i) EXPECT_NEAR(out[i] - p0[i], cr[i], 1e-12) << i;
  for (long i = 0; i < 2 * n; ++i) pos[i] = p0[i] + 40.0;
  cage_relative_positions(p0.data(), pos.data(), v, buffer, out.data());
  for (long i = 0; i < 2 * n; ++i) EXPECT_NEAR(out[i], p0[i], 1e-12) << i;
}

TEST(Cage, SinusoidalShearOfATriangularLatticeIsKnownExactly) {
  // nx columns a apart, ny rows b apart, odd rows shifted by a/2: every
  // particle has 6 neighbours, 2 in its row and 4 at dy = +-b. For dr_x =
  // A sin(k y), k = 2 pi / L, the neighbours' mean is A sin(k y) (2 + 4 cos(k b)) / 6.
  const int nx = 12, ny = 14;
  const double box = 24.0, a = box / nx, b = box / ny, amp = 0.7, k = 2 * kPi / box;
  std::vector<double> p, dr;
  for (int r = 0; r < ny; ++r)
    for (int c = 0; c < nx; ++c) {
      const double x = (c + 0.5 * (r % 2)) * a, y = (r + 0.5) * b;
      p.push_back(x), p.push_back(y);
      dr.push_back(amp * std::sin(k * y)), dr.push_back(0.0);
    }
  const long n = nx * ny;
  const Neighbours v = voronoi_neighbours(p.data(), n, box);
  std::vector<double> cr(2 * n);
  cage_relative(dr.data(), v, cr.data());
  const double keep = 1 - (2 + 4 * std::cos(k * b)) / 6;
  for (long i = 0; i < n; ++i) {
    EXPECT_EQ(v.count(i), 6) << i;
    EXPECT_NEAR(cr[2 * i], dr[2 * i] * keep, 1e-12) << i;
    EXPECT_NEAR(cr[2 * i + 1], 0.0, 1e-12);
  }
}

TEST(Cage, BadInputIsRefusedWithItsReason) {
  std::vector<double> p = random_points(30, 8.0, 0.8, 5);
  EXPECT_THROW(voronoi_neighbours(p.data(), 30, 0.0), std::invalid_argument);
  auto q = p;
  q[7] = std::nan("");
  try {
    voronoi_neighbours(q.data(), 30, 8.0);
    FAIL() << "a NaN position was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("particle 3 not finite"), std::string::npos) << e.what();
  }
  q = p;
  q[2] = q[0], q[3] = q[1];
  EXPECT_THROW(voronoi_neighbours(q.data(), 30, 8.0), std::invalid_argument);
  const double two[] = {1.0, 1.0, 5.0, 5.0};
  EXPECT_THROW(voronoi_neighbours(two, 2, 8.0), std::invalid_argument); // too few for one sheet
}

// The kernel sums a row over a fixed number of masked slots (no loop exit
// that depends on the row's length): its sums are the plain loop's bit for
// bit, for rows of every length from empty to longer than the slots, and
// at the end of the list where there is nothing past the row to read.
TEST(Cage, MaskedRowSumsAreThePlainLoopsBitForBit) {
  std::mt19937_64 gen(5);
  std::normal_distribution<double> g(0.0, 3.0);
  const long n = 400;
  Neighbours v;
  v.offset.push_back(0);
  for (long i = 0; i < n; ++i) {
    const long c = i % 13; // 0 .. 12: empty rows, short ones, longer than 8
    for (long k = 0; k < c; ++k) v.list.push_back(static_cast<std::int32_t>((i * 7 + k * 31) % n));
    v.offset.push_back(static_cast<std::int64_t>(v.list.size()));
  }
  std::vector<double> dr(2 * n), cr(2 * n);
  for (double& d : dr) d = g(gen);
  dr[10] = -0.0, dr[11] = -0.0; // a negative zero among the neighbours
  cage_relative(dr.data(), v, cr.data());
  for (long i = 0; i < n; ++i) {
    double mx = 0, my = 0;
    for (std::int64_t k = v.offset[i]; k < v.offset[i + 1]; ++k) mx += dr[2 * v.list[k]], my += dr[2 * v.list[k] + 1];
    const long c = v.count(i);
    EXPECT_EQ(cr[2 * i], dr[2 * i] - (c > 0 ? mx / c : 0.0)) << i;
    EXPECT_EQ(cr[2 * i + 1], dr[2 * i + 1] - (c > 0 ? my / c : 0.0)) << i;
  }
}
