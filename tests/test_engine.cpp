// The EDMD engine as a whole: no overlaps (brute force over all pairs),
// conservation laws, reproducibility, the driving. The engine against
// liquid-state theory: test_theory.cpp.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "dynhet/engine/engine.hpp"
#include "dynhet/engine/rows.hpp"
#include "dynhet/state_archive.hpp"
#include "engine_test_params.hpp"

using dynhet::engine::Engine;
using dynhet::engine::KickPairs;
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


} // namespace

TEST(Engine, CompressionReachesPhiWithoutOverlap) {
  for (auto [n, phi] : {std::pair{600L, 0.5}, {600L, 0.78}, {3000L, 0.76}, {2000L, 0.82}}) {
    Engine e(params(n, phi, 1.0, false));
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
  for (const auto rule : {KickPairs::neighbours, KickPairs::any}) {
    Params p = params(1000, 0.7, 0.9, true);
    p.kick_pairs = rule;
    Engine e(p);
    e.prepare();
    e.run_until(100.0);
    // Kicks are a Poisson process of N * rate / 2 pairs per unit time:
    // 4e5 expected, standard deviation 632; 5 of them.
    const double expected = 0.5 * p.kick_rate * p.n_particles * 100.0;
    EXPECT_NEAR(double(e.counters().kicks), expected, 5 * std::sqrt(expected));
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
}

namespace {
// Ids of the particles whose surface lies within `reach` of particle i's,
// by brute force over all pairs (minimum image), in id order.
std::vector<long> brute_kick_partners(const Engine& e, long i, double reach) {
  std::vector<double> xy;
  e.unwrapped_positions(xy);
  const double L = e.box_length();
  std::vector<long> out;
  for (long j = 0; j < e.size(); ++j) {
    if (j == i) continue;
    double dx = xy[2 * i] - xy[2 * j], dy = xy[2 * i + 1] - xy[2 * j + 1];
    dx -= L * std::round(dx / L);
    dy -= L * std::round(dy / L);
    if (std::hypot(dx, dy) <= e.radius(e.species()[i]) + e.radius(e.species()[j]) + reach) out.push_back(j);
  }
  return out;
}
} // namespace

// Neighbour pairs: at 2000 moments of a driven run, the pair the next kick
// takes is checked against brute force: the second particle is one of
// those within reach of the first, and uniform among them (the mean of
// (rank + 1/2) / count is 1/2, standard deviation at most 1/sqrt(12 K);
// 4 of them). The first particle is uniform: the mean id is (N - 1)/2.
TEST(Engine, NeighbourKickPairsAreWithinReachAndUniform) {
  for (const double reach : {1.0, 2.5}) {
    Params p = params(600, 0.72, 0.9, true);
    p.kick_reach = reach;
    Engine e(p);
    e.prepare();
    e.run_until(2.0);
    const int k = 2000;
    double u_sum = 0, i_sum = 0;
    for (int s = 0; s < k; ++s) {
      e.run_until(2.0 + 0.01 * (s + 1));
      const auto pair = e.next_kick_pair();
      ASSERT_EQ(pair.redraws, 0); // at phi = 0.72 everyone has neighbours in reach
      const auto partners = brute_kick_partners(e, pair.i, reach);
      const auto at = std::find(partners.begin(), partners.end(), pair.j);
      ASSERT_NE(at, partners.end()) << "kick " << s << ": " << pair.j << " is not within reach of " << pair.i;
      u_sum += (double(at - partners.begin()) + 0.5) / double(partners.size());
      i_sum += double(pair.i);
    }
    EXPECT_NEAR(u_sum / k, 0.5, 4 / std::sqrt(12.0 * k)) << "reach " << reach;
    // ids uniform on 0..N-1: standard deviation N / sqrt(12 K).
    EXPECT_NEAR(i_sum / k, 0.5 * (p.n_particles - 1), 4 * p.n_particles / std::sqrt(12.0 * k));
  }
}

namespace {
// A snapshot's packed rows (Rows::save_packed, from their own slot), one vector each.
std::vector<std::vector<int>> rows_of(const std::vector<uint8_t>& packed, size_t n) {
  dynhet::engine::Rows rows;
  EXPECT_TRUE(rows.load_packed(n, packed, static_cast<int32_t>(n), true)) << "the snapshot's rows do not unpack";
  std::vector<std::vector<int>> out(n);
  for (size_t r = 0; r < n; ++r) {
    const int32_t* c = rows.row(r);
    out[r].assign(c + 1, c + 1 + c[0]);
  }
  return out;
}
} // namespace

// The kick candidates of slot i are its neighbour list followed by its kick
// list, which holds only those the neighbour list does not. Through a
// driven run with thousands of single-particle rebuilds, at 20 moments:
// no row holds its own slot or a member twice, both kinds of row are
// symmetric, no kick list repeats a member of its neighbour list, and the
// two together hold exactly the slots whose list centres lie within
// r_i + r_j + reach + skin of i's (brute force over all pairs; 1e-9 of
// slack either way for the roundoff allowance of the criterion), so
// everyone within reach now.
TEST(Engine, KickListsHoldTheCandidatesBeyondTheNeighbourList) {
  Params p = dynhet::engine::paper_params(1000, 0.78, 0.9, true);
  Engine e(p);
  e.prepare();
  const double skin = dynhet::engine::auto_skin(p.packing_fraction);
  const double L = e.box_length();
  int64_t rebuilds0 = e.counters().rebuilds;
  for (int s = 1; s <= 20; ++s) {
    e.run_until(1.0 * s);
    const auto snap = e.snapshot();
    const size_t n = static_cast<size_t>(e.size());
    const auto nbr = rows_of(snap.neighbours, n), kick = rows_of(snap.kick_lists, n);
    std::vector<std::vector<char>> in_nbr(n, std::vector<char>(n, 0)), in_kick(n, std::vector<char>(n, 0));
    for (size_t i = 0; i < n; ++i) {
      for (const int j : nbr[i]) {
        ASSERT_NE(size_t(j), i);
        ASSERT_FALSE(in_nbr[i][j]++) << "slot " << j << " twice in the neighbour list of " << i;
      }
      for (const int j : kick[i]) {
        ASSERT_NE(size_t(j), i);
        ASSERT_FALSE(in_kick[i][j]++) << "slot " << j << " twice in the kick list of " << i;
      }
    }
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j) {
        ASSERT_EQ(in_nbr[i][j], in_nbr[j][i]) << "neighbour lists of " << i << " and " << j << ", moment " << s;
        ASSERT_EQ(in_kick[i][j], in_kick[j][i]) << "kick lists of " << i << " and " << j << ", moment " << s;
        ASSERT_FALSE(in_nbr[i][j] && in_kick[i][j]) << j << " in both lists of " << i << ", moment " << s;
        if (i == j) continue;
        double dx = snap.centres[2 * i] - snap.centres[2 * j], dy = snap.centres[2 * i + 1] - snap.centres[2 * j + 1];
        dx -= L * std::round(dx / L);
        dy -= L * std::round(dy / L);
        const double d = std::hypot(dx, dy);
        const double reach = e.radius(e.species()[snap.id[i]]) + e.radius(e.species()[snap.id[j]]) + p.kick_reach + skin;
        const bool listed = in_nbr[i][j] || in_kick[i][j];
        if (d < reach - 1e-9) {
          ASSERT_TRUE(listed) << j << " is a kick candidate of " << i << ", moment " << s;
        } else if (d > reach + 1e-9) {
          ASSERT_FALSE(listed) << j << " is no kick candidate of " << i << ", moment " << s;
        }
      }
  }
  EXPECT_GT(e.counters().rebuilds - rebuilds0, 2000);
  const auto snap = e.snapshot();
  const size_t n = static_cast<size_t>(e.size());
  size_t most = 0, in_nbr = 0, in_kick = 0;
  for (const auto& r : rows_of(snap.neighbours, n)) in_nbr += r.size();
  for (const auto& r : rows_of(snap.kick_lists, n)) most = std::max(most, r.size()), in_kick += r.size();
  std::printf("members per particle: neighbour list %.2f, kick list %.2f (longest %zu)\n", double(in_nbr) / n,
              double(in_kick) / n, most);
}

// A dilute gas with a short reach: most first particles have nobody in
// reach and are drawn again; after kMaxKickDraws in vain the pair comes
// from the whole system. Both are counted, momentum is still conserved,
// and every pair found by a draw is within reach.
TEST(Engine, LonelyFirstParticlesAreDrawnAgain) {
  Params p = params(400, 0.05, 0.9, true);
  p.kick_reach = 0.1;
  Engine e(p);
  e.prepare();
  for (int s = 1; s <= 200; ++s) {
    e.run_until(0.05 * s);
    const auto pair = e.next_kick_pair();
    if (pair.redraws < Engine::kMaxKickDraws) {
      const auto partners = brute_kick_partners(e, pair.i, p.kick_reach);
      EXPECT_NE(std::find(partners.begin(), partners.end(), pair.j), partners.end());
    }
  }
  EXPECT_GT(e.counters().kick_redraws, 10 * e.counters().kicks);
  EXPECT_GT(e.counters().kick_far, 0);
  double px, py;
  e.momentum(px, py);
  EXPECT_LT(std::hypot(px, py), 1e-10);
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

// The AVX2 pair tests (neighbours' lines transposed in registers, the
// earliest lane by vector compares) and the portable ones move the same
// data and take the same lane: compression (growing radii), an elastic and
// a driven run give the same bits either way.
TEST(Engine, VectorAndPortablePairTestsGiveTheSameBits) {
  const char* was = std::getenv("DYNHET_PORTABLE_PAIR_TESTS"); // put back at the end
  const std::string kept = was ? was : "";
  for (const bool driven : {false, true}) {
    std::vector<double> xy[2];
    int64_t events[2];
    for (const bool portable : {true, false}) {
      if (portable) setenv("DYNHET_PORTABLE_PAIR_TESTS", "1", 1);
      Engine e(params(1000, 0.78, driven ? 0.9 : 1.0, driven));
      unsetenv("DYNHET_PORTABLE_PAIR_TESTS");
      if (!portable && !e.vector_pair_tests()) {
        if (was) setenv("DYNHET_PORTABLE_PAIR_TESTS", kept.c_str(), 1);
        GTEST_SKIP() << "the vector pair tests do not run here (no AVX2, or a Particle layout they do not suit)";
      }
      EXPECT_EQ(e.vector_pair_tests(), !portable);
      e.prepare();
      e.run_until(20.0);
      e.unwrapped_positions(xy[portable]);
      events[portable] = e.counters().collisions + e.counters().kicks + e.counters().stale;
    }
    EXPECT_GT(events[0], 100000);
    EXPECT_EQ(events[0], events[1]);
    EXPECT_EQ(xy[0].size(), xy[1].size());
    size_t differ = 0, first = 0;
    for (size_t i = 0; i < std::min(xy[0].size(), xy[1].size()); ++i)
      if (xy[0][i] != xy[1][i] && differ++ == 0) first = i;
    EXPECT_EQ(differ, 0u) << (driven ? "driven" : "elastic") << ": the first at coordinate " << first;
  }
  if (was) setenv("DYNHET_PORTABLE_PAIR_TESTS", kept.c_str(), 1);
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

TEST(Engine, TcModelMakesCollisionsWithinTcElastic) {
  // tc longer than the run: after each particle's first collision, every
  // collision is elastic, so the energy lost is at most what the first
  // collisions of all particles can take; with tc = 0 it decays much more.
  Params p = params(500, 0.6, 0.5, false);
  p.tc = 1e9;
  Engine e(p);
  e.prepare();
  e.run_until(20.0);
  const auto& c = e.counters();
  EXPECT_GT(c.tc, c.collisions - e.size()); // all but at most one per particle
  EXPECT_GT(e.kinetic_energy_per_particle(), 0.3);

  Params q = params(500, 0.6, 0.5, false);
  Engine f(q);
  f.prepare();
  f.run_until(20.0);
  EXPECT_EQ(f.counters().tc, 0);
  EXPECT_LT(f.kinetic_energy_per_particle(), 0.05); // homogeneous cooling, Haff's law
}

TEST(Engine, RestoredRunContinuesBitForBit) {
  // Uninterrupted: synchronise at t = 10 and 20, run to 30. Resumed: a
  // second engine restored from the state at t = 10 does the same, and
  // draws the same kick pairs (which, with neighbour pairs, depend on the
  // positions at the kick).
  for (const auto rule : {KickPairs::neighbours, KickPairs::any}) {
    Params p = params(400, 0.75, 0.9, true);
    p.tc = 1e-3;
    p.kick_pairs = rule;
    Engine a(p);
    a.prepare();
    a.run_until(10.0);
    a.synchronize();
    const auto saved = a.state();
    const auto pair_a = a.next_kick_pair();
    a.run_until(15.0);
    const auto pair_a15 = a.next_kick_pair();
    a.run_until(20.0);
    a.synchronize();
    a.run_until(30.0);

    Engine b(p);
    b.restore(saved);
    EXPECT_EQ(b.time(), 10.0);
    const auto pair_b = b.next_kick_pair();
    EXPECT_EQ(pair_a.i, pair_b.i);
    EXPECT_EQ(pair_a.j, pair_b.j);
    b.run_until(15.0);
    const auto pair_b15 = b.next_kick_pair();
    EXPECT_EQ(pair_a15.i, pair_b15.i);
    EXPECT_EQ(pair_a15.j, pair_b15.j);
    b.run_until(20.0);
    b.synchronize();
    b.run_until(30.0);

    std::vector<double> xa, xb;
    a.unwrapped_positions(xa);
    b.unwrapped_positions(xb);
    ASSERT_EQ(xa.size(), xb.size());
    for (size_t i = 0; i < xa.size(); ++i) ASSERT_EQ(xa[i], xb[i]) << i;
    EXPECT_EQ(a.counters().collisions, b.counters().collisions);
    EXPECT_EQ(a.counters().kicks, b.counters().kicks);
    EXPECT_EQ(a.counters().kick_redraws, b.counters().kick_redraws);
    EXPECT_EQ(a.kinetic_energy_per_particle(), b.kinetic_energy_per_particle());
    double px, py;
    a.momentum(px, py);
    EXPECT_LT(std::hypot(px, py), 1e-10);

    Params wrong = p;
    wrong.n_particles = 401;
    Engine c(wrong);
    EXPECT_THROW(c.restore(saved), std::invalid_argument);
  }
}

TEST(Engine, SnapshotBetweenSynchronisedTimesContinuesBitForBit) {
  // A snapshot taken anywhere (here after a count of events, between the
  // synchronised times 10 and 20), written out and read back, continues in
  // a second engine exactly as the first engine goes on: the same kick
  // pairs, collisions and positions through the next synchronisation.
  for (const auto rule : {KickPairs::neighbours, KickPairs::any}) {
    for (const double eps : {0.9, 1.0}) {
      Params p = params(400, 0.75, eps, eps < 1.0);
      p.tc = eps < 1.0 ? 1e-3 : 0.0;
      p.kick_pairs = rule;
      Engine a(p);
      a.prepare();
      a.run_until(10.0);
      a.synchronize();
      ASSERT_FALSE(a.run_until(20.0, 3 * 400 + 17)); // stops at an event, mid-interval
      dynhet::StateOut out;
      auto snap = a.snapshot();
      out(snap);
      dynhet::StateIn in(out.bytes().data(), out.bytes().size(), "snapshot");
      dynhet::engine::Snapshot back;
      in(back);
      Engine b(p);
      b.restore_snapshot(back);
      EXPECT_EQ(a.time(), b.time());
      for (const double t : {13.0, 17.5, 20.0}) {
        a.run_until(t);
        b.run_until(t);
        const auto ka = a.next_kick_pair(), kb = b.next_kick_pair();
        EXPECT_EQ(ka.i, kb.i);
        EXPECT_EQ(ka.j, kb.j);
      }
      a.synchronize();
      b.synchronize();
      a.run_until(25.0);
      b.run_until(25.0);
      std::vector<double> xa, xb;
      a.unwrapped_positions(xa);
      b.unwrapped_positions(xb);
      ASSERT_EQ(xa.size(), xb.size());
      for (size_t i = 0; i < xa.size(); ++i) ASSERT_EQ(xa[i], xb[i]) << i;
      EXPECT_EQ(a.counters().collisions, b.counters().collisions);
      EXPECT_EQ(a.counters().kicks, b.counters().kicks);
      EXPECT_EQ(a.counters().rebuilds, b.counters().rebuilds);
      EXPECT_EQ(a.counters().stale, b.counters().stale);
      EXPECT_EQ(a.counters().tc, b.counters().tc);
      EXPECT_EQ(a.counters().virial, b.counters().virial);
      EXPECT_GT(a.counters().collisions, 20 * 400);

      // A snapshot that does not fit is refused by name.
      auto bad = snap;
      std::swap(bad.id[0], bad.id[1]);
      bad.id[1] = bad.id[0];
      Engine c(p);
      EXPECT_THROW(c.restore_snapshot(bad), std::invalid_argument);
      bad = snap;
      bad.neighbours.push_back(3);
      EXPECT_THROW(c.restore_snapshot(bad), std::invalid_argument);
      if (rule == KickPairs::neighbours && eps < 1.0) {
        // Kick lists that hold every kick candidate, the neighbours too
        // (another layout of the rows), are refused by name.
        const auto nbr = rows_of(snap.neighbours, 400), kick = rows_of(snap.kick_lists, 400);
        dynhet::engine::Rows every;
        every.reset(400);
        for (size_t i = 0; i < 400; ++i) {
          for (const int j : nbr[i]) every.push(i, j);
          for (const int j : kick[i]) every.push(i, j);
        }
        bad = snap;
        every.save_packed(bad.kick_lists, true);
        try {
          c.restore_snapshot(bad);
          ADD_FAILURE() << "kick lists holding the neighbours were accepted";
        } catch (const std::invalid_argument& ex) {
          EXPECT_NE(std::string(ex.what()).find("repeat members of the neighbour lists"), std::string::npos) << ex.what();
        }
      }
      Params wrong = p;
      wrong.n_particles = 401;
      Engine d(wrong);
      EXPECT_THROW(d.restore_snapshot(snap), std::invalid_argument);
    }
  }
}

// The packed rows of a snapshot (Rows::save_packed): every row's members
// back in their order, whatever their distance from the base (far members
// take more bytes, not a wrong value); bytes that are not exactly the rows
// (cut short, left over, a member out of range) are refused.
TEST(Rows, PackedRowsRoundTripAndRefuseMalformedBytes) {
  using dynhet::engine::Rows;
  const int32_t limit = 3000000;
  for (const bool from_row : {true, false}) {
    Rows a;
    a.reset(6);
    const std::vector<std::vector<int32_t>> rows = {
        {}, {2, 0, 5, 1}, {limit - 1, 0, 7}, {3}, {}, {17, 16, 18, 2999999, 1, 0, 64, 63, 8191, 8192, 1 << 20}};
    for (size_t r = 0; r < rows.size(); ++r)
      for (const int32_t v : rows[r]) a.push(r, v);
    std::vector<uint8_t> bytes;
    a.save_packed(bytes, from_row);
    Rows b;
    ASSERT_TRUE(b.load_packed(rows.size(), bytes, limit, from_row));
    for (size_t r = 0; r < rows.size(); ++r) {
      ASSERT_EQ(b.row(r)[0], static_cast<int32_t>(rows[r].size()));
      for (size_t k = 0; k < rows[r].size(); ++k) EXPECT_EQ(b.row(r)[k + 1], rows[r][k]) << r << " " << k;
    }
    EXPECT_FALSE(b.load_packed(rows.size() + 1, bytes, limit, from_row)); // a row short
    EXPECT_FALSE(b.load_packed(rows.size() - 1, bytes, limit, from_row)); // bytes left over
    EXPECT_FALSE(b.load_packed(rows.size(), bytes, limit - 1, from_row)); // limit - 1 out of range
    auto cut_short = bytes;
    cut_short.pop_back();
    EXPECT_FALSE(b.load_packed(rows.size(), cut_short, limit, from_row));
    auto unterminated = bytes;
    unterminated.back() |= 0x80; // the last number never ends
    EXPECT_FALSE(b.load_packed(rows.size(), unterminated, limit, from_row));
  }
}

// A row's head (the neighbour lists keep their centre there) is the
// owner's: pushes, removals and the stride doubling when a row overflows
// keep it and the members, in order; clearing a row keeps its head.
TEST(Rows, HeadsSurviveGrowthPushesAndRemovals) {
  using dynhet::engine::Rows;
  struct Head {
    double x, y;
  };
  Rows a(4);
  a.reset(3);
  for (size_t r = 0; r < 3; ++r) a.set_head(r, Head{0.5 + r, -1.25 * r});
  for (int v = 0; v < 11; ++v) a.push(1, v); // fills row 1 at stride 16 (4 head words, a count, 11 members)
  a.push(0, 7);
  const size_t before = a.bytes();
  a.push(1, 11); // the 12th member: the stride doubles
  EXPECT_EQ(a.bytes(), 2 * before);
  a.remove(1, 3);
  a.clear(2);
  for (size_t r = 0; r < 3; ++r) {
    const Head h = a.head<Head>(r);
    EXPECT_EQ(h.x, 0.5 + r);
    EXPECT_EQ(h.y, -1.25 * r);
  }
  const std::vector<int32_t> row1{0, 1, 2, 11, 4, 5, 6, 7, 8, 9, 10}; // 3 removed: the last member took its place
  ASSERT_EQ(a.row(1)[0], static_cast<int32_t>(row1.size()));
  for (size_t k = 0; k < row1.size(); ++k) EXPECT_EQ(a.row(1)[k + 1], row1[k]) << k;
  EXPECT_EQ(a.row(0)[0], 1);
  EXPECT_EQ(a.row(0)[1], 7);
  EXPECT_EQ(a.row(2)[0], 0);
}

// A prepared state (compressed, velocities drawn, before begin()) serves
// every restitution and driving: a run started from it equals, bit for
// bit, the run that compresses itself with the same seed. Compression is
// elastic and undriven, and uses the same cells whatever the run does.
TEST(Engine, PreparedStateGivesTheRunThatCompressesItself) {
  Params base = params(500, 0.74, 1.0, false);
  Engine prep(base);
  prep.compress();
  prep.thermalize(1.0);
  const auto prepared = prep.state();
  for (const double eps : {1.0, 0.9, 0.7}) {
    Params p = params(500, 0.74, eps, eps < 1.0);
    Engine a(p), b(p);
    a.prepare();
    b.start_prepared(prepared);
    a.run_until(5.0);
    b.run_until(5.0);
    std::vector<double> xa, xb;
    a.unwrapped_positions(xa);
    b.unwrapped_positions(xb);
    ASSERT_EQ(xa.size(), xb.size());
    for (size_t i = 0; i < xa.size(); ++i) ASSERT_EQ(xa[i], xb[i]) << "eps " << eps << ", " << i;
    EXPECT_EQ(a.counters().collisions, b.counters().collisions);
    EXPECT_EQ(a.counters().kicks, b.counters().kicks);
    EXPECT_GT(a.counters().collisions, 1000);
  }
  // Positions from elsewhere: refused if they overlap or leave the box.
  Engine c(base);
  std::vector<double> x(prepared.x), y(prepared.y);
  c.place(x, y);
  EXPECT_GE(brute_min_gap(c), 1.0 - 1e-9);
  y[1] = y[0], x[1] = x[0] + 0.5; // 1 sits on 0
  EXPECT_THROW(c.place(x, y), std::invalid_argument);
  x[1] = -1.0;
  EXPECT_THROW(c.place(x, y), std::invalid_argument);
  x[1] = NAN;
  EXPECT_THROW(c.place(x, y), std::invalid_argument);
}

// The neighbour-list skin changes only the bookkeeping: from one state, a
// thin skin (a rebuild every few collisions) and a thick one (lists longer
// than a cache line, so they grow) make the same collisions in the same
// order. Roundoff differs (positions are wrapped into the box at different
// times) and the dynamics is chaotic, so the run is short: about one
// collision per particle, where differences of 1e-16 grow to at most
// ~1e-12. A collision missed by either would change the counts and move
// particles by O(sigma).
TEST(Engine, SkinChangesNoCollision) {
  Params p = params(2000, 0.78, 1.0, false);
  Engine src(p);
  src.prepare();
  src.synchronize();
  const auto start = src.state();
  Params thin = p, thick = p;
  thin.skin = 0.05;
  thick.skin = 4.0;
  Engine a(thin), b(thick);
  a.restore(start);
  b.restore(start);
  for (double t = 0.02; t <= 0.0801; t += 0.02) {
    a.run_until(t);
    b.run_until(t);
    EXPECT_GT(brute_min_gap(a), 1 - 1e-9) << t;
    EXPECT_GT(brute_min_gap(b), 1 - 1e-9) << t;
  }
  EXPECT_GT(a.counters().rebuilds, p.n_particles / 2); // the thin skin was left often
  EXPECT_GT(a.counters().collisions, p.n_particles / 2);
  EXPECT_EQ(a.counters().collisions, b.counters().collisions);
  std::vector<double> xa, xb;
  a.unwrapped_positions(xa);
  b.unwrapped_positions(xb);
  double worst = 0;
  for (size_t i = 0; i < xa.size(); ++i) worst = std::max(worst, std::abs(xa[i] - xb[i]));
  EXPECT_LT(worst, 1e-9);
  std::printf("%ld collisions, %ld rebuilds (thin skin); largest difference %.3g\n", long(a.counters().collisions), long(a.counters().rebuilds), worst);
  EXPECT_GT(b.mean_neighbours(), 15); // the thick skin's lists outgrew one line (15 ids)

  Params bad = p;
  bad.skin = -1;
  EXPECT_THROW(Engine{bad}, std::invalid_argument);
}

TEST(Engine, RefusesMoreParticlesThanTheCalendarCanNumber) {
  // The calendar packs particle ids into 27 bits: 2^27 + 1 particles are
  // refused before anything is allocated.
  Params p = dynhet::engine::paper_params(dynhet::engine::Calendar::kMaxLeaves + 1, 0.7, 1.0, false);
  try {
    Engine e(p);
    FAIL() << "accepted " << p.n_particles << " particles";
  } catch (const std::invalid_argument& ex) {
    EXPECT_NE(std::string(ex.what()).find("at most 134217728 particles"), std::string::npos) << ex.what();
  }
}

// The partner drawn from the kick list (rejection from a superset) against
// the 3 x 3-cell search of the earlier engine: the same distribution of
// partners, so the same dynamics. Over 6 seeds each (N = 1000, phi = 0.78,
// eps = 0.9, the paper's driving), the seed means of the reduced pressure,
// the temperature, the self overlap at lag 4 (|dr| < 0.3 small radii,
// structural relaxation) and the partner gap (its mean and the share in
// the lower half of the reach, from 300 kicks per run) agree within 4
// combined standard errors of the seeds' spread. The trajectories differ.
TEST(Engine, KickListDrawsTheSameDynamicsAsTheCellSearch) {
  constexpr int kSeeds = 6, kQ = 5;
  const char* names[kQ] = {"Z", "T", "Q(4)", "mean gap", "gap share below reach/2"};
  double sum[2][kQ] = {}, sum2[2][kQ] = {};
  for (int cells = 0; cells < 2; ++cells)
    for (int seed = 1; seed <= kSeeds; ++seed) {
      Params p = dynhet::engine::paper_params(1000, 0.78, 0.9, true);
      p.seed = static_cast<uint64_t>(seed);
      p.kick_search_cells = cells == 1;
      Engine e(p);
      e.prepare();
      e.run_until(5.0);
      const double v0 = e.counters().virial;
      double ke = 0;
      std::vector<double> x0, x1;
      e.unwrapped_positions(x0);
      double gap = 0, low = 0;
      const int kicks = 300;
      for (int s = 1; s <= kicks; ++s) {
        e.run_until(5.0 + 4.0 * s / kicks);
        ke += e.kinetic_energy_per_particle() / kicks;
        const auto pair = e.next_kick_pair();
        std::vector<double> xy;
        e.unwrapped_positions(xy);
        const long i = pair.i, j = pair.j;
        double dx = xy[2 * i] - xy[2 * j], dy = xy[2 * i + 1] - xy[2 * j + 1];
        const double L = e.box_length();
        dx -= L * std::round(dx / L);
        dy -= L * std::round(dy / L);
        const double g = std::hypot(dx, dy) - e.radius(e.species()[i]) - e.radius(e.species()[j]);
        ASSERT_LE(g, p.kick_reach + 1e-9);
        gap += g / kicks;
        low += (g < 0.5 * p.kick_reach) / double(kicks);
      }
      e.unwrapped_positions(x1);
      double q = 0;
      for (long k = 0; k < e.size(); ++k)
        q += std::hypot(x1[2 * k] - x0[2 * k], x1[2 * k + 1] - x0[2 * k + 1]) < 0.3;
      const double z = dynhet::engine::reduced_pressure(e.counters().virial - v0, 4.0, e.size(), ke);
      const double v[kQ] = {z, dynhet::engine::temperature(ke, e.size()), q / e.size(), gap, low};
      for (int k = 0; k < kQ; ++k) sum[cells][k] += v[k], sum2[cells][k] += v[k] * v[k];
    }
  for (int k = 0; k < kQ; ++k) {
    double m[2], se[2];
    for (int c = 0; c < 2; ++c) {
      m[c] = sum[c][k] / kSeeds;
      se[c] = std::sqrt(std::max(0.0, sum2[c][k] / kSeeds - m[c] * m[c]) / (kSeeds - 1));
    }
    const double tol = 4 * std::hypot(se[0], se[1]);
    std::printf("%-26s kick list %.5g +- %.2g   cell search %.5g +- %.2g   (%.1f sigma)\n", names[k], m[0], se[0],
                m[1], se[1], std::abs(m[0] - m[1]) / std::hypot(se[0], se[1]));
    EXPECT_GT(tol, 0) << names[k];
    EXPECT_NEAR(m[0], m[1], tol) << names[k];
  }
}
