// The collision rule, the collision time and the event calendar against
// their definitions.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "dynhet/engine/calendar.hpp"
#include "dynhet/engine/collision.hpp"

using namespace dynhet::engine;

TEST(CollisionRule, ConservesMomentumAndLosesTheEnergyTheFormulaSays) {
  std::mt19937_64 gen(7);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0.1, 1.0);
  for (int trial = 0; trial < 10000; ++trial) {
    const double eps = u(gen), mi = 1.0, mj = trial % 2 ? 1.43 * 1.43 : 1.0;
    double dx = g(gen), dy = g(gen);
    double vix = g(gen), viy = g(gen), vjx = g(gen), vjy = g(gen);
    const double d = std::hypot(dx, dy), nx = dx / d, ny = dy / d;
    const double gn = (vix - vjx) * nx + (viy - vjy) * ny;
    const double px = mi * vix + mj * vjx, py = mi * viy + mj * vjy;
    const double e0 = 0.5 * mi * (vix * vix + viy * viy) + 0.5 * mj * (vjx * vjx + vjy * vjy);
    collide_pair(dx, dy, mi, mj, eps, vix, viy, vjx, vjy);
    const double scale = std::abs(px) + std::abs(py) + mi + mj;
    EXPECT_NEAR(mi * vix + mj * vjx, px, 4e-16 * scale * 8);
    EXPECT_NEAR(mi * viy + mj * vjy, py, 4e-16 * scale * 8);
    const double e1 = 0.5 * mi * (vix * vix + viy * viy) + 0.5 * mj * (vjx * vjx + vjy * vjy);
    if (gn < 0) {
      // Delta E = -(1 - eps^2)/2 mu (g.n)^2, and (g.n)' = -eps (g.n).
      const double mu = mi * mj / (mi + mj);
      EXPECT_NEAR(e1 - e0, -0.5 * (1 - eps * eps) * mu * gn * gn, 1e-13 * e0);
      EXPECT_NEAR((vix - vjx) * nx + (viy - vjy) * ny, -eps * gn, 1e-13 * (1 + std::abs(gn)));
    } else {
      EXPECT_EQ(e1, e0); // receding: untouched
    }
  }
}

TEST(CollisionTime, PairTouchesExactlyAtThePredictedTime) {
  std::mt19937_64 gen(3);
  std::normal_distribution<double> g;
  int hits = 0;
  for (int trial = 0; trial < 10000; ++trial) {
    const double sigma = 2.0 + std::abs(g(gen));
    const double dx = 3 * g(gen), dy = 3 * g(gen), gx = g(gen), gy = g(gen);
    if (std::hypot(dx, dy) <= sigma) continue;
    const double t = pair_collision_time(dx, dy, gx, gy, sigma);
    // Brute force: the smallest distance along the straight paths.
    const double tmin = std::max(0.0, -(dx * gx + dy * gy) / (gx * gx + gy * gy));
    const double dmin = std::hypot(dx + gx * tmin, dy + gy * tmin);
    if (dmin >= sigma) {
      EXPECT_EQ(t, kNever);
      continue;
    }
    ++hits;
    ASSERT_LT(t, kNever);
    EXPECT_NEAR(std::hypot(dx + gx * t, dy + gy * t), sigma, 1e-12 * sigma);
    EXPECT_LE(t, tmin);
  }
  EXPECT_GT(hits, 1000);
}

TEST(CollisionTime, OverlapByRoundoffCollidesNowOnlyIfApproaching) {
  EXPECT_EQ(pair_collision_time(2.0 - 1e-14, 0, -1, 0, 2.0), 0.0);
  EXPECT_EQ(pair_collision_time(2.0 - 1e-14, 0, 1, 0, 2.0), kNever);
}

TEST(CollisionTime, GrowingDisksMeetEvenWhenAtRest) {
  // At rest 1 apart beyond contact, contact distance growing at 0.5: t = 2.
  EXPECT_NEAR(pair_collision_time(3.0, 0, 0, 0, 2.0, 0.5), 2.0, 1e-14);
}

TEST(Calendar, TopIsAlwaysTheEarliestLeaf) {
  std::mt19937_64 gen(11);
  std::uniform_real_distribution<double> u(0, 100);
  const int n = 1000;
  Calendar cal;
  cal.reset(n, kNever);
  std::vector<double> t(n, kNever);
  for (int step = 0; step < 100000; ++step) {
    const int leaf = static_cast<int>(gen() % n);
    t[leaf] = u(gen);
    cal.set(leaf, t[leaf]);
    const int best = static_cast<int>(std::min_element(t.begin(), t.end()) - t.begin());
    ASSERT_EQ(cal.top_time(), t[best]);
  }
}

TEST(Calendar, TiesGoToTheLowerLeafForEverySize) {
  // Times from a few values (many ties), sizes around powers of 4; the top
  // must be the earliest time and, among equal times, the lowest leaf
  // (that order makes runs reproducible).
  std::mt19937_64 gen(5);
  for (int n : {1, 2, 3, 4, 5, 15, 16, 17, 63, 64, 65, 257, 1025}) {
    Calendar cal;
    cal.reset(n, kNever);
    std::vector<double> t(n, kNever);
    for (int step = 0; step < 20 * n + 100; ++step) {
      const int leaf = static_cast<int>(gen() % n);
      t[leaf] = (gen() % 5 == 0) ? kNever : static_cast<double>(gen() % 4);
      cal.set(leaf, t[leaf]);
      const int best = static_cast<int>(std::min_element(t.begin(), t.end()) - t.begin());
      if (t[best] == kNever) continue;
      ASSERT_EQ(cal.top(), best) << "n=" << n << " step=" << step;
      ASSERT_EQ(cal.top_time(), t[best]);
      ASSERT_EQ(cal.time(leaf), t[leaf]);
    }
  }
}
