// Bond breaking for the overlap node (Yamamoto and Onuki,
// PRE 58, 3515 (1998); Shiba et al., PRL 117, 245701 (2016)): the bonds of
// each origin frame (r_ij < a1 sigma_ij), which of them are still intact
// (r_ij <= a2 sigma_ij) at every lag, C_B(t) and tau_B, and chi_B(t) per
// sub-box grid with chi4's estimator (analysis::Chi4Accumulator), C_B,r of
// the bonds whose first particle was in sub-box r at t0 in the place of Q_r.
// Bonds see relative positions only: a particle moving with its
// neighbours breaks none, so there is no cage-relative version.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <vector>

#include "dynhet/analysis/bonds.hpp"
#include "dynhet/analysis/chi4.hpp"
#include "dynhet/analysis/overlap.hpp"
#include "dynhet/bond_breaking_t.hpp"
#include "dynhet/run_info_t.hpp"
#include "dynhet/scene.hpp"

namespace dynhet {

class BondBreaking {
public:
  // grids: the chi4 sub-box grids; species: 0 small, 1 large, per particle.
  BondBreaking(const run_info_t& run, const Scene::BondBreaking& scene, std::vector<analysis::SubboxGrid> grids,
               const std::vector<std::uint8_t>& species);
  // Origin k's bonds, found when its frame arrives (and again on resume).
  void on_origin(int k, const std::vector<double>& pos0);
  void on_origin_dropped(int k) { bonds_.erase(k); }
  // One (origin, lag) pair: dr the unwrapped displacements since t0.
  void add(int k, int j, const std::vector<double>& pos0, const double* dr);
  bond_breaking_t message() const;
  template <class Ar> void state(Ar& ar) { ar(c_b_, bonds_per_particle_, chi_b_); } // what a checkpoint keeps

private:
  const run_info_t& run_;
  Scene::BondBreaking scene_;
  std::vector<analysis::SubboxGrid> grids_;
  const std::vector<std::uint8_t>& species_;
  std::map<int, analysis::BondSet> bonds_; // origin k -> its bonds
  std::vector<double> c_b_;                // per (origin, lag): the unbroken fraction; NaN not measured
  std::vector<double> bonds_per_particle_; // per origin; NaN not seen
  std::vector<analysis::Chi4Accumulator> chi_b_; // per grid
  std::vector<std::uint8_t> intact_;       // reused: per bond
  std::vector<double> box_bonds_, box_intact_; // reused: per sub-box
};

} // namespace dynhet
