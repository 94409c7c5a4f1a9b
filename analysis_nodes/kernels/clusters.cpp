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

namespace {

// One bond seen from a particle: the neighbour and r_neighbour - r_particle.
struct Link {
  std::int32_t to;
  double dx, dy;
};

} // namespace

// What a search keeps between calls: the adjacency of the selected
// particles (CSR, each bond stored from both ends so the walk reads memory
// in order), unwrapped positions and the walk's queue.
struct ClusterFinder::Scratch {
  std::vector<std::int32_t> start, fill, queue;
  std::vector<Link> links;
  std::vector<std::array<double, 2>> u;

  void graph(const NeighbourPairs& nb, const std::uint8_t* sel) {
    start.assign(nb.n + 1, 0);
    for (const auto& p : nb.pairs)
      if (sel[p[0]] && sel[p[1]]) ++start[p[0] + 1], ++start[p[1] + 1];
    for (long i = 0; i < nb.n; ++i) start[i + 1] += start[i];
    links.resize(start[nb.n]);
    fill.assign(start.begin(), start.end() - 1);
    for (size_t e = 0; e < nb.pairs.size(); ++e) {
      const std::int32_t i = nb.pairs[e][0], j = nb.pairs[e][1];
      if (!sel[i] || !sel[j]) continue;
      links[fill[i]++] = {j, nb.bond[e][0], nb.bond[e][1]};
      links[fill[j]++] = {i, -nb.bond[e][0], -nb.bond[e][1]};
    }
  }
};

ClusterFinder::ClusterFinder() : s_(std::make_unique<Scratch>()) {}
ClusterFinder::~ClusterFinder() = default;

const ClusterSet& ClusterFinder::find(const NeighbourPairs& nb, const double* pos, double box,
                                      const std::uint8_t* selected) {
  const long n = nb.n;
  Scratch& s = *s_;
  s.graph(nb, selected);
  out_.label.assign(n, -1);
  out_.clusters.clear();
  s.u.resize(n); // positions unwrapped along the tree, relative to the root
  for (long root = 0; root < n; ++root) {
    if (!selected[root] || out_.label[root] >= 0) continue;
    const auto id = static_cast<std::int32_t>(out_.clusters.size());
    // Breadth-first over the cluster: each new particle sits at its parent's
    // unwrapped position plus the (minimum-image) bond.
    s.queue.assign(1, static_cast<std::int32_t>(root));
    out_.label[root] = id, s.u[root] = {0.0, 0.0};
    bool spans = false;
    double sx = 0, sy = 0, sxx = 0;
    for (size_t h = 0; h < s.queue.size(); ++h) {
      const std::int32_t a = s.queue[h];
      const double ax = s.u[a][0], ay = s.u[a][1];
      sx += ax, sy += ay, sxx += ax * ax + ay * ay;
      for (int k = s.start[a]; k < s.start[a + 1]; ++k) {
        const Link& l = s.links[k];
        const double bx = ax + l.dx, by = ay + l.dy;
        if (out_.label[l.to] < 0) {
          out_.label[l.to] = id, s.u[l.to] = {bx, by};
          s.queue.push_back(l.to);
        } else if (std::abs(s.u[l.to][0] - bx) > box / 2 || std::abs(s.u[l.to][1] - by) > box / 2) {
          spans = true; // the bond closes a loop around the periodic box
        }
      }
    }
    const double nc = double(s.queue.size()), mx = sx / nc, my = sy / nc;
    Cluster c{static_cast<long>(s.queue.size()), kNaN, kNaN, kNaN, spans};
    if (!spans) {
      c.radius_of_gyration = std::sqrt(std::max(0.0, sxx / nc - mx * mx - my * my)); // eq. (10)
      c.cx = fold(pos[2 * root] + mx, box), c.cy = fold(pos[2 * root + 1] + my, box);
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

namespace {

// Integer log-bin edges 1 = e_0 < e_1 < ... covering up to max_size.
std::vector<long> log_edges(long max_size, int per_decade) {
  std::vector<long> e;
  long last = 1;
  e.push_back(last);
  for (int k = 1; last <= max_size; ++k) {
    const long v = std::lround(std::pow(10.0, double(k) / per_decade));
    if (v > last) e.push_back(v), last = v;
  }
  return e;
}

} // namespace

SizeHistogram cluster_size_distribution(const std::vector<long>& sizes, int bins_per_decade) {
  SizeHistogram h;
  if (sizes.empty()) return h;
  const std::vector<long> e = log_edges(*std::max_element(sizes.begin(), sizes.end()), bins_per_decade);
  h.count.assign(e.size() - 1, 0);
  for (long s : sizes) ++h.count[std::upper_bound(e.begin(), e.end(), s) - e.begin() - 1];
  h.total = static_cast<long>(sizes.size());
  for (size_t b = 0; b + 1 < e.size(); ++b) {
    h.lo.push_back(e[b]), h.hi.push_back(e[b + 1] - 1);
    h.centre.push_back(std::sqrt(double(e[b]) * (e[b + 1] - 1)));
    h.p.push_back(h.count[b] / (double(h.total) * (e[b + 1] - e[b]))); // P(N_c): fraction per size
  }
  return h;
}

FractalFit fit_fractal_dimension(const std::vector<Cluster>& clusters, long n_min, int bins_per_decade) {
  long max_size = 1;
  for (const Cluster& c : clusters) max_size = std::max(max_size, c.size);
  const std::vector<long> e = log_edges(max_size, bins_per_decade);
  std::vector<double> sn(e.size(), 0.0), sr(e.size(), 0.0);
  std::vector<long> cnt(e.size(), 0);
  long used = 0;
  for (const Cluster& c : clusters) {
    if (c.spans || c.size < n_min || !(c.radius_of_gyration > 0)) continue;
    const size_t b = std::upper_bound(e.begin(), e.end(), c.size) - e.begin() - 1;
    sn[b] += std::log(double(c.size)), sr[b] += std::log(c.radius_of_gyration), ++cnt[b], ++used;
  }
  // Mean ln N_c and mean ln R_g of the non-empty bins, compacted in place.
  size_t used_bins = 0;
  for (size_t b = 0; b < e.size(); ++b)
    if (cnt[b] > 0) sn[used_bins] = sn[b] / cnt[b], sr[used_bins] = sr[b] / cnt[b], ++used_bins;
  sn.resize(used_bins), sr.resize(used_bins);
  const LinearFit f = linear_fit(sn, sr); // ln R_g = (1/d_f) ln N_c + c
  return {1 / f.slope, f.slope_err / (f.slope * f.slope), f.n, used};
}

} // namespace dynhet::analysis
