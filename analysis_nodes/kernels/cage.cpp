// Voronoi neighbours in a periodic box by CGAL's periodic Delaunay
// triangulation, and cage-relative displacements (dynhet/analysis/cage.hpp).
#include "dynhet/analysis/cage.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Periodic_2_Delaunay_triangulation_2.h>
#include <CGAL/Periodic_2_Delaunay_triangulation_traits_2.h>
#include <CGAL/Periodic_2_triangulation_face_base_2.h>
#include <CGAL/Periodic_2_triangulation_vertex_base_2.h>
#include <CGAL/Triangulation_data_structure_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/spatial_sort.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

namespace dynhet::analysis {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Gt = CGAL::Periodic_2_Delaunay_triangulation_traits_2<K>;
using Vb0 = CGAL::Periodic_2_triangulation_vertex_base_2<Gt>;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<std::int32_t, Gt, Vb0>;
using Fb = CGAL::Periodic_2_triangulation_face_base_2<Gt>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using Triangulation = CGAL::Periodic_2_Delaunay_triangulation_2<Gt, Tds>;
using Point = Triangulation::Point;

double fold(double x, double box) {
  x = std::fmod(x, box);
  if (x < 0) x += box;
  return x < box ? x : 0.0; // fmod of -tiny + box can round to box
}

} // namespace

Neighbours voronoi_neighbours(const double* pos, long n, double box) {
  if (!(box > 0) || !std::isfinite(box)) throw std::invalid_argument("voronoi_neighbours: box must be finite and > 0");
  if (n < 0 || n > std::numeric_limits<std::int32_t>::max())
    throw std::invalid_argument("voronoi_neighbours: particle count out of range");
  std::vector<Point> points(n);
  for (long i = 0; i < n; ++i) {
    if (!std::isfinite(pos[2 * i]) || !std::isfinite(pos[2 * i + 1]))
      throw std::invalid_argument("voronoi_neighbours: position of particle " + std::to_string(i) + " not finite");
    points[i] = Point(fold(pos[2 * i], box), fold(pos[2 * i + 1], box));
  }
  // Insert in spatial (Hilbert) order, each from the last as a hint: what
  // CGAL's range insertion does, keeping each vertex's particle index.
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  using Map = CGAL::Pointer_property_map<Point>::type;
  using SortTraits = CGAL::Spatial_sort_traits_adapter_2<K, Map>;
  CGAL::spatial_sort(order.begin(), order.end(), SortTraits(CGAL::make_property_map(points)));
  Triangulation t(Gt::Iso_rectangle_2(0, 0, box, box));
  Triangulation::Vertex_handle hint;
  for (const std::size_t i : order) {
    const auto before = t.number_of_vertices();
    hint = hint == Triangulation::Vertex_handle() ? t.insert(points[i]) : t.insert(points[i], hint->face());
    if (t.number_of_vertices() == before)
      throw std::invalid_argument("voronoi_neighbours: particle " + std::to_string(i) + " coincides with another");
    hint->info() = static_cast<std::int32_t>(i);
  }
  if (!t.is_triangulation_in_1_sheet())
    throw std::invalid_argument("voronoi_neighbours: " + std::to_string(n) +
                                " particles are too few for a periodic triangulation of one box");
  // Compressed rows straight from the edges: count, place, then sort each
  // row (no vector per particle).
  Neighbours v;
  v.offset.assign(n + 1, 0);
  auto ends = [](const Triangulation::Edge& e) {
    return std::pair<std::int32_t, std::int32_t>(e.first->vertex(Triangulation::cw(e.second))->info(),
                                                 e.first->vertex(Triangulation::ccw(e.second))->info());
  };
  for (auto e = t.edges_begin(); e != t.edges_end(); ++e) {
    const auto [a, b] = ends(*e);
    if (a != b) ++v.offset[a + 1], ++v.offset[b + 1];
  }
  for (long i = 0; i < n; ++i) v.offset[i + 1] += v.offset[i];
  v.list.resize(v.offset[n]);
  std::vector<std::int64_t> fill(v.offset.begin(), v.offset.end() - 1);
  for (auto e = t.edges_begin(); e != t.edges_end(); ++e) {
    const auto [a, b] = ends(*e);
    if (a != b) v.list[fill[a]++] = b, v.list[fill[b]++] = a;
  }
  // In one sheet every periodic edge is stored once: no duplicates to remove.
  for (long i = 0; i < n; ++i) std::sort(v.list.begin() + v.offset[i], v.list.begin() + v.offset[i + 1]);
  return v;
}

namespace {
// out_i = from_i - (mean dr_j of i's neighbours; 0 without any): from = dr
// gives dr^CR, from = the positions at t gives pos0 + dr^CR.
//
// (x, y) travel as one two-lane vector (GCC's vector extension: the same
// IEEE operation in each lane, so the same bits as two scalar sums). A row
// of up to kRow neighbours is summed over exactly kRow slots, the slots past
// its end multiplied by 0: no loop exit that depends on the row's length,
// which a Voronoi row (4 to 9 long) makes unpredictable. The sums are those
// of the plain loop bit for bit: d * 1.0 == d, d * 0.0 == +-0.0, and
// s + +-0.0 == s for any s the sum can hold (it starts at +0.0 and is never
// -0.0). The masked slots read the next row's indices, valid particles.
// bench_analysis --sections cage: 1.05 -> 0.8 ms per (origin, lag) at N = 1e5.
using Pair = double __attribute__((vector_size(16)));
constexpr long kRow = 8;

struct RowMasks {
  Pair m[kRow + 1][kRow];
  RowMasks() {
    for (long c = 0; c <= kRow; ++c)
      for (long k = 0; k < kRow; ++k) m[c][k] = k < c ? Pair{1.0, 1.0} : Pair{0.0, 0.0};
  }
};
const RowMasks kMasks;

Pair load(const double* p) {
  Pair v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

void less_cage_mean(const double* dr, const Neighbours& v, const double* from, double* out) {
  const long n = v.size();
  const std::int64_t* offset = v.offset.data();
  const std::int32_t* list = v.list.data();
  const auto listed = static_cast<std::int64_t>(v.list.size());
  for (long i = 0; i < n; ++i) {
    const std::int64_t o = offset[i];
    const long c = static_cast<long>(offset[i + 1] - o);
    Pair s{0.0, 0.0};
    if (c <= kRow && o + kRow <= listed) {
      const Pair* mask = kMasks.m[c];
      for (long k = 0; k < kRow; ++k) s += load(dr + 2 * std::int64_t{list[o + k]}) * mask[k];
    } else {
      for (long k = 0; k < c; ++k) s += load(dr + 2 * std::int64_t{list[o + k]});
    }
    const double cd = c > 0 ? double(c) : 1.0; // no neighbour: s is 0, out = from
    const Pair r = load(from + 2 * i) - s / Pair{cd, cd};
    std::memcpy(out + 2 * i, &r, sizeof r);
  }
}
} // namespace

void cage_relative(const double* dr, const Neighbours& v, double* out) { less_cage_mean(dr, v, dr, out); }

void cage_relative_positions(const double* pos0, const double* pos, const Neighbours& v, std::vector<double>& dr,
                             double* out) {
  const long n = v.size();
  dr.resize(2 * n);
  for (long i = 0; i < 2 * n; ++i) dr[i] = pos[i] - pos0[i];
  less_cage_mean(dr.data(), v, pos, out);
}

} // namespace dynhet::analysis
