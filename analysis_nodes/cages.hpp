// The cages of the origin frames, for the cage-relative measures of every
// node: V_i(t0) of each particle, built once per origin frame
// when it arrives and held with it. Two kinds ([observables] cage):
//   "voronoi" (default): the Voronoi neighbours (CGAL's periodic Delaunay
//     triangulation, analysis::voronoi_neighbours);
//   "g_ab": the particles within the first minima of g_ab(r), as the
//     clusters node's neighbours: the scene's clusters.neighbour_cutoffs, or
//     the first minima of the smoothed g_ab of the first origin frame this
//     process sees (then fixed, and kept in its checkpoint part, so that a
//     resumed node builds the same cages).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "dynhet/analysis/cage.hpp"
#include "dynhet/analysis/clusters.hpp"
#include "dynhet/run_info_t.hpp"
#include "dynhet/scene.hpp"

namespace dynhet {

class Cages {
public:
  // name: the node's, for its log ("overlap_node").
  Cages(const run_info_t& run, const Scene& scene, std::string name);
  // Origin k's cages from its positions (on arrival, and again on resume).
  void build(int k, const std::vector<double>& pos0);
  void drop(int k) { cages_.erase(k); }
  const analysis::Neighbours& at(int k) const { return cages_.at(k); }
  // "voronoi", or "g_ab r11 r12 r22" once the cutoffs are known.
  std::string describe() const;
  template <class Ar> void state(Ar& ar) { ar(cut_); } // what a checkpoint keeps

private:
  long n_;
  double box_;
  std::string kind_, name_;
  Scene::Clusters spec_;
  std::vector<std::uint8_t> species_;
  std::optional<analysis::NeighbourCutoffs> cut_; // g_ab: fixed at the first frame
  std::map<int, analysis::Neighbours> cages_;     // origin k -> its cages
};

// Neighbour lists in compressed rows from the pairs i < j of a frame.
analysis::Neighbours neighbours_from_pairs(const analysis::NeighbourPairs& p, long n);

} // namespace dynhet
