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

// The calendar used as the engine uses it: the earliest event is taken, its
// leaf gets a later time, other leaves' times change (earlier or later, never
// before the clock), now and then everything is entered afresh. Times come
// from a grid (many ties), some lie far beyond the ring (overflow), some are
// infinite. Against a brute-force minimum over (time, leaf).
struct VectorTimes {
  const std::vector<double>* t;
  double operator()(int i) const { return (*t)[i]; }
  void prefetch(int) const {}
};

void calendar_against_brute_force(int n, uint64_t seed, double far_fraction) {
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<double> t(n);
  double now = 0;
  auto draw = [&] {
    const double r = u(gen);
    if (r < 0.05) return kNever;
    const double horizon = r < 0.05 + far_fraction ? 1e4 : 1.0;
    return now + std::floor(u(gen) * horizon * 64) / 64; // grid: ties
  };
  for (auto& x : t) x = draw();
  Calendar cal;
  const VectorTimes times{&t};
  cal.rebuild(n, now, times);
  for (int step = 0; step < 30 * n + 3000; ++step) {
    const auto top = cal.top(times);
    int best = 0;
    for (int i = 1; i < n; ++i)
      if (t[i] < t[best]) best = i; // ties: the lower leaf stays
    if (t[best] == kNever) {
      ASSERT_EQ(top.leaf, -1) << "n=" << n << " step=" << step;
      for (auto& x : t) x = draw();
      cal.rebuild(n, now, times);
      continue;
    }
    ASSERT_EQ(top.leaf, best) << "n=" << n << " step=" << step;
    ASSERT_EQ(top.time, t[best]);
    now = t[best];
    // The event is processed: its leaf's time moves on (or stays, a
    // zero-delay event), and so do a few others'.
    const double next = u(gen) < 0.05 ? now : draw();
    if (next != t[best]) t[best] = next, cal.push(best, next);
    for (int k = static_cast<int>(gen() % 3); k > 0; --k) {
      const int j = static_cast<int>(gen() % n);
      const double tj = draw();
      if (tj != t[j]) t[j] = tj, cal.push(j, tj);
    }
    if (step % 997 == 0) cal.rebuild(n, now, times);
  }
}

TEST(Calendar, TakesEventsInTheOrderOfATournamentTree) {
  for (int n : {1, 2, 3, 17, 100, 1000, 5000}) calendar_against_brute_force(n, 7 + n, 0.0);
}

TEST(Calendar, FarEventsWaitInTheOverflowAndAreNotLost) {
  // A fifth of the times lie up to 10^4 horizons ahead: beyond the ring.
  for (int n : {2, 50, 2000}) calendar_against_brute_force(n, 3 + n, 0.2);
}
