#pragma once
// Cages: who a particle's neighbours are at an origin frame, and the
// displacement of a particle relative to its cage.
//
// In two dimensions long-wavelength displacements grow with the box
// (Mermin-Wagner; Flenner and Szamel, Nat. Commun. 6, 7392 (2015)): they
// move a particle together with its neighbours and decorrelate the overlap
// without any rearrangement. The cage-relative displacement removes them:
//   dr_i^CR = dr_i - (1/N_i) sum_{j in V_i(t0)} dr_j,
// with V_i(t0) the Voronoi neighbours of i in the origin frame (Illing et
// al., PNAS 114, 1856 (2017); Vivek et al., PNAS 114, 1850 (2017)).
#include <cstdint>
#include <vector>

namespace dynhet::analysis {

// Neighbour lists in compressed rows: the neighbours of particle i are
// list[offset[i]] .. list[offset[i + 1] - 1], ascending, without i.
struct Neighbours {
  std::vector<std::int64_t> offset; // n + 1 entries
  std::vector<std::int32_t> list;
  long size() const { return static_cast<long>(offset.size()) - 1; }
  long count(long i) const { return static_cast<long>(offset[i + 1] - offset[i]); }
};

// Voronoi neighbours of every particle in the periodic square box of side
// `box`: the particles whose Voronoi cells share an edge with i's, which are
// its neighbours in the Delaunay triangulation (CGAL's
// Periodic_2_Delaunay_triangulation_2, exact predicates). pos: x0 y0 x1 y1
// ..., folded or not. Throws std::invalid_argument on a bad box or
// non-finite positions, and where the triangulation of so few points does
// not fit one copy of the box (then the neighbours are not defined by the
// periodic box alone). Coincident points are refused.
Neighbours voronoi_neighbours(const double* pos, long n, double box);

// dr^CR (x y interleaved, as dr) for every particle: its displacement less
// the mean displacement of its neighbours; a particle with no neighbour
// keeps its own displacement. dr are unwrapped displacements (never the
// minimum image). out must not be dr.
void cage_relative(const double* dr, const Neighbours& v, double* out);

// The positions whose displacements from pos0 are the cage-relative ones,
// pos_i - (mean dr_j of i's neighbours) = pos0_i + dr^CR_i (up to
// rounding), in one gather: what the overlap node hands its measures for
// the cage-relative set. dr is a buffer, left holding pos - pos0 (the
// unwrapped displacements, for whoever needs them too); out must not alias
// pos0 or pos.
void cage_relative_positions(const double* pos0, const double* pos, const Neighbours& v, std::vector<double>& dr,
                             double* out);

} // namespace dynhet::analysis
