// The slowest and fastest fractions of a set of squared displacements
// (msd_extremes, displacement.hpp): exact by nth_element on small sets,
// by a sampled band and one pass over the set on large ones.
#include "dynhet/analysis/displacement.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace dynhet::analysis {

// On x86-64 the arithmetic is compiled twice, for AVX2 and for the
// baseline, and the loader picks what the CPU has.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define DYNHET_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define DYNHET_CLONES
#endif

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

} // namespace

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

} // namespace dynhet::analysis
