#include "dynhet/analysis/clusters.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

namespace dynhet::analysis {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = 3.14159265358979323846;

double fold(double x, double box) { return x - box * std::floor(x / box); }
double min_image(double d, double box) { return d - box * std::floor(d / box + 0.5); }

} // namespace

// Particles sorted into square cells of side >= rc, with their folded
// positions stored cell by cell so that a cell's particles sit together.
struct CellList {
  int m;                           // cells per side
  std::vector<std::int32_t> start; // first entry of each cell, m*m + 1 values
  std::vector<std::int32_t> id;    // particle index of each entry
  std::vector<double> x, y;        // folded position of each entry
  std::vector<std::int32_t> cell;  // scratch: cell of each particle
  std::vector<std::uint8_t> sp;    // species of each entry

  void build(const double* pos, long n, double box, double rc) {
    m = std::max(1, static_cast<int>(box / rc));
    const double to_cell = m / box;
    cell.resize(n);
    start.assign(static_cast<size_t>(m) * m + 1, 0);
    for (long i = 0; i < n; ++i) {
      const double fx = fold(pos[2 * i], box), fy = fold(pos[2 * i + 1], box);
      const int cx = std::min(m - 1, static_cast<int>(fx * to_cell));
      const int cy = std::min(m - 1, static_cast<int>(fy * to_cell));
      cell[i] = cy * m + cx;
      ++start[cell[i] + 1];
    }
    for (size_t k = 1; k < start.size(); ++k) start[k] += start[k - 1];
    id.resize(n), x.resize(n), y.resize(n);
    for (long i = 0; i < n; ++i) {
      const int e = start[cell[i]]++; // start[c] walks to the end of cell c ...
      id[e] = static_cast<std::int32_t>(i), x[e] = fold(pos[2 * i], box), y[e] = fold(pos[2 * i + 1], box);
    }
    for (size_t k = start.size() - 1; k > 0; --k) start[k] = start[k - 1]; // ... so shift it back
    start[0] = 0;
  }
};

namespace {

// Calls f(p, q, dx, dy, r2) once for every pair of cell-list entries closer
// than rc, with (dx, dy) = r_q - r_p the minimum image. Cells are stored row
// by row, so the neighbours of a cell in its own row (itself and the next
// cell) and in the next row (three cells) are two runs of entries; a run
// across the box edge is seen through its periodic image, shifted by
// +-box, so no pair needs a minimum-image rounding. With fewer than 3
// cells per side every pair is tried instead.
template <class F> void for_each_pair(const CellList& c, double box, double rc, F&& f) {
  const double rc2 = rc * rc;
  const long n = static_cast<long>(c.x.size());
  if (c.m < 3) {
    for (long p = 0; p < n; ++p)
      for (long q = p + 1; q < n; ++q) {
        const double dx = min_image(c.x[q] - c.x[p], box), dy = min_image(c.y[q] - c.y[p], box);
        if (dx * dx + dy * dy < rc2) f(p, q, dx, dy, dx * dx + dy * dy);
      }
    return;
  }
  // Entries [q0, q1) against particle p seen shifted by (sx, sy).
  auto run = [&](long p, int q0, int q1, double sx, double sy) {
    const double px = c.x[p] - sx, py = c.y[p] - sy;
    for (int q = q0; q < q1; ++q) {
      const double dx = c.x[q] - px, dy = c.y[q] - py, r2 = dx * dx + dy * dy;
      if (r2 < rc2) f(p, q, dx, dy, r2);
    }
  };
  const int m = c.m;
  auto first = [&](int cx, int cy) { return c.start[cy * m + cx]; };
  auto last = [&](int cx, int cy) { return c.start[cy * m + cx + 1]; };
  for (int cy = 0; cy < m; ++cy) {
    const int ny = (cy + 1) % m;
    const double sy = cy + 1 == m ? box : 0.0; // the next row, through the image above
    for (int cx = 0; cx < m; ++cx)
      for (int p = first(cx, cy); p < last(cx, cy); ++p) {
        // Own row: the rest of this cell and the cell to the right.
        if (cx + 1 < m)
          run(p, p + 1, last(cx + 1, cy), 0, 0);
        else
          run(p, p + 1, last(cx, cy), 0, 0), run(p, first(0, cy), last(0, cy), box, 0);
        // Next row: cells cx-1 .. cx+1.
        const int lo = std::max(cx - 1, 0), hi = std::min(cx + 1, m - 1);
        run(p, first(lo, ny), last(hi, ny), 0, sy);
        if (cx == 0) run(p, first(m - 1, ny), last(m - 1, ny), -box, sy);
        if (cx == m - 1) run(p, first(0, ny), last(0, ny), box, sy);
      }
  }
}

// Gaussian smoothing of g over bins of width dr, renormalised at the ends.
std::vector<double> smooth_bins(const std::vector<double>& g, double dr, double width) {
  if (width <= 0) return g;
  const int half = static_cast<int>(std::ceil(3 * width / dr));
  const int nb = static_cast<int>(g.size());
  std::vector<double> s(nb, 0.0);
  for (int k = 0; k < nb; ++k) {
    double sw = 0;
    for (int l = std::max(0, k - half); l <= std::min(nb - 1, k + half); ++l) {
      const double w = std::exp(-0.5 * std::pow((l - k) * dr / width, 2));
      s[k] += w * g[l], sw += w;
    }
    s[k] /= sw;
  }
  return s;
}

} // namespace

PairDistribution pair_distribution(const double* pos, const std::uint8_t* species, long n, double box,
                                   double r_max, double dr) {
  if (r_max > box / 2) throw std::invalid_argument("pair_distribution: r_max > box/2");
  PairDistribution out;
  out.dr = dr;
  const int nb = static_cast<int>(r_max / dr);
  for (int k = 0; k < nb; ++k) out.r.push_back((k + 0.5) * dr);
  std::array<std::vector<double>, 3> count;
  for (auto& v : count) v.assign(nb, 0.0);
  CellList cells;
  cells.build(pos, n, box, r_max);
  std::vector<std::uint8_t> sp(n); // species in cell order
  for (long e = 0; e < n; ++e) sp[e] = species[cells.id[e]];
  for_each_pair(cells, box, nb * dr, [&](long p, long q, double, double, double r2) {
    const int k = std::min(nb - 1, static_cast<int>(std::sqrt(r2) / dr));
    ++count[species_pair(sp[p], sp[q])][k];
  });
  long na[2] = {0, 0};
  for (long i = 0; i < n; ++i) ++na[species[i]];
  // Ideal-gas pairs per bin: n_a n_b shell / box^2 (a != b), n_a (n_a - 1)/2 shell / box^2 (a == b).
  const double pairs_ideal[3] = {0.5 * na[0] * (na[0] - 1.0), double(na[0]) * na[1],
                                 0.5 * na[1] * (na[1] - 1.0)};
  for (int p = 0; p < 3; ++p) {
    out.g[p].assign(nb, 0.0);
    for (int k = 0; k < nb; ++k) {
      const double shell = kPi * dr * dr * ((k + 1.0) * (k + 1.0) - double(k) * k);
      const double ideal = pairs_ideal[p] * shell / (box * box);
      out.g[p][k] = ideal > 0 ? count[p][k] / ideal : kNaN;
    }
  }
  return out;
}

double first_minimum(const std::vector<double>& r, const std::vector<double>& g, double smooth) {
  if (r.size() < 3) return kNaN;
  const double dr = r[1] - r[0];
  const std::vector<double> s = smooth_bins(g, dr, smooth);
  const int nb = static_cast<int>(s.size());
  int k = 1;
  while (k < nb - 1 && !(s[k] > 1 && s[k] >= s[k - 1] && s[k] >= s[k + 1])) ++k; // first peak
  while (k < nb - 1 && !(s[k] <= s[k - 1] && s[k] < s[k + 1])) ++k;              // then first minimum
  if (k >= nb - 1) return kNaN;
  // Vertex of the parabola through the three bins around the minimum.
  const double den = s[k - 1] - 2 * s[k] + s[k + 1];
  const double shift = den > 0 ? 0.5 * (s[k - 1] - s[k + 1]) / den : 0.0;
  return r[k] + shift * dr;
}

NeighbourCutoffs neighbour_cutoffs(const PairDistribution& g, double smooth) {
  NeighbourCutoffs c;
  for (int p = 0; p < 3; ++p) c.r[p] = first_minimum(g.r, g.g[p], smooth); // r^min_ab
  return c;
}

NeighbourFinder::NeighbourFinder(const NeighbourCutoffs& cut)
    : cut_(cut), cells_(std::make_unique<CellList>()) {}
NeighbourFinder::~NeighbourFinder() = default;

const NeighbourPairs& NeighbourFinder::find(const double* pos, const std::uint8_t* species, long n,
                                            double box) {
  std::array<double, 3> c2;
  for (int p = 0; p < 3; ++p) c2[p] = cut_.r[p] * cut_.r[p];
  CellList& cells = *cells_;
  cells.build(pos, n, box, cut_.max());
  cells.sp.resize(n);
  for (long e = 0; e < n; ++e) cells.sp[e] = species[cells.id[e]];
  out_.n = n;
  out_.pairs.clear(), out_.bond.clear();
  for_each_pair(cells, box, cut_.max(), [&](long p, long q, double dx, double dy, double r2) {
    if (r2 >= c2[species_pair(cells.sp[p], cells.sp[q])]) return;
    const std::int32_t i = cells.id[p], j = cells.id[q];
    if (i < j)
      out_.pairs.push_back({i, j}), out_.bond.push_back({dx, dy});
    else
      out_.pairs.push_back({j, i}), out_.bond.push_back({-dx, -dy});
  });
  return out_;
}

NeighbourPairs neighbour_pairs(const double* pos, const std::uint8_t* species, long n, double box,
                               const NeighbourCutoffs& cut) {
  NeighbourFinder f(cut);
  return f.find(pos, species, n, box);
}

std::vector<std::uint8_t> slow_particles(const double* d2, long n, double a) {
  std::vector<std::uint8_t> s(n);
  for (long i = 0; i < n; ++i) s[i] = d2[i] < a * a; // |dr| < a
  return s;
}

std::vector<std::uint8_t> fast_particles(const double* d2, long n, double a) {
  std::vector<std::uint8_t> s(n);
  for (long i = 0; i < n; ++i) s[i] = d2[i] > 9 * a * a; // |dr| > 3a
  return s;
}

void NeighbourGraph::build(const NeighbourPairs& nb) {
  start.assign(nb.n + 1, 0);
  for (const auto& p : nb.pairs) ++start[p[0] + 1], ++start[p[1] + 1];
  for (long i = 0; i < nb.n; ++i) start[i + 1] += start[i];
  to.resize(start[nb.n]);
  std::vector<std::int32_t> fill(start.begin(), start.end() - 1);
  for (const auto& p : nb.pairs) to[fill[p[0]]++] = p[1], to[fill[p[1]]++] = p[0];
}

ClusterFinder::ClusterFinder() = default;
ClusterFinder::~ClusterFinder() = default;

const ClusterSet& ClusterFinder::find(const NeighbourPairs& nb, const double* pos, double box,
                                      const std::uint8_t* selected) {
  graph_.build(nb);
  return find(graph_, pos, pos, box, selected);
}

const ClusterSet& ClusterFinder::find(const NeighbourGraph& g, const double* p0, const double* pt, double box,
                                      const std::uint8_t* selected) {
  const long n = g.n();
  out_.label.assign(n, -1);
  out_.clusters.clear();
  u_.resize(n);
  for (long root = 0; root < n; ++root) {
    if (!selected[root] || out_.label[root] >= 0) continue;
    const auto id = static_cast<std::int32_t>(out_.clusters.size());
    // Breadth-first over the cluster: each new particle sits at its parent's
    // unwrapped t0 position plus the minimum-image bond at t0.
    queue_.assign(1, static_cast<std::int32_t>(root));
    out_.label[root] = id, u_[root] = {0.0, 0.0};
    bool spans = false;
    double sx = 0, sy = 0, sxx = 0; // of the positions at t, relative to the root's at t0
    for (size_t h = 0; h < queue_.size(); ++h) {
      const std::int32_t a = queue_[h];
      const double ax = u_[a][0], ay = u_[a][1];
      const double x = ax + pt[2 * a] - p0[2 * a], y = ay + pt[2 * a + 1] - p0[2 * a + 1];
      sx += x, sy += y, sxx += x * x + y * y;
      for (int k = g.start[a]; k < g.start[a + 1]; ++k) {
        const std::int32_t b = g.to[k];
        if (!selected[b]) continue;
        const double bx = ax + min_image(p0[2 * b] - p0[2 * a], box);
        const double by = ay + min_image(p0[2 * b + 1] - p0[2 * a + 1], box);
        if (out_.label[b] < 0) {
          out_.label[b] = id, u_[b] = {bx, by};
          queue_.push_back(b);
        } else if (std::abs(u_[b][0] - bx) > box / 2 || std::abs(u_[b][1] - by) > box / 2) {
          spans = true; // the bond closes a loop around the periodic box
        }
      }
    }
    const double nc = double(queue_.size()), mx = sx / nc, my = sy / nc;
    Cluster c{static_cast<long>(queue_.size()), kNaN, kNaN, kNaN, spans};
    if (!spans) {
      c.radius_of_gyration = std::sqrt(std::max(0.0, sxx / nc - mx * mx - my * my)); // eq. (10)
      c.cx = fold(p0[2 * root] + mx, box), c.cy = fold(p0[2 * root + 1] + my, box);
    }
    out_.clusters.push_back(c);
  }
  return out_;
}

ClusterSet find_clusters(const NeighbourPairs& nb, const double* pos, double box,
                         const std::uint8_t* selected) {
  ClusterFinder f;
  return f.find(nb, pos, box, selected);
}

std::vector<long> cluster_sizes(const ClusterSet& c) {
  std::vector<long> s;
  for (const Cluster& k : c.clusters) s.push_back(k.size);
  return s;
}

std::vector<long> log_bin_edges(long max_size, int per_decade) {
  std::vector<long> e;
  long last = 1;
  e.push_back(last);
  for (int k = 1; last <= max_size; ++k) {
    const long v = std::lround(std::pow(10.0, double(k) / per_decade));
    if (v > last) e.push_back(v), last = v;
  }
  return e;
}

namespace {

// The bin of size s: edges[b] <= s < edges[b + 1].
size_t bin_of(const std::vector<long>& e, long s) {
  return std::upper_bound(e.begin(), e.end(), s) - e.begin() - 1;
}

// P(N_c) from counts on integer log bins, over the first n_bins bins.
SizeHistogram size_histogram(const std::vector<long>& e, const std::vector<long>& count, size_t n_bins) {
  SizeHistogram h;
  h.count.assign(count.begin(), count.begin() + n_bins);
  for (long c : h.count) h.total += c;
  if (h.total == 0) return SizeHistogram{};
  for (size_t b = 0; b < n_bins; ++b) {
    h.lo.push_back(e[b]), h.hi.push_back(e[b + 1] - 1);
    h.centre.push_back(std::sqrt(double(e[b]) * (e[b + 1] - 1)));
    h.p.push_back(h.count[b] / (double(h.total) * (e[b + 1] - e[b]))); // P(N_c): fraction per size
  }
  return h;
}

} // namespace

SizeHistogram cluster_size_distribution(const std::vector<long>& sizes, int bins_per_decade) {
  if (sizes.empty()) return {};
  const std::vector<long> e = log_bin_edges(*std::max_element(sizes.begin(), sizes.end()), bins_per_decade);
  std::vector<long> count(e.size() - 1, 0);
  for (long s : sizes) ++count[bin_of(e, s)];
  return size_histogram(e, count, count.size());
}

ClusterTally::ClusterTally(long max_size, int bins_per_decade, long rg_min)
    : edges(log_bin_edges(max_size, bins_per_decade)), rg_min_size(rg_min), count(edges.size() - 1, 0),
      rg_count(count), sum_ln_n(count.size(), 0.0), sum_ln_rg(count.size(), 0.0) {}

void ClusterTally::add(const ClusterSet& c) {
  ++sets;
  for (const Cluster& k : c.clusters) {
    const size_t b = bin_of(edges, k.size);
    ++count.at(b), ++clusters, particles += k.size, spanning += k.spans;
    largest = std::max(largest, k.size);
    if (k.spans || k.size < rg_min_size || !(k.radius_of_gyration > 0)) continue;
    ++rg_count[b], sum_ln_n[b] += std::log(double(k.size)), sum_ln_rg[b] += std::log(k.radius_of_gyration);
  }
}

void ClusterTally::add(const ClusterTally& o) {
  sets += o.sets, particles += o.particles, clusters += o.clusters, spanning += o.spanning;
  largest = std::max(largest, o.largest);
  for (size_t b = 0; b < count.size(); ++b) {
    count[b] += o.count[b], rg_count[b] += o.rg_count[b];
    sum_ln_n[b] += o.sum_ln_n[b], sum_ln_rg[b] += o.sum_ln_rg[b];
  }
}

double ClusterTally::mean_size() const { return clusters ? double(particles) / clusters : kNaN; }

SizeHistogram ClusterTally::histogram() const {
  return clusters ? size_histogram(edges, count, bin_of(edges, largest) + 1) : SizeHistogram{};
}

FractalFit fit_fractal_dimension(const ClusterTally& t) {
  // Mean ln N_c and mean ln R_g of the non-empty bins.
  std::vector<double> ln_n, ln_rg;
  long used = 0;
  for (size_t b = 0; b < t.rg_count.size(); ++b)
    if (t.rg_count[b] > 0) {
      ln_n.push_back(t.sum_ln_n[b] / t.rg_count[b]), ln_rg.push_back(t.sum_ln_rg[b] / t.rg_count[b]);
      used += t.rg_count[b];
    }
  // Two bins make a line but no test of it, and a slope near 0 then gives
  // any d_f at all (11 +- 15 was seen for fast clusters): NaN below 3 bins.
  if (ln_n.size() < 3) return {kNaN, kNaN, static_cast<int>(ln_n.size()), used};
  const LinearFit f = linear_fit(ln_n, ln_rg); // ln R_g = (1/d_f) ln N_c + c
  return {1 / f.slope, f.slope_err / (f.slope * f.slope), f.n, used};
}

FractalFit fit_fractal_dimension(const std::vector<Cluster>& clusters, long n_min, int bins_per_decade) {
  long max_size = 1;
  for (const Cluster& c : clusters) max_size = std::max(max_size, c.size);
  ClusterTally t(max_size, bins_per_decade, n_min);
  t.add(ClusterSet{{}, clusters});
  return fit_fractal_dimension(t);
}

} // namespace dynhet::analysis
