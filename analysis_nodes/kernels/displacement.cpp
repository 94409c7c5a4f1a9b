#include "dynhet/analysis/displacement.hpp"
#include "dynhet/subbox.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace dynhet::analysis {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Which grids get a per-particle index. From the finest down, a grid whose
// m divides that of a grid already placed is summed from the nearest such
// grid (so m, m/2, m/4 ... each sum the one before); any other is indexed.
void plan_grids(const DisplacementSpec& spec, std::vector<int>& sides,
                std::vector<OriginIndex::Source>& source, std::vector<int>& order) {
  const int ng = static_cast<int>(spec.grids.size());
  order.resize(ng);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return spec.grids[a].per_side > spec.grids[b].per_side; });
  source.assign(ng, {-1, -1, 1});
  for (int i = 0; i < ng; ++i) {
    const int g = order[i], m = spec.grids[g].per_side;
    for (int j = i - 1; j >= 0 && source[g].from < 0; --j) {
      const int h = order[j], mh = spec.grids[h].per_side;
      if (mh % m == 0) source[g] = {-1, h, mh / m};
    }
    if (source[g].from < 0) source[g] = {static_cast<int>(sides.size()), -1, 1}, sides.push_back(m);
  }
  if (sides.empty()) sides.push_back(1); // no grids: one box, for Q alone
}

} // namespace

std::vector<SubboxGrid> nested_subbox_grids(long n_total, double box, const std::vector<int>& targets) {
  const std::vector<int> sides = nested_subbox_sides(n_total, targets);
  std::vector<SubboxGrid> out;
  for (int m : sides) out.push_back(SubboxGrid{m, box, double(n_total) / (double(m) * m)});
  return out;
}

OriginIndex::OriginIndex(const double* pos0, long n, const DisplacementSpec& spec) : n_(n) {
  if (spec.cutoffs.size() > 255) throw std::invalid_argument("OriginIndex: at most 255 cutoffs");
  ranks_ = static_cast<int>(spec.cutoffs.size()) + 1;
  plan_grids(spec, sides_, source_, order_);
  const size_t kn = sides_.size();
  counters_ = 0;
  for (int m : sides_) base_.push_back(counters_), counters_ += size_t(m) * m * ranks_;
  if (counters_ > UINT32_MAX) throw std::invalid_argument("OriginIndex: too many sub-boxes");
  const double box = spec.grids.empty() ? 1.0 : spec.grids[0].box;
  offset_.resize(static_cast<size_t>(n) * kn);
  for (size_t k = 0; k < kn; ++k) {
    const SubboxGrid g{sides_[k], box, 0.0};
    for (long i = 0; i < n; ++i)
      offset_[i * kn + k] = static_cast<std::uint32_t>(
          base_[k] + size_t(subbox_index(pos0[2 * i], pos0[2 * i + 1], g)) * ranks_);
  }
}

namespace {

// On x86-64 the arithmetic is compiled twice, for AVX2 and for the
// baseline, and the loader picks what the CPU has.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define DYNHET_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define DYNHET_CLONES
#endif

constexpr long kBlock = 256;

// What the arithmetic of a block needs, fixed for a pass.
struct BlockParams {
  double a2[4];         // first four cutoffs squared; +inf where unused
  const double* a_more; // cutoffs 5.. (not squared), n_more of them
  int n_more;
  double hist_lo, inv_w, top; // histogram: first edge, 1/width, last slot
  int stride;                 // slots per species
};

// A block's per-particle results, and its MSD sums.
struct Block {
  double d2[kBlock];
  std::int32_t rank[kBlock], bin[kBlock];
  double sum, sum_small;
  long n_small;
};

// Plain arithmetic on doubles, written so the compiler vectorises it:
// |dr|^2, rank = number of cutoffs with |dr| >= a (slow for cutoff c iff
// c >= rank), the histogram slot of dx, and the MSD sums.
DYNHET_CLONES void block_arithmetic(const double* p0, const double* pt, const std::uint8_t* species, long nb,
                                    const BlockParams& p, Block& out) {
  double rank_d[kBlock], slot[kBlock];
  const double a0 = p.a2[0], a1 = p.a2[1], a2 = p.a2[2], a3 = p.a2[3];
  const double lo = p.hist_lo, inv_w = p.inv_w, top = p.top;
  for (long b = 0; b < nb; ++b) {
    const double dx = pt[2 * b] - p0[2 * b], dy = pt[2 * b + 1] - p0[2 * b + 1];
    const double r2 = dx * dx + dy * dy;
    out.d2[b] = r2;
    rank_d[b] =
        (r2 >= a0 ? 1.0 : 0.0) + (r2 >= a1 ? 1.0 : 0.0) + (r2 >= a2 ? 1.0 : 0.0) + (r2 >= a3 ? 1.0 : 0.0);
    slot[b] = std::min(top, std::max(0.0, (dx - lo) * inv_w + 1.0)); // 0 and top: outside the bins
  }
  for (int c = 0; c < p.n_more; ++c) {
    const double a2c = p.a_more[c] * p.a_more[c];
    for (long b = 0; b < nb; ++b) rank_d[b] += out.d2[b] >= a2c ? 1.0 : 0.0;
  }
  for (long b = 0; b < nb; ++b) out.rank[b] = static_cast<std::int32_t>(rank_d[b]);
  for (long b = 0; b < nb; ++b) out.bin[b] = static_cast<std::int32_t>(slot[b]) + species[b] * p.stride;
  // MSD sums: two independent partial sums each, so the additions overlap.
  double s0 = 0, s1 = 0, t0 = 0, t1 = 0;
  long b = 0;
  for (; b + 1 < nb; b += 2) {
    const double w0 = species[b] == 0, w1 = species[b + 1] == 0;
    s0 += out.d2[b], s1 += out.d2[b + 1], t0 += w0 * out.d2[b], t1 += w1 * out.d2[b + 1];
  }
  if (b < nb) s0 += out.d2[b], t0 += (species[b] == 0) * out.d2[b];
  out.sum = s0 + s1, out.sum_small = t0 + t1;
  out.n_small = 0;
  for (b = 0; b < nb; ++b) out.n_small += species[b] == 0;
}

// The counts of a block: one counter per indexed grid and one histogram
// slot per particle. Done after the arithmetic, when every address is
// known; interleaved with it, the CPU waits on store addresses and the
// pass takes twice as long. K: indexed grids if known at compile time.
template <int K>
void block_counts(const Block& blk, long i0, long nb, const OriginIndex& o, std::uint32_t* counter,
                  long* hist) {
  const int kn = K > 0 ? K : o.indexed_grids();
  for (long b = 0; b < nb; ++b) {
    const std::uint32_t* off = o.offsets(i0 + b);
    for (int k = 0; k < kn; ++k) ++counter[off[k] + blk.rank[b]];
    ++hist[blk.bin[b]];
  }
}

// Slow particles per box of every grid, as [c * boxes + box]: an indexed
// grid from its counters (a particle of rank r is slow for the cutoffs
// c >= r), a summed grid from its finer source, factor x factor boxes
// into one.
std::vector<std::vector<long>> slow_counts(const std::vector<std::uint32_t>& counter, const OriginIndex& o,
                                           const DisplacementSpec& spec) {
  const int nc = o.ranks() - 1, ng = static_cast<int>(spec.grids.size());
  std::vector<std::vector<long>> slow(ng);
  for (int g : o.order()) {
    const int m = spec.grids[g].per_side, boxes = m * m;
    const OriginIndex::Source src = o.source(g);
    slow[g].assign(static_cast<size_t>(nc) * boxes, 0);
    if (src.indexed >= 0) {
      const std::uint32_t* k = counter.data() + o.base(src.indexed);
      for (int r = 0; r < boxes; ++r) {
        long running = 0;
        for (int c = 0; c < nc; ++c) running += k[r * (nc + 1) + c], slow[g][c * boxes + r] = running;
      }
      continue;
    }
    const int mh = spec.grids[src.from].per_side, f = src.factor;
    const std::vector<long>& fine = slow[src.from];
    for (int c = 0; c < nc; ++c)
      for (int by = 0; by < mh; ++by)
        for (int bx = 0; bx < mh; ++bx)
          slow[g][c * boxes + (by / f) * m + bx / f] += fine[(size_t(c) * mh + by) * mh + bx];
  }
  return slow;
}

} // namespace

void displacement_pass(const double* pos0, const double* pos_t, const std::uint8_t* species, long n,
                       const OriginIndex& origin, const DisplacementSpec& spec, DisplacementResult& out,
                       double* d2) {
  if (origin.size() != n) throw std::invalid_argument("displacement_pass: origin index of another size");
  const int nc = static_cast<int>(spec.cutoffs.size()), ng = static_cast<int>(spec.grids.size());
  std::vector<std::uint32_t> counter(origin.counters(), 0);
  const int stride = spec.hist_bins + 2;
  std::vector<long> hist(2 * static_cast<size_t>(stride), 0);
  BlockParams bp{{kInf, kInf, kInf, kInf},
                 nc > 4 ? spec.cutoffs.data() + 4 : nullptr,
                 std::max(0, nc - 4),
                 spec.hist_lo,
                 1.0 / spec.hist_width,
                 spec.hist_bins + 1.0,
                 stride};
  for (int c = 0; c < std::min(nc, 4); ++c) bp.a2[c] = spec.cutoffs[c] * spec.cutoffs[c];
  double sum = 0, sum_small = 0;
  long n_small = 0;
  Block blk;
  for (long i0 = 0; i0 < n; i0 += kBlock) {
    const long nb = std::min(kBlock, n - i0);
    block_arithmetic(pos0 + 2 * i0, pos_t + 2 * i0, species + i0, nb, bp, blk);
    sum += blk.sum, sum_small += blk.sum_small, n_small += blk.n_small;
    if (d2) std::copy(blk.d2, blk.d2 + nb, d2 + i0);
    const int k = origin.indexed_grids(); // unrolled for the usual numbers of indexed grids
    if (k == 1) block_counts<1>(blk, i0, nb, origin, counter.data(), hist.data());
    else if (k == 2) block_counts<2>(blk, i0, nb, origin, counter.data(), hist.data());
    else if (k == 3) block_counts<3>(blk, i0, nb, origin, counter.data(), hist.data());
    else block_counts<0>(blk, i0, nb, origin, counter.data(), hist.data());
  }

  // MSD, eq. (9): Delta(t) = (1/N_set) sum_i |dr_i|^2.
  out.n_small = n_small;
  out.msd_all = n > 0 ? sum / n : NAN;
  out.msd_small = out.n_small > 0 ? sum_small / out.n_small : NAN;

  // Histogram: drop the under/overflow slots into hist_out.
  out.hist_out = 0;
  for (int s = 0; s < 2; ++s) {
    const long* h = hist.data() + s * stride;
    out.hist[s].assign(h + 1, h + 1 + spec.hist_bins);
    out.hist_out += h[0] + h[stride - 1];
  }

  // Q per cutoff from all counters of the first indexed grid, eq. (6): Q = N_slow / N_tot.
  out.q.assign(nc, 0.0);
  for (size_t r = 0; r < size_t(origin.indexed_side(0)) * origin.indexed_side(0); ++r) {
    long running = 0;
    for (int c = 0; c < nc; ++c) running += counter[r * (nc + 1) + c], out.q[c] += running;
  }
  for (double& q : out.q) q /= n;

  // Q_r on every grid and the sub-box sums behind chi4.
  const std::vector<std::vector<long>> slow = slow_counts(counter, origin, spec);
  const size_t ngc = static_cast<size_t>(ng) * nc;
  out.q_r.resize(ngc), out.q_r_sum.assign(ngc, 0.0), out.q_r_sum2.assign(ngc, 0.0), out.chi4.assign(ngc, 0.0);
  for (int g = 0; g < ng; ++g) {
    const SubboxGrid& grid = spec.grids[g];
    const int boxes = grid.per_side * grid.per_side;
    for (int c = 0; c < nc; ++c) {
      const size_t gc = static_cast<size_t>(g) * nc + c;
      std::vector<double>& q_r = out.q_r[gc];
      q_r.resize(boxes);
      double s1 = 0, s2 = 0;
      for (int r = 0; r < boxes; ++r) {
        // Q_r = (1/N) sum_i theta(a - |dr_i|), eq. (5)
        q_r[r] = slow[g][size_t(c) * boxes + r] / grid.mean_particles;
        s1 += q_r[r], s2 += q_r[r] * q_r[r];
      }
      const double mean = s1 / boxes;
      out.q_r_sum[gc] = s1, out.q_r_sum2[gc] = s2;
      out.chi4[gc] = grid.mean_particles * (s2 / boxes - mean * mean); // N[<Q_r^2> - <Q_r>^2], eq. (14)
    }
  }
}

namespace {

// The exact selection of msd_extremes, by std::nth_element on a copy of the
// set: the slowest k in v[0, k); the fastest k are then the top of v[k, m)
// (the whole of v if the subsets overlap), so the second selection skips
// v[0, k). The small sets' path and the fallback of the sampled one.
ExtremeMsd extremes_by_nth_element(const double* d2, const std::uint8_t* species, long n, double fraction,
                                   int which, std::vector<double>& v) {
  v.clear();
  if (which < 0) v.assign(d2, d2 + n);
  else
    for (long i = 0; i < n; ++i)
      if (species[i] == which) v.push_back(d2[i]);
  const long m = static_cast<long>(v.size());
  if (m == 0) return {NAN, NAN, 0};
  const long k = std::min(m, std::max(1L, std::lround(fraction * m)));
  std::nth_element(v.begin(), v.begin() + (k - 1), v.end());
  const double slow = std::accumulate(v.begin(), v.begin() + k, 0.0) / k;
  const auto from = 2 * k <= m ? v.begin() + k : v.begin();
  std::nth_element(from, v.begin() + (m - k), v.end());
  const double fast = std::accumulate(v.begin() + (m - k), v.end(), 0.0) / k;
  return {fast, slow, k, 0};
}

// The sampled selection. Up to two sets (s = 0, 1), each with two "sides"
// (0: the slowest k, 1: the fastest k): band j = 2 s + side is the value
// range [lo, hi] that should hold the set's k-th smallest (side 0) or k-th
// largest (side 1) |dr|^2. One pass sums what lies surely inside a subset
// (side 0: below lo; side 1: above hi) and copies the band's values out;
// nth_element then runs on the bands alone.
constexpr long kSelectBlock = 256;
constexpr long kSampledFrom = 4096; // smaller sets: nth_element on the set

// Four lanes, as GCC/Clang vector extensions: AVX2 registers in the avx2
// clone, pairs of SSE2 registers in the default one. Comparisons give
// masks of all ones (-1) or zeros per lane.
typedef double V4d __attribute__((vector_size(32)));
typedef long long V4l __attribute__((vector_size(32)));
typedef std::uint8_t V4b __attribute__((vector_size(4)));

struct ExtremeCuts {
  double lo[4], hi[4];
  double every[2], which[2]; // set s: all particles (every = 1) or species which
};

// Per band j: the sum and count of what lies surely inside its subset;
// per set: its size. Lanes are summed at the end.
struct ExtremeSums {
  V4d sum[4];
  V4l count[4], members[2];
};

// One group of four particles (lanes beyond `valid` are no set's members):
// the sure sums and counts, the set sizes, and the flag word of each
// particle (bit j: in band j).
inline void extreme_group(const double* x, const std::uint8_t* sp, const V4l& valid, const ExtremeCuts& c,
                          ExtremeSums& s, std::int64_t* flag) {
  V4d y;
  V4b t;
  std::memcpy(&y, x, sizeof y);
  std::memcpy(&t, sp, sizeof t);
  const V4d spd = __builtin_convertvector(t, V4d);
  V4l word = V4l{} ;
  for (int set = 0; set < 2; ++set) {
    const V4l in = ((c.every[set] > 0 ? V4l{} - 1 : V4l{}) | (spd == c.which[set])) & valid;
    const int j = 2 * set;
    const V4l below = (y < c.lo[j]) & in, above = (y > c.hi[j + 1]) & in;
    s.members[set] -= in;
    s.sum[j] += (V4d)((V4l)y & below), s.count[j] -= below;
    s.sum[j + 1] += (V4d)((V4l)y & above), s.count[j + 1] -= above;
    word |= (y >= c.lo[j]) & (y <= c.hi[j]) & in & (1LL << j);
    word |= (y >= c.lo[j + 1]) & (y <= c.hi[j + 1]) & in & (2LL << j);
  }
  std::memcpy(flag, &word, sizeof word);
}

DYNHET_CLONES void extreme_block(const double* x, const std::uint8_t* sp, long nb, const ExtremeCuts& c,
                                 ExtremeSums& s, std::int64_t* flag) {
  long b = 0;
  for (; b + 4 <= nb; b += 4) extreme_group(x + b, sp + b, V4l{} - 1, c, s, flag + b);
  if (b < nb) { // the tail, padded
    double xt[4] = {0, 0, 0, 0};
    std::uint8_t st[4] = {0, 0, 0, 0};
    std::int64_t ft[4];
    std::copy(x + b, x + nb, xt), std::copy(sp + b, sp + nb, st);
    const long r = nb - b;
    extreme_group(xt, st, V4l{0, 1, 2, 3} < r, c, s, ft);
    std::copy(ft, ft + r, flag + b);
  }
}

// Values at the given ascending ranks of y[0, m), by nth_element from the
// middle rank outwards.
void select_ranks(double* y, long m, const long* rank, int nr, double* out, long offset = 0) {
  if (nr == 0) return;
  const int mid = nr / 2;
  const long r = rank[mid] - offset;
  std::nth_element(y, y + r, y + m);
  out[mid] = y[r];
  select_ranks(y, r, rank, mid, out, offset);
  select_ranks(y + r + 1, m - r - 1, rank + mid + 1, nr - mid - 1, out + mid + 1, offset + r + 1);
}

void sampled_extremes(const double* d2, const std::uint8_t* species, long n, const double* fraction,
                      const int* which, int n_sets, std::vector<double>& v, ExtremeMsd* out) {
  // A sample of about 8 sqrt(n) values at a fixed stride; each set's
  // members among them.
  const long samples = std::clamp(static_cast<long>(8 * std::sqrt(double(n))), 256L, 8192L);
  v.resize(2 * static_cast<size_t>(samples));
  double* sample[2] = {v.data(), v.data() + samples};
  long ns[2] = {0, 0};
  for (long j = 0; j < samples; ++j) {
    const long i = static_cast<long>((2 * j + 1) * static_cast<double>(n) / (2 * samples));
    for (int s = 0; s < n_sets; ++s)
      if (which[s] < 0 || species[i] == which[s]) sample[s][ns[s]++] = d2[i];
  }
  // The bands: the sample ranks of each subset's bound, widened by z = 3.5
  // standard deviations of a sample rank (the binomial sqrt(s q (1 - q)))
  // and one rank; a bound beyond the sample is infinite.
  constexpr double kZ = 3.5;
  ExtremeCuts cut{};
  long cap[4] = {0, 0, 0, 0};
  for (int s = 0; s < 2; ++s) {
    cut.every[s] = s < n_sets && which[s] < 0 ? 1.0 : 0.0;
    cut.which[s] = s < n_sets && which[s] >= 0 ? which[s] : -1.0; // -1: no species
    cut.lo[2 * s] = cut.lo[2 * s + 1] = kInf, cut.hi[2 * s] = cut.hi[2 * s + 1] = -kInf; // empty bands
    if (s >= n_sets || ns[s] == 0) continue; // no members sampled: no band, the fallback decides
    const double m_est = double(n) * ns[s] / samples, q = std::clamp(fraction[s], 0.0, 1.0);
    long rank[4];
    for (int side = 0; side < 2; ++side) {
      const double p = side ? 1 - q : q, r = p * ns[s] - 0.5, sd = std::sqrt(ns[s] * p * (1 - p));
      rank[2 * side] = static_cast<long>(std::floor(r - kZ * sd - 1));
      rank[2 * side + 1] = static_cast<long>(std::ceil(r + kZ * sd + 1));
      const double width = double(rank[2 * side + 1] - rank[2 * side] + 1) / ns[s];
      cap[2 * s + side] = static_cast<long>(2 * width * m_est) + 4 * kSelectBlock;
    }
    long inside[4];
    int ni = 0;
    for (long r : rank)
      if (r >= 0 && r < ns[s]) inside[ni++] = r;
    for (int a = 1; a < ni; ++a) // insertion sort (std::sort on 4 trips GCC 12's -Warray-bounds)
      for (int b = a; b > 0 && inside[b - 1] > inside[b]; --b) std::swap(inside[b - 1], inside[b]);
    ni = static_cast<int>(std::unique(inside, inside + ni) - inside);
    double at[4];
    select_ranks(sample[s], ns[s], inside, ni, at);
    auto value = [&](long r) {
      if (r < 0) return -kInf;
      if (r >= ns[s]) return kInf;
      return at[std::lower_bound(inside, inside + ni, r) - inside];
    };
    for (int side = 0; side < 2; ++side)
      cut.lo[2 * s + side] = value(rank[2 * side]), cut.hi[2 * s + side] = value(rank[2 * side + 1]);
  }
  // The pass: sure sums, and the bands copied out (branch-free: every value
  // is stored, the count grows only for band members, so each band has one
  // slot more than it may fill), as long as they fit.
  std::size_t start[4], total = 0;
  for (int j = 0; j < 4; ++j) start[j] = total, total += cap[j] + 1;
  v.resize(total);
  long count[4] = {0, 0, 0, 0};
  bool overflow[4] = {false, false, false, false};
  std::int32_t mask = 0;
  for (int j = 0; j < 4; ++j) mask |= cap[j] > 0 ? 1 << j : 0;
  ExtremeSums sums{};
  std::int64_t flag[kSelectBlock];
  for (long i0 = 0; i0 < n; i0 += kSelectBlock) {
    const long nb = std::min(kSelectBlock, n - i0);
    extreme_block(d2 + i0, species + i0, nb, cut, sums, flag);
    for (int j = 0; j < 4; ++j)
      if ((mask >> j & 1) && count[j] + nb > cap[j]) mask &= ~(1 << j), overflow[j] = true;
    if (!mask) continue;
    double* band[4];
    for (int j = 0; j < 4; ++j) band[j] = v.data() + start[j];
    long c0 = count[0], c1 = count[1], c2 = count[2], c3 = count[3];
    for (long b = 0; b < nb; ++b) {
      const double x = d2[i0 + b];
      const std::int64_t f = flag[b] & mask;
      band[0][c0] = x, c0 += f & 1;
      band[1][c1] = x, c1 += f >> 1 & 1;
      band[2][c2] = x, c2 += f >> 2 & 1;
      band[3][c3] = x, c3 += f >> 3 & 1;
    }
    count[0] = c0, count[1] = c1, count[2] = c2, count[3] = c3;
  }
  // Each side: exact if its k-th value is in the band (the counts say so),
  // else the whole set again with nth_element.
  for (int s = 0; s < n_sets; ++s) {
    auto lanes = [](const auto& a) { return (a[0] + a[1]) + (a[2] + a[3]); };
    const long m = lanes(sums.members[s]);
    if (m == 0) {
      out[s] = {NAN, NAN, 0, 0};
      continue;
    }
    const long k = std::min(m, std::max(1L, std::lround(fraction[s] * m)));
    double mean[2] = {NAN, NAN};
    bool ok = true;
    for (int side = 0; side < 2 && ok; ++side) {
      const int j = 2 * s + side;
      const long sure = lanes(sums.count[j]), need = k - sure;
      ok = !overflow[j] && cap[j] > 0 && need > 0 && need <= count[j];
      if (!ok) break;
      double* b = v.data() + start[j];
      double* e = b + count[j];
      // Side 0: the smallest `need` of the band; side 1: its largest.
      double* first = side ? e - need : b;
      std::nth_element(b, side ? first : b + (need - 1), e);
      mean[side] = (lanes(sums.sum[j]) + std::accumulate(first, first + need, 0.0)) / k;
    }
    out[s] = ok ? ExtremeMsd{mean[1], mean[0], k, 0} : ExtremeMsd{NAN, NAN, -1, 0}; // -1: to redo
  }
  for (int s = 0; s < n_sets; ++s)
    if (out[s].count < 0) {
      out[s] = extremes_by_nth_element(d2, species, n, fraction[s], which[s], v);
      out[s].full_selections = 1;
    }
}

} // namespace

ExtremeMsd msd_extremes(const double* d2, const std::uint8_t* species, long n, double fraction,
                        int which_species, std::vector<double>& v) {
  if (n < kSampledFrom) return extremes_by_nth_element(d2, species, n, fraction, which_species, v);
  ExtremeMsd out;
  sampled_extremes(d2, species, n, &fraction, &which_species, 1, v, &out);
  return out;
}

ExtremeMsd msd_extremes(const double* d2, const std::uint8_t* species, long n, double fraction,
                        int which_species) {
  std::vector<double> buffer;
  return msd_extremes(d2, species, n, fraction, which_species, buffer);
}

ExtremeMsdAllSmall msd_extremes_all_small(const double* d2, const std::uint8_t* species, long n,
                                          double fraction_all, double fraction_small,
                                          std::vector<double>& buffer) {
  if (n < kSampledFrom)
    return {extremes_by_nth_element(d2, species, n, fraction_all, -1, buffer),
            extremes_by_nth_element(d2, species, n, fraction_small, 0, buffer)};
  const double fraction[2] = {fraction_all, fraction_small};
  const int which[2] = {-1, 0};
  ExtremeMsd out[2];
  sampled_extremes(d2, species, n, fraction, which, 2, buffer, out);
  return {out[0], out[1]};
}

void overlap_weights(const double* d2, long n, double a, std::vector<double>& weight) {
  weight.resize(n);
  const double a2 = a * a;
  for (long i = 0; i < n; ++i) weight[i] = d2[i] < a2 ? 1.0 : 0.0; // theta(a - |dr_i|)
}

DisplacementDensity displacement_density(const DisplacementSpec& s, const std::vector<long>& counts,
                                         long n_total) {
  DisplacementDensity d;
  d.count = counts;
  for (size_t b = 0; b < counts.size(); ++b) {
    d.x.push_back(s.hist_lo + (b + 0.5) * s.hist_width);
    d.p.push_back(counts[b] / (double(n_total) * s.hist_width));
  }
  return d;
}

void wave_vectors(int n_max, std::vector<int>& nx, std::vector<int>& ny) {
  nx.clear(), ny.clear();
  for (int b = 0; b <= n_max; ++b)
    for (int a = -n_max; a <= n_max; ++a)
      if ((b > 0 || a > 0) && a * a + b * b <= n_max * n_max) nx.push_back(a), ny.push_back(b);
}

WaveModes collective_modes(const double* pos0, const double* pos_t, long n, double box, int n_max, double msd) {
  WaveModes w;
  wave_vectors(n_max, w.nx, w.ny);
  const size_t m = w.nx.size();
  // The displacements summed on a kGrid x kGrid grid by the cell holding
  // r_i(t0) (3 ns a particle), then the Fourier sums over the cells,
  // separable: rows first (a = -n_max..n_max), then columns (b = 0..n_max).
  constexpr int kGrid = 64; // cells of L/64: at |n| <= 4 the window is 0.99 or more
  static_assert((kGrid & (kGrid - 1)) == 0, "a power of 2: the cell index wraps by a mask");
  std::vector<double> gx(kGrid * kGrid, 0.0), gy(kGrid * kGrid, 0.0);
  const double inv_h = kGrid / box;
  for (long i = 0; i < n; ++i) {
    const double x = pos0[2 * i], y = pos0[2 * i + 1];
    const long ix = static_cast<long>(std::floor(x * inv_h)) & (kGrid - 1);
    const long iy = static_cast<long>(std::floor(y * inv_h)) & (kGrid - 1);
    gx[iy * kGrid + ix] += pos_t[2 * i] - x, gy[iy * kGrid + ix] += pos_t[2 * i + 1] - y;
  }
  const double pi = 3.14159265358979323846;
  // exp(-i 2 pi a (c + 1/2) / kGrid) for a = 0..n_max: the cell centres' phases
  std::vector<double> cs((n_max + 1) * kGrid), sn(cs.size());
  for (int a = 0; a <= n_max; ++a)
    for (int c = 0; c < kGrid; ++c) {
      const double ph = 2 * pi * a * (c + 0.5) / kGrid;
      cs[a * kGrid + c] = std::cos(ph), sn[a * kGrid + c] = -std::sin(ph);
    }
  // Rows: F(a, iy) for both components, a = -n_max..n_max (index a + n_max).
  const int na = 2 * n_max + 1;
  std::vector<double> fxr(na * kGrid), fxi(fxr.size()), fyr(fxr.size()), fyi(fxr.size());
  for (int iy = 0; iy < kGrid; ++iy)
    for (int a = 0; a <= n_max; ++a) {
      double xr = 0, xi = 0, yr = 0, yi = 0;
      for (int ix = 0; ix < kGrid; ++ix) {
        const double c = cs[a * kGrid + ix], s = sn[a * kGrid + ix];
        const double vx = gx[iy * kGrid + ix], vy = gy[iy * kGrid + ix];
        xr += vx * c, xi += vx * s, yr += vy * c, yi += vy * s;
      }
      // the real data's transform at -a is the conjugate
      fxr[(n_max + a) * kGrid + iy] = xr, fxi[(n_max + a) * kGrid + iy] = xi;
      fyr[(n_max + a) * kGrid + iy] = yr, fyi[(n_max + a) * kGrid + iy] = yi;
      fxr[(n_max - a) * kGrid + iy] = xr, fxi[(n_max - a) * kGrid + iy] = -xi;
      fyr[(n_max - a) * kGrid + iy] = yr, fyi[(n_max - a) * kGrid + iy] = -yi;
    }
  w.transverse.resize(m), w.longitudinal.resize(m);
  for (size_t k = 0; k < m; ++k) {
    const int a = w.nx[k], b = w.ny[k];
    double xr = 0, xi = 0, yr = 0, yi = 0; // u_k times n, components x and y
    for (int iy = 0; iy < kGrid; ++iy) {
      const double c = cs[b * kGrid + iy], s = sn[b * kGrid + iy];
      const size_t j = static_cast<size_t>(n_max + a) * kGrid + iy;
      xr += fxr[j] * c - fxi[j] * s, xi += fxr[j] * s + fxi[j] * c;
      yr += fyr[j] * c - fyi[j] * s, yi += fyr[j] * s + fyi[j] * c;
    }
    // Positions spread uniformly over a cell put the cell-centre sum at
    // W = sinc(pi a / kGrid) sinc(pi b / kGrid) of the exact one, on
    // average: divided out, the floor MSD / N divided likewise.
    auto sinc = [&](int q) { return q == 0 ? 1.0 : std::sin(pi * q / kGrid) / (pi * q / kGrid); };
    const double win = sinc(a) * sinc(b), scale = 1.0 / (double(n) * win);
    const double kn = std::hypot(double(a), double(b)), ex = a / kn, ey = b / kn; // k-hat; transverse (-ey, ex)
    const double lr = (xr * ex + yr * ey) * scale, li = (xi * ex + yi * ey) * scale;
    const double tr = (-xr * ey + yr * ex) * scale, ti = (-xi * ey + yi * ex) * scale;
    const double floor = msd / double(n) / (win * win);
    w.longitudinal[k] = 2 * (lr * lr + li * li) - floor;
    w.transverse[k] = 2 * (tr * tr + ti * ti) - floor;
    w.t_re.push_back(tr), w.t_im.push_back(ti), w.l_re.push_back(lr), w.l_im.push_back(li);
  }
  return w;
}

} // namespace dynhet::analysis
