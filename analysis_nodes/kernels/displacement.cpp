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
