// Bond breaking (dynhet/analysis/bonds.hpp) against plain loops over all
// pairs: the bonds of a frame (r < A1 sigma_ab, minimum image at t0) and
// which of them are broken after displacements far beyond L/2 (unwrapped);
// a uniform translation breaks none; one particle moved off breaks its own.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "dynhet/analysis/bonds.hpp"

using namespace dynhet::analysis;

namespace {

struct Config {
  std::vector<double> pos;
  std::vector<std::uint8_t> species;
  double box;
};

Config fluid(int n, double box, unsigned seed) {
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> u(0, box);
  Config c{{}, {}, box};
  for (int i = 0; i < n; ++i) c.pos.push_back(u(gen)), c.pos.push_back(u(gen)), c.species.push_back(i % 2);
  return c;
}

double min_image(double d, double box) { return d - box * std::round(d / box); }

} // namespace

TEST(Bonds, BondsAndBreakingEqualAllPairsLoops) {
  const std::array<double, 2> diam{1.0, 1.43};
  const double a1 = 1.1, a2 = 1.5;
  const Config c = fluid(400, 14.0, 3);
  const BondSet b = make_bonds(c.pos.data(), c.species.data(), 400, c.box, diam, a1, a2);
  // Brute force: every pair, the minimum image at t0.
  std::map<std::pair<int, int>, std::array<double, 2>> want;
  for (int i = 0; i < 400; ++i)
    for (int j = i + 1; j < 400; ++j) {
      const double dx = min_image(c.pos[2 * j] - c.pos[2 * i], c.box), dy = min_image(c.pos[2 * j + 1] - c.pos[2 * i + 1], c.box);
      const double sigma = 0.5 * (diam[c.species[i]] + diam[c.species[j]]);
      if (dx * dx + dy * dy < a1 * sigma * a1 * sigma) want[{i, j}] = {dx, dy};
    }
  ASSERT_EQ(b.pairs.pairs.size(), want.size());
  ASSERT_GT(want.size(), 100u);
  for (size_t k = 0; k < b.pairs.pairs.size(); ++k) {
    const auto& p = b.pairs.pairs[k];
    const auto it = want.find({p[0], p[1]});
    ASSERT_NE(it, want.end()) << p[0] << " " << p[1];
    EXPECT_NEAR(b.pairs.bond[k][0], it->second[0], 1e-12);
    EXPECT_NEAR(b.pairs.bond[k][1], it->second[1], 1e-12);
  }
  // Displacements: a common drift of 3.7 boxes plus a random part.
  std::mt19937_64 gen(5);
  std::normal_distribution<double> g(0, 0.35);
  std::vector<double> dr(800);
  for (int i = 0; i < 800; ++i) dr[i] = (i % 2 ? -3.7 : 3.7) * c.box + g(gen);
  std::vector<std::uint8_t> intact(b.pairs.pairs.size());
  const long got = bonds_intact(b, c.species.data(), dr.data(), intact.data());
  long expect = 0, broken = 0;
  for (size_t k = 0; k < b.pairs.pairs.size(); ++k) {
    const int i = b.pairs.pairs[k][0], j = b.pairs.pairs[k][1];
    const auto d0 = want[{i, j}];
    // Unwrapped positions at t: r(t0) + dr; the bond is the t0 image carried along.
    const double x = d0[0] + (c.pos[2 * j] + dr[2 * j] - c.pos[2 * j]) - (c.pos[2 * i] + dr[2 * i] - c.pos[2 * i]);
    const double y = d0[1] + dr[2 * j + 1] - dr[2 * i + 1];
    const double sigma = 0.5 * (diam[c.species[i]] + diam[c.species[j]]);
    const bool ok = std::hypot(x, y) <= a2 * sigma;
    EXPECT_EQ(bool(intact[k]), ok) << k;
    expect += ok, broken += !ok;
  }
  EXPECT_EQ(got, expect);
  EXPECT_GT(broken, 10); // the test sees both kinds
  EXPECT_GT(expect, 10);
}

TEST(Bonds, TranslationBreaksNoneAndAParticleMovedOffBreaksItsOwn) {
  const std::array<double, 2> diam{1.0, 1.43};
  const Config c = fluid(300, 12.0, 8);
  const BondSet b = make_bonds(c.pos.data(), c.species.data(), 300, c.box, diam, 1.1, 1.5);
  std::vector<double> dr(600);
  for (int i = 0; i < 300; ++i) dr[2 * i] = 123.4, dr[2 * i + 1] = -56.7;
  EXPECT_EQ(bonds_intact(b, c.species.data(), dr.data(), nullptr), static_cast<long>(b.pairs.pairs.size()));
  const int moved = b.pairs.pairs[0][0];
  dr[2 * moved] += 5.0; // more than A2 sigma of any pair away from every old neighbour
  long own = 0;
  for (const auto& p : b.pairs.pairs) own += (p[0] == moved || p[1] == moved);
  EXPECT_EQ(bonds_intact(b, c.species.data(), dr.data(), nullptr), static_cast<long>(b.pairs.pairs.size()) - own);
}

TEST(Bonds, BadParametersAreRefused) {
  const Config c = fluid(10, 5.0, 1);
  EXPECT_THROW(make_bonds(c.pos.data(), c.species.data(), 10, c.box, {1.0, 1.43}, 1.5, 1.1), std::invalid_argument);
  EXPECT_THROW(make_bonds(c.pos.data(), c.species.data(), 10, c.box, {0.0, 1.43}, 1.1, 1.5), std::invalid_argument);
}
