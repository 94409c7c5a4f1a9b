// The event loop (engine.hpp, class Engine): cells, synchronisation of one
// particle, predictions, collisions and the calendar; the lists are in
// lists.cpp, the kicks in kicks.cpp, how a run starts in setup.cpp.
#include "dynhet/engine/engine.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <cmath>
#include <stdexcept>
#include <string>

#include "dynhet/engine/collision.hpp"
#include "dynhet/model.hpp"

#if defined(__x86_64__) && defined(__gnu_linux__) && !defined(DYNHET_NO_CLONES)
#include <immintrin.h>
#define DYNHET_AVX2_GATHER 1
#endif

namespace dynhet::engine {

Engine::Engine(const Params& p) : p_(p), n_(p.n_particles), eps_(p.restitution), rng_(p.seed) {
#ifdef DYNHET_AVX2_GATHER
  vector_pair_tests_ = avx2_gather_fits() && !std::getenv("DYNHET_PORTABLE_PAIR_TESTS");
#endif
  if (n_ < 2) throw std::invalid_argument("engine: need at least 2 particles");
  if (n_ > Calendar::kMaxLeaves)
    throw std::invalid_argument("engine: at most " + std::to_string(Calendar::kMaxLeaves) + " particles, not " +
                                std::to_string(n_));
  const Model m = make_model(n_, p.packing_fraction, p.radius_ratio);
  box_ = m.box_length;
  half_box_ = 0.5 * box_;
  for (int s = 0; s < 2; ++s) {
    radius_[s] = m.radius[s];
    mass_[s] = m.mass[s];
  }
  species_by_id_.resize(n_);
  for (long i = 0; i < n_; ++i) species_by_id_[i] = static_cast<uint8_t>(species_of(i, n_));
  id_.resize(n_);
  for (long i = 0; i < n_; ++i) id_[i] = static_cast<int32_t>(i);

  if (!(p.skin >= 0) || !std::isfinite(p.skin))
    throw std::invalid_argument("engine: the neighbour-list skin must be positive (or 0 for automatic), not " +
                                std::to_string(p.skin));
  list_margin_ = 1e-12 * box_;
  neighbour_kicks_ = p.driving && p.kick_rate > 0 && p.restitution < 1.0 && p.kick_pairs == KickPairs::neighbours;
  if (neighbour_kicks_ && !(p.kick_reach > 0 && std::isfinite(p.kick_reach)))
    throw std::invalid_argument("engine: the kick reach must be a positive gap, not " + std::to_string(p.kick_reach));
  const double widest = 2.0 * std::max(radius_[0], radius_[1]) + 2 * list_margin_;
  skin_ = (p.skin > 0 ? p.skin : auto_skin(p.packing_fraction)) * radius_[0];
  // An automatic skin narrows to let a small box hold 3 cells.
  if (p.skin == 0) skin_ = std::max(0.0, std::min(skin_, 0.999 * (box_ / 3 - widest)));
  // Cells over list centres at least as wide as the largest contact
  // distance plus the skin, at least 3 a side. In the run, with neighbour
  // kick pairs, wider by the kick reach: the 3 x 3 cells around a particle's
  // then hold every partner its kick may take. Compression uses the narrower
  // cells whatever the run does, so that its result, a prepared state, is
  // the same for every restitution and driving.
  nc_compress_ = static_cast<int>(std::floor(box_ / (widest + skin_)));
  nc_run_ = static_cast<int>(std::floor(box_ / (widest + skin_ + (neighbour_kicks_ ? p.kick_reach : 0.0))));
  if (nc_run_ < 3 || !(skin_ > 0))
    throw std::invalid_argument("engine: box of side " + std::to_string(box_) +
                                " holds fewer than 3 cells of the largest contact distance plus the skin" +
                                (neighbour_kicks_ ? " and the kick reach" : "") +
                                "; use more particles or a thinner skin");
  use_cells(false);

  part_.assign(n_, Particle{0, 0, 0, 0, 0, kNever, 0, 0, kRebuild, 0});
  for (long i = 0; i < n_; ++i) part_[i].species = species_by_id_[i];
  species_ = species_by_id_;
  image_x_.assign(n_, 0);
  image_y_.assign(n_, 0);
  last_collision_.assign(n_, -kNever);
  nbr_.reset(static_cast<size_t>(n_));
}

double Engine::packing_fraction() const {
  double a = 0;
  for (long i = 0; i < n_; ++i) a += M_PI * radius_[part_[i].species] * radius_[part_[i].species];
  return a * scale() * scale() / (box_ * box_);
}

// ---------------------------------------------------------------- cells

void Engine::cell_insert(int i, int cx, int cy) {
  cells_.push(cell_index(cx, cy), i);
  cell_x_[i] = cx;
  cell_y_[i] = cy;
}

void Engine::cell_remove(int i) { cells_.remove(cell_index(cell_x_[i], cell_y_[i]), i); }

void Engine::cells_around(int cx, int cy, int out[9]) const {
  for (int dy = 0; dy < 3; ++dy)
    for (int dx = 0; dx < 3; ++dx) {
      const int x = cx + dx - 1, y = cy + dy - 1;
      out[3 * dy + dx] = cell_index(x < 0 ? x + nc_ : (x >= nc_ ? x - nc_ : x), y < 0 ? y + nc_ : (y >= nc_ ? y - nc_ : y));
    }
}

void Engine::clear_cells() {
  cells_.reset(static_cast<size_t>(nc_) * nc_);
  cell_x_.assign(n_, 0);
  cell_y_.assign(n_, 0);
}

void Engine::build_cells() {
  clear_cells();
  for (long i = 0; i < n_; ++i)
    cell_insert(static_cast<int>(i), cell_coord(part_[i].x), cell_coord(part_[i].y));
}

void Engine::reorder() {
  // Positions into the box first: the order must follow from the state
  // alone (a run restored from a checkpoint, whose positions are wrapped,
  // gets the same slots, and so the same kick pairs).
  for (long s = 0; s < n_; ++s) wrap(static_cast<int>(s));
  std::vector<int32_t> cell(n_);
  for (long s = 0; s < n_; ++s) cell[s] = cell_index(cell_coord(part_[s].x), cell_coord(part_[s].y));
  std::vector<int32_t> order(n_);
  for (long s = 0; s < n_; ++s) order[s] = static_cast<int32_t>(s);
  std::sort(order.begin(), order.end(), [&](int32_t a, int32_t b) {
    return cell[a] != cell[b] ? cell[a] < cell[b] : id_[a] < id_[b];
  });
  auto permute = [&](auto& v) {
    auto old = v;
    for (long s = 0; s < n_; ++s) v[s] = old[order[s]];
  };
  permute(part_);
  permute(species_);
  permute(image_x_);
  permute(image_y_);
  permute(last_collision_);
  permute(id_);
  build_cells();
}

// ---------------------------------------------------------------- events

void Engine::sync(int i) {
  Particle& a = part_[i];
  const double dt = now_ - a.t;
  a.x += a.vx * dt;
  a.y += a.vy * dt;
  a.t = now_;
}

// Next event of particle i (synchronised to now): reaching the edge of its
// skin, or the earliest collision with a particle of its list (the
// neighbours' own events stay as they are: engine.hpp says why). The
// neighbours' cache lines are requested all at once before any is
// read: at large N each is a miss, and waiting for them one by one would
// cost most of the time.
void Engine::prefetch_neighbours(int i) const {
  const int32_t* l = list(i);
  for (int k = 1; k <= l[0]; ++k) __builtin_prefetch(&part_[l[k]]);
}

// Collision times of particle (x, y, vx, vy, r) with a block of neighbours
// (bx, by, bvx, bvy, br at their local times bt) at time now, by
// pair_collision_time(), which has no branch: the compiler makes vector
// code of the loop. An AVX2 clone (4 lanes, no FMA, so the same bits) is
// picked at run time where the compiler and the C library support it
// (x86-64 with ifunc); elsewhere, or with DYNHET_NO_CLONES, one portable
// version.
#if defined(__x86_64__) && defined(__gnu_linux__) && !defined(DYNHET_NO_CLONES)
#define DYNHET_PAIR_CLONES [[gnu::target_clones("avx2", "default")]]
#else
#define DYNHET_PAIR_CLONES
#endif

struct PairBlock {
  static constexpr int kSize = 8;
  double x, y, vx, vy, r, now, scale, growth, box, half_box;
  alignas(32) double bx[kSize], by[kSize], bvx[kSize], bvy[kSize], bt[kSize], br[kSize];
};

namespace {

// The body of collision_times(), also inlined into pair_block_avx2().
[[gnu::always_inline]] inline void collision_times_of(const PairBlock& p, double* dt) {
  for (int q = 0; q < PairBlock::kSize; ++q) {
    const double bdt = p.now - p.bt[q];
    const double x = p.x - (p.bx[q] + p.bvx[q] * bdt), y = p.y - (p.by[q] + p.bvy[q] * bdt);
    const double rsum = p.r + p.br[q];
    dt[q] = pair_collision_time(nearest_image(x, p.box, p.half_box), nearest_image(y, p.box, p.half_box),
                                p.vx - p.bvx[q], p.vy - p.bvy[q], p.scale * rsum, p.growth * rsum);
  }
}

DYNHET_PAIR_CLONES void collision_times(const PairBlock& p, double* dt) { collision_times_of(p, dt); }

// The first lane q < nk with the smallest dt[q], if that is below best
// (then best becomes it), else -1: what a scan in lane order keeping the
// first strictly smaller value finds.
int earliest_lane(const double* dt, int nk, double& best) {
  int lane = -1;
  for (int q = 0; q < nk; ++q)
    if (dt[q] < best) best = dt[q], lane = q;
  return lane;
}
} // namespace

// What the pair tests read of the neighbours l[0], ..., l[nk - 1] (and of
// l[nk - 1] again for the lanes beyond them) copied into the block. This
// moves data only, so every version gives the same block (and the same
// trajectories). Where the processor has AVX2, each half of a neighbour's
// line is read as one vector and four neighbours' halves are transposed in
// registers: (x, y, vx, vy) and (t, event time, counter, partner) give bx,
// by, bvx, bvy and bt, and the counter word's top bit, the species, picks
// the radius by its sign (blendv): per neighbour, six loads and six
// stores (and a look-up of the radius) become two loads, about three
// shuffles and one and a half stores. The pair tests follow inlined, and
// the earliest lane is found by vector compares.
#ifdef DYNHET_AVX2_GATHER
[[gnu::target("avx2")]] int Engine::pair_block_avx2(const Particle* part, const int32_t* l, int nk,
                                                    const double* radius, PairBlock& blk, double& best) {
  // The indices: lanes below nk from the list, the others its last member
  // (a masked load reads nothing beyond the list).
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i in_list = _mm256_cmpgt_epi32(_mm256_set1_epi32(nk), lane);
  const __m256i idx = _mm256_blendv_epi8(_mm256_set1_epi32(l[nk - 1]), _mm256_maskload_epi32(l, in_list), in_list);
  alignas(32) int32_t k[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(k), idx);
  const __m256d r0 = _mm256_set1_pd(radius[0]), r1 = _mm256_set1_pd(radius[1]);
  for (int h = 0; h < PairBlock::kSize; h += 4) {
    const double* b0 = &part[k[h]].x;
    const double* b1 = &part[k[h + 1]].x;
    const double* b2 = &part[k[h + 2]].x;
    const double* b3 = &part[k[h + 3]].x;
    {
      const __m256d q0 = _mm256_load_pd(b0), q1 = _mm256_load_pd(b1), q2 = _mm256_load_pd(b2), q3 = _mm256_load_pd(b3);
      const __m256d t0 = _mm256_unpacklo_pd(q0, q1), t1 = _mm256_unpackhi_pd(q0, q1); // x0 x1 vx0 vx1, y0 y1 vy0 vy1
      const __m256d t2 = _mm256_unpacklo_pd(q2, q3), t3 = _mm256_unpackhi_pd(q2, q3);
      _mm256_store_pd(blk.bx + h, _mm256_permute2f128_pd(t0, t2, 0x20));
      _mm256_store_pd(blk.bvx + h, _mm256_permute2f128_pd(t0, t2, 0x31));
      _mm256_store_pd(blk.by + h, _mm256_permute2f128_pd(t1, t3, 0x20));
      _mm256_store_pd(blk.bvy + h, _mm256_permute2f128_pd(t1, t3, 0x31));
    }
    {
      const __m256d q0 = _mm256_load_pd(b0 + 4), q1 = _mm256_load_pd(b1 + 4);
      const __m256d q2 = _mm256_load_pd(b2 + 4), q3 = _mm256_load_pd(b3 + 4);
      const __m256d t0 = _mm256_unpacklo_pd(q0, q1), t2 = _mm256_unpacklo_pd(q2, q3); // t0 t1 c0 c1, t2 t3 c2 c3
      _mm256_store_pd(blk.bt + h, _mm256_permute2f128_pd(t0, t2, 0x20));
      _mm256_store_pd(blk.br + h, _mm256_blendv_pd(r0, r1, _mm256_permute2f128_pd(t0, t2, 0x31)));
    }
  }
  alignas(32) double dt[PairBlock::kSize];
  collision_times_of(blk, dt);
  // The earliest lane as earliest_lane() finds it: lanes beyond the list,
  // and any NaN, count as never; the first lane holding the minimum.
  const __m256d never = _mm256_set1_pd(kNever);
  const __m256i in_lo = _mm256_cvtepi32_epi64(_mm256_castsi256_si128(in_list));
  const __m256i in_hi = _mm256_cvtepi32_epi64(_mm256_extracti128_si256(in_list, 1));
  __m256d lo = _mm256_load_pd(dt), hi = _mm256_load_pd(dt + 4);
  lo = _mm256_blendv_pd(never, lo, _mm256_and_pd(_mm256_castsi256_pd(in_lo), _mm256_cmp_pd(lo, lo, _CMP_ORD_Q)));
  hi = _mm256_blendv_pd(never, hi, _mm256_and_pd(_mm256_castsi256_pd(in_hi), _mm256_cmp_pd(hi, hi, _CMP_ORD_Q)));
  __m256d m = _mm256_min_pd(lo, hi);
  m = _mm256_min_pd(m, _mm256_permute2f128_pd(m, m, 0x01));
  m = _mm256_min_pd(m, _mm256_permute_pd(m, 0x5));
  const double low = _mm256_cvtsd_f64(m);
  if (!(low < best)) return -1;
  best = low;
  const int at = _mm256_movemask_pd(_mm256_cmp_pd(lo, m, _CMP_EQ_OQ)) | _mm256_movemask_pd(_mm256_cmp_pd(hi, m, _CMP_EQ_OQ)) << 4;
  return __builtin_ctz(static_cast<unsigned>(at));
}

// pair_block_avx2 reads t at byte 32 and the species as the top bit of the
// word at byte 48 (the bit-field's place in this ABI, checked here, not
// assumed: elsewhere the portable copy runs, with the same result).
bool Engine::avx2_gather_fits() {
  static_assert(offsetof(Particle, x) == 0 && offsetof(Particle, vy) == 24 && offsetof(Particle, t) == 32 &&
                offsetof(Particle, partner) == 56);
  Particle p{};
  p.species = 1;
  uint64_t word;
  std::memcpy(&word, reinterpret_cast<const char*>(&p) + 48, sizeof word);
  return word == uint64_t{1} << 63 && __builtin_cpu_supports("avx2");
}
#endif

int Engine::pair_block(const int32_t* l, int nk, PairBlock& blk, double& best) const {
#ifdef DYNHET_AVX2_GATHER
  if (vector_pair_tests_) return pair_block_avx2(part_.data(), l, nk, radius_, blk, best);
#endif
  for (int q = 0; q < PairBlock::kSize; ++q) {
    const Particle& b = part_[l[std::min(q, nk - 1)]]; // beyond the list: the last one again
    blk.bx[q] = b.x, blk.by[q] = b.y, blk.bvx[q] = b.vx, blk.bvy[q] = b.vy, blk.bt[q] = b.t;
    blk.br[q] = radius_[b.species];
  }
  alignas(32) double dt[PairBlock::kSize];
  collision_times(blk, dt);
  return earliest_lane(dt, nk, best);
}

void Engine::predict(int i) {
  const Particle& a = part_[i];
  const int32_t* l = list(i);
  const int m = l[0];
  prefetch_neighbours(i);

  // Leaving the disc of radius skin / 2 around the centre: the positive
  // root of |d + v t|^2 = R^2, d = r - c, in the cancellation-free form.
  double best = kNever;
  {
    const Centre c0 = centre(i);
    const double dx = a.x - c0.x, dy = a.y - c0.y;
    const double R = 0.5 * skin_;
    const double b = dx * a.vx + dy * a.vy, v2 = a.vx * a.vx + a.vy * a.vy, c = dx * dx + dy * dy - R * R;
    if (c >= 0) {
      best = 0; // at the edge already (roundoff)
    } else if (v2 > 0) {
      const double root = std::sqrt(b * b - v2 * c);
      best = b > 0 ? -c / (b + root) : (root - b) / v2;
    }
  }
  // The pair tests, a block of neighbours at a time: their data are copied
  // into short arrays, then collision_times() takes the block at once.
  PairBlock blk;
  blk.x = a.x, blk.y = a.y, blk.vx = a.vx, blk.vy = a.vy, blk.r = radius_[a.species];
  blk.now = now_, blk.scale = scale(), blk.growth = grow_, blk.box = box_, blk.half_box = half_box_;
  int best_k = 0;
  for (int k0 = 1; k0 <= m; k0 += PairBlock::kSize)
    if (const int q = pair_block(l + k0, std::min(PairBlock::kSize, m - k0 + 1), blk, best); q >= 0) best_k = k0 + q;
  const int32_t partner = best_k > 0 ? l[best_k] : kRebuild;
  const uint32_t partner_seen = best_k > 0 ? seen(part_[partner].coll) : 0;
  part_[i].partner = partner;
  part_[i].partner_seen = partner_seen;
  set_event_time(i, now_ + best);
}

// Every particle's event predicted again (the next kick stays).
// Lists are built afresh for radii up to list_scale_: while compressing, a
// round lasts at most one time unit (prepare()), so the radii reached by its
// end; then 1.
void Engine::clear_events() {
  for (long i = 0; i < n_; ++i) sync(static_cast<int>(i));
  list_scale_ = grow_ > 0 ? std::min(1.0, scale0_ + grow_ * (now_ + 1.0)) : scale0_;
  build_lists();
  cal_.suspend();
  for (long i = 0; i < n_; ++i) part_[i].event_time = kNever;
  for (long i = 0; i < n_; ++i) predict(static_cast<int>(i));
  cal_.rebuild(n_, now_, event_times());
}

void Engine::collide(int i, int j) {
  sync(i);
  sync(j);
  Particle &a = part_[i], &b = part_[j];
  double eps = eps_;
  if (p_.tc > 0 && eps < 1.0 &&
      (now_ - last_collision_[i] < p_.tc || now_ - last_collision_[j] < p_.tc)) {
    eps = 1.0; // TC model: too soon after the previous collision
    ++count_.tc;
  }
  if (p_.tc > 0) last_collision_[i] = last_collision_[j] = now_; // two cache misses otherwise wasted
  const double impulse = collide_pair(min_image(a.x - b.x), min_image(a.y - b.y), mass_of(static_cast<int>(i)),
                                      mass_of(j), eps, a.vx, a.vy, b.vx, b.vy, growth(i, j));
  count_.virial += sigma(i, j) * impulse;
  ++part_[i].coll;
  ++part_[j].coll;
  ++count_.collisions;
  prefetch_neighbours(j); // arriving while i's prediction computes
  predict(i);
  predict(j);
}

// Keep absolute time small: move every clock so that now is 0.
void Engine::rebase() {
  for (long i = 0; i < n_; ++i) {
    sync(static_cast<int>(i));
    part_[i].t = 0;
    last_collision_[i] -= now_;
  }
  kick_time_ -= now_;
  for (auto& a : part_) a.event_time -= now_;
  scale0_ += grow_ * now_;
  offset_ += now_;
  now_ = 0;
  events_since_rebase_ = 0;
  cal_.rebuild(n_, now_, event_times());
}

bool Engine::run_until(double t_abs, int64_t max_events) {
  const double target = t_abs - offset_;
  for (int64_t done = 0; done < max_events; ++done) {
    const Calendar::Entry next = cal_.top(event_times());
    // On a tie the particle's event comes first (as the kick was the last leaf of the tree calendar).
    const bool kick_next = kick_time_ < next.time;
    const double t = kick_next ? kick_time_ : next.time;
    const int leaf = next.leaf;
    if (t > target) {
      now_ = std::max(now_, target);
      if (events_since_rebase_ > 10 * n_) rebase();
      return true;
    }
    now_ = t;
    ++events_since_rebase_;
    // Software pipeline over the next events in the calendar: the list,
    // centre and partner of the third; the neighbours, and the partner's
    // list and centre, of the second; the partner's neighbours of the next.
    if (const int a3 = cal_.ahead(3); a3 >= 0) {
      prefetch_list(a3);
      if (const int q = part_[a3].partner; q >= 0) __builtin_prefetch(&part_[q]);
    }
    if (const int a2 = cal_.ahead(2); a2 >= 0) {
      prefetch_neighbours(a2);
      if (const int q = part_[a2].partner; q >= 0) prefetch_list(q);
    }
    if (const int a1 = cal_.ahead(1); a1 >= 0) {
      if (const int q = part_[a1].partner; q >= 0) prefetch_neighbours(q);
    }
    if (kick_next) {
      kick();
      continue;
    }
    // Lines the event will need, requested before the first is waited for:
    // the list and centre of the particle, then, once its line says who the
    // partner is, the same for the partner.
    prefetch_list(leaf);
    const int partner = part_[leaf].partner;
    if (partner == kRebuild) {
      sync(leaf);
      rebuild(leaf);
      continue;
    }
    prefetch_list(partner);
    if (seen(part_[partner].coll) != part_[leaf].partner_seen) {
      ++count_.stale;
      sync(leaf);
      predict(leaf);
    } else {
      collide(leaf, partner);
    }
  }
  return false;
}

// ---------------------------------------------------------------- checks

double Engine::kinetic_energy_per_particle() const {
  double e = 0;
  for (long i = 0; i < n_; ++i) {
    const auto& a = part_[i];
    e += 0.5 * mass_of(static_cast<int>(i)) * (a.vx * a.vx + a.vy * a.vy);
  }
  return e / n_;
}

void Engine::momentum(double& px, double& py) const {
  px = py = 0;
  for (long i = 0; i < n_; ++i) {
    px += mass_of(static_cast<int>(i)) * part_[i].vx;
    py += mass_of(static_cast<int>(i)) * part_[i].vy;
  }
}

void Engine::unwrapped_positions(std::vector<double>& xy) const {
  xy.resize(2 * n_);
  for (long k = 0; k < n_; ++k) {
    const auto& a = part_[k];
    const double dt = now_ - a.t;
    const long i = id_[k];
    xy[2 * i] = a.x + a.vx * dt + image_x_[k] * box_;
    xy[2 * i + 1] = a.y + a.vy * dt + image_y_[k] * box_;
  }
}

// Cells hold the list centres, each within skin / 2 of its particle and
// at least the largest contact distance plus the skin wide: every pair
// closer than its contact distance sits in neighbouring cells.
double Engine::min_gap_ratio() const {
  double best = kNever;
  for (long i = 0; i < n_; ++i) {
    const auto& a = part_[i];
    const double ax = a.x + a.vx * (now_ - a.t), ay = a.y + a.vy * (now_ - a.t);
    int around[9];
    cells_around(cell_x_[i], cell_y_[i], around);
    for (const int ci : around) {
      const int32_t* c = cells_.row(ci);
      for (int k = 1; k <= c[0]; ++k) {
        const int j = c[k];
        if (j <= i) continue;
        const auto& b = part_[j];
        const double ddx = min_image(ax - (b.x + b.vx * (now_ - b.t)));
        const double ddy = min_image(ay - (b.y + b.vy * (now_ - b.t)));
        best = std::min(best, std::sqrt(ddx * ddx + ddy * ddy) / sigma(static_cast<int>(i), j));
      }
    }
  }
  return best;
}

double Engine::mean_neighbours() const {
  double sum = 0;
  for (long i = 0; i < n_; ++i) sum += list(static_cast<int>(i))[0];
  return sum / n_;
}

size_t Engine::memory_bytes() const {
  auto b = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  return b(part_) + b(species_by_id_) + b(species_) + b(id_) + b(image_x_) + b(image_y_) + b(last_collision_) +
         cells_.bytes() + b(cell_x_) + b(cell_y_) + nbr_.bytes() + kick_beyond_.bytes() + cal_.bytes();
}

double Engine::max_overlap() const { return 1.0 - min_gap_ratio(); }

} // namespace dynhet::engine
