// The EDMD engine as a whole: no overlaps (brute force over all pairs),
// conservation laws, reproducibility.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "dynhet/engine/engine.hpp"

using dynhet::engine::Engine;
using dynhet::engine::Params;

namespace {

// Smallest d / sigma over all pairs, with the minimum image: O(N^2).
double brute_min_gap(const Engine& e) {
  std::vector<double> xy;
  e.unwrapped_positions(xy);
  const double L = e.box_length();
  double best = 1e300;
  for (long i = 0; i < e.size(); ++i)
    for (long j = i + 1; j < e.size(); ++j) {
      double dx = xy[2 * i] - xy[2 * j], dy = xy[2 * i + 1] - xy[2 * j + 1];
      dx -= L * std::round(dx / L);
      dy -= L * std::round(dy / L);
      const double s = e.radius(e.species()[i]) + e.radius(e.species()[j]);
      best = std::min(best, std::hypot(dx, dy) / s);
    }
  return best;
}

Params params(long n, double phi, double eps, bool driving) {
  Params p;
  p.n_particles = n;
  p.packing_fraction = phi;
  p.restitution = eps;
  p.driving = driving;
  p.kick_rate = 8.0;
  p.seed = 42;
  return p;
}

} // namespace

TEST(Engine, CompressionReachesPhiWithoutOverlap) {
  for (double phi : {0.5, 0.78}) {
    Engine e(params(600, phi, 1.0, false));
    e.prepare();
    EXPECT_NEAR(e.packing_fraction(), phi, 1e-12);
    EXPECT_GE(brute_min_gap(e), 1.0 - 1e-9) << "phi " << phi;
    EXPECT_NEAR(e.kinetic_energy_per_particle(), 1.0, 1e-12); // time unit: KE = 1 at t = 0
    EXPECT_EQ(e.time(), 0.0);
  }
}

TEST(Engine, ElasticUndrivenConservesEnergyAndMomentum) {
  Engine e(params(1000, 0.7, 1.0, false));
  e.prepare();
  double px0, py0;
  e.momentum(px0, py0);
  const double e0 = e.kinetic_energy_per_particle();
  e.run_until(400.0);
  EXPECT_GT(e.counters().collisions, 1'000'000);
  EXPECT_EQ(e.counters().kicks, 0);
  EXPECT_NEAR(e.kinetic_energy_per_particle() / e0 - 1.0, 0.0, 1e-11);
  double px, py;
  e.momentum(px, py);
  EXPECT_NEAR(px - px0, 0.0, 1e-10);
  EXPECT_NEAR(py - py0, 0.0, 1e-10);
  EXPECT_GE(brute_min_gap(e), 1.0 - 1e-9);
}

TEST(Engine, DrivenConservesMomentumAndReachesSteadyState) {
  Engine e(params(1000, 0.7, 0.9, true));
  e.prepare();
  e.run_until(100.0);
  EXPECT_GT(e.counters().kicks, 100'000);
  double px, py;
  e.momentum(px, py);
  // Each event adds roundoff ~1e-16 of the momenta it moves (~1): a random
  // walk over ~1e6 events stays far below 1e-10.
  EXPECT_LT(std::hypot(px, py), 1e-10);
  // Kicks balance the collisional loss: the granular temperature stays O(1).
  const double ke = e.kinetic_energy_per_particle();
  EXPECT_GT(ke, 0.3);
  EXPECT_LT(ke, 3.0);
  EXPECT_GE(brute_min_gap(e), 1.0 - 1e-9);
}

TEST(Engine, SameSeedSameTrajectoryBitForBit) {
  std::vector<double> a, b;
  for (auto* out : {&a, &b}) {
    Engine e(params(500, 0.75, 0.9, true));
    e.prepare();
    e.run_until(20.0);
    e.unwrapped_positions(*out);
  }
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]) << i;
}

TEST(Engine, UnwrappedPositionsAreContinuousAcrossTheBoundary) {
  Engine e(params(400, 0.6, 1.0, false));
  e.prepare();
  std::vector<double> prev, now;
  e.unwrapped_positions(prev);
  int outside = 0;
  for (int step = 1; step <= 2000; ++step) {
    e.run_until(0.05 * step);
    e.unwrapped_positions(now);
    for (size_t i = 0; i < now.size(); ++i) {
      // KE = 1 per particle: no particle moves more than ~1 in 0.05.
      ASSERT_LT(std::abs(now[i] - prev[i]), 1.0) << "particle " << i / 2 << " jumped at step " << step;
      if (step == 2000) outside += now[i] < 0 || now[i] >= e.box_length();
    }
    prev = now;
  }
  EXPECT_GT(outside, 10); // particles did cross the periodic boundary
}
