// The driving's kicks (engine.hpp, class Engine): which pair a kick takes
// (neighbour pairs from the neighbour and kick lists, or the 3 x 3-cell search they
// replaced; pairs from the whole system) and the kick itself. The kick
// lists are kept with the neighbour lists, in lists.cpp.
#include "dynhet/engine/engine.hpp"

#include <cmath>
#include <stdexcept>

#include "dynhet/engine/collision.hpp"
#include "dynhet/model.hpp"

namespace dynhet::engine {

// Driving (paper, section 2): "kicks" to "randomly chosen pairs of
// particles": the pair gets opposite momenta +-p_Dr kappa, kappa a 2D
// standard Gaussian vector, "to ensure conservation of the total momentum of
// the system" (citing Espanol and Warren, Europhys. Lett. 30, 191 (1995)).
// With two species the amplitude is p_Dr^2 = (1 - eps^2) m1 m2 / (m1 + m2)
// for every pair. How the pair is drawn the paper leaves to its references:
//
// - KickPairs::neighbours (the default): the first particle uniform over
//   the system, the second uniform among the particles whose surface lies
//   within kick_reach of its surface (|r_i - r_j| <= sigma_ij + reach) at
//   the time of the kick. In Espanol and Warren's dissipative particle
//   dynamics the random forces act between neighbours, and the driven
//   granular fluids of Fiege et al. (2009) and Gholami et al. (2011),
//   which the paper cites for its details, show the hydrodynamic long-time
//   tails that exist only when the driving conserves momentum locally.
//   A first particle with nobody in reach is drawn again (counted in
//   kick_redraws), so the kick rate stays what the scene says; after
//   kMaxKickDraws such draws (a very dilute gas, where locality means
//   little) the last one's partner is drawn from the whole system
//   (kick_far).
// - KickPairs::any: two distinct particles uniform over the whole system:
//   momentum is conserved only globally, and each kick acts like an
//   independent random force on two distant particles. Near phi_c the two
//   rules differ in tau_alpha by more than tenfold (docs/engine.md).
//
// Every draw comes from a hash of the seed and the kick's number (and the
// draw's), by storage slot, so it needs no random state of its own (the
// kick count is checkpointed); the neighbours are read from the positions
// now. Slots, cells and positions follow from the state alone after a
// synchronisation (reorder()), so a run restored from a checkpoint draws
// the same pairs.
namespace {
// Uniform in [0, n) from a 64-bit hash.
int below(uint64_t h, uint64_t n) { return static_cast<int>((static_cast<unsigned __int128>(h) * n) >> 64); }
} // namespace

uint64_t Engine::kick_hash(int64_t k, int draw, int which) const {
  const uint64_t h = mix64(kick_key_ + 2 * static_cast<uint64_t>(k) + which);
  return draw == 0 ? h : mix64(h ^ static_cast<uint64_t>(draw)); // the first draw's: those of the rule "any"
}

int Engine::kick_pair(int64_t k, int& i, int& j) const {
  const auto hash = [&](int d, int which) { return kick_hash(k, d, which); };
  if (neighbour_kicks_ && kick_lists()) {
    for (int d = 0; d < kMaxKickDraws; ++d) {
      i = below(hash(d, 0), static_cast<uint64_t>(n_));
      if ((j = kick_partner(k, d, i)) >= 0) return d;
    }
  } else if (neighbour_kicks_) {
    int32_t cand[kMaxKickCandidates];
    for (int d = 0; d < kMaxKickDraws; ++d) {
      i = below(hash(d, 0), static_cast<uint64_t>(n_));
      if (const int m = kick_candidates(i, cand); m > 0) {
        j = cand[below(hash(d, 1), static_cast<uint64_t>(m))];
        return d;
      }
    }
  } else {
    i = below(hash(0, 0), static_cast<uint64_t>(n_));
  }
  j = below(hash(0, 1), static_cast<uint64_t>(n_ - 1));
  if (j >= i) ++j;
  return neighbour_kicks_ ? kMaxKickDraws : 0;
}

// The 3 x 3 cells around i's list centre hold every such partner: centres
// are within skin / 2 of their particles, and cells at least the largest
// contact distance plus skin plus reach wide.
int Engine::kick_candidates(int i, int32_t* out) const {
  const Particle& a = part_[i];
  const double ax = a.x + a.vx * (now_ - a.t), ay = a.y + a.vy * (now_ - a.t);
  const double ri = radius_[a.species] + p_.kick_reach;
  int around[9];
  cells_around(cell_x_[i], cell_y_[i], around);
  int m = 0;
  for (const int ci : around) {
    const int32_t* c = cells_.row(ci);
    for (int k = 1; k <= c[0]; ++k) {
      const int j = c[k];
      const Particle& b = part_[j];
      const double dx = min_image(ax - (b.x + b.vx * (now_ - b.t))), dy = min_image(ay - (b.y + b.vy * (now_ - b.t)));
      const double reach = ri + radius_[b.species];
      if (j != i && dx * dx + dy * dy <= reach * reach) {
        if (m == kMaxKickCandidates) throw std::logic_error("engine: more than 512 particles within kick reach");
        out[m++] = j;
      }
    }
  }
  return m;
}

bool Engine::within_kick_reach(int i, int j) const {
  const Particle &a = part_[i], &b = part_[j];
  const double dx = min_image((a.x + a.vx * (now_ - a.t)) - (b.x + b.vx * (now_ - b.t)));
  const double dy = min_image((a.y + a.vy * (now_ - a.t)) - (b.y + b.vy * (now_ - b.t)));
  // The species from j's line, read anyway for its position (species_[j]
  // would be one more miss per trial at large N).
  const double reach = radius_[a.species] + p_.kick_reach + radius_[b.species];
  return dx * dx + dy * dy <= reach * reach;
}

// The second particle of draw d of kick k, first particle i: i's kick
// candidates (its neighbour list, then its kick list) drawn uniformly
// (hashes of k, d and the trial) until one is within reach: uniform over
// those within reach. After kKickTrials in vain (few or none within reach)
// the candidates are searched whole and one of those within reach taken
// uniformly (the same distribution), or -1 if none.
int Engine::kick_partner(int64_t k, int d, int i) const {
  const int32_t* a = list(i);
  const int32_t* b = kick_beyond_.row(static_cast<size_t>(i));
  const int m = a[0] + b[0];
  if (m == 0) return -1;
  const uint64_t h = kick_hash(k, d, 1);
  for (int t = 0; t < kKickTrials; ++t) {
    const int j = kick_candidate(
        a, b, below(t == 0 ? h : mix64(h + 0x9e3779b97f4a7c15ULL * static_cast<uint64_t>(t)), static_cast<uint64_t>(m)));
    if (within_kick_reach(i, j)) return j;
  }
  int32_t cand[kMaxKickCandidates];
  int c = 0;
  for (int u = 0; u < m; ++u)
    if (const int j = kick_candidate(a, b, u); within_kick_reach(i, j)) {
      if (c == kMaxKickCandidates) throw std::logic_error("engine: more than 512 particles within kick reach");
      cand[c++] = j;
    }
  return c ? cand[below(mix64(h ^ 0x5f6c6973745f6b21ULL), static_cast<uint64_t>(c))] : -1;
}

Engine::KickPair Engine::next_kick_pair() const {
  int i, j;
  const int redraws = kick_pair(count_.kicks, i, j);
  return KickPair{id_[i], id_[j], redraws};
}

void Engine::prefetch_list(int i) const {
  nbr_.prefetch(i); // the list and its centre
}

void Engine::prefetch_particle(int i) const {
  __builtin_prefetch(&part_[i]);
  prefetch_list(i);
}

void Engine::kick() {
  int i, j;
  if (const int redraws = kick_pair(count_.kicks, i, j); redraws > 0) {
    count_.kick_redraws += std::min(redraws, kMaxKickDraws - 1);
    count_.kick_far += redraws == kMaxKickDraws;
  }
  // Their lines were requested at the previous kick; now their neighbours'.
  prefetch_neighbours(i);
  prefetch_neighbours(j);
  double kx, ky;
  rng_.normal_pair(kx, ky);
  const double p = kick_amplitude(eps_, mass_[0], mass_[1]);
  sync(i);
  sync(j);
  const double mi = mass_of(static_cast<int>(i)), mj = mass_of(j);
  part_[i].vx += p * kx / mi;
  part_[i].vy += p * ky / mi;
  part_[j].vx -= p * kx / mj;
  part_[j].vy -= p * ky / mj;
  ++part_[i].coll;
  ++part_[j].coll;
  ++count_.kicks;
  kick_time_ = now_ + rng_.exponential(kick_pair_rate_);
  predict(i);
  predict(j);
  // The next pair's lines. With neighbour pairs from kick lists, in stages
  // (below); with the cell search, the first particle's and its cell's: its
  // partner depends on where things are then (requesting the search's own
  // lines a kick or two ahead gained nothing measurable there).
  if (neighbour_kicks_) {
    const int ni = below(kick_hash(count_.kicks, 0, 0), static_cast<uint64_t>(n_));
    if (kick_lists()) {
      // In stages: the rows of the next kick's first particle (its
      // neighbour list and kick list) were requested a kick ago, so its
      // first draw's particle (line, list and centre) can be requested now,
      // with the first particle's; the rows of the kick after it now.
      prefetch_particle(ni);
      const int32_t *a = list(ni), *b = kick_beyond_.row(ni);
      if (const int m = a[0] + b[0]; m > 0)
        prefetch_particle(kick_candidate(a, b, below(kick_hash(count_.kicks, 0, 1), static_cast<uint64_t>(m))));
      const int nn = below(kick_hash(count_.kicks + 1, 0, 0), static_cast<uint64_t>(n_));
      __builtin_prefetch(&part_[nn]);
      nbr_.prefetch(nn);
      kick_beyond_.prefetch(nn);
    } else {
      __builtin_prefetch(&part_[ni]);
      __builtin_prefetch(&cell_x_[ni]);
      __builtin_prefetch(&cell_y_[ni]);
    }
  } else {
    int ni, nj;
    kick_pair(count_.kicks, ni, nj);
    prefetch_particle(ni);
    prefetch_particle(nj);
  }
}

} // namespace dynhet::engine
