#pragma once
// Bond breaking (Yamamoto and Onuki, PRE 58, 3515 (1998); Shiba et al.,
// PRL 117, 245701 (2016)): a bond joins i and j when r_ij < A1 sigma_ij at
// the origin frame t0; it is broken at t0 + t when r_ij > A2 sigma_ij.
// C_B(t) is the fraction of t0's bonds not broken. Unlike the overlap it
// does not see a particle move together with its neighbours.
#include <array>
#include <cstdint>
#include <vector>

#include "dynhet/analysis/clusters.hpp"

namespace dynhet::analysis {

struct BondSet {
  NeighbourPairs pairs;              // i < j, and the bond r_j - r_i at t0 (minimum image)
  std::array<double, 3> broken_sq{}; // (A2 sigma_ab)^2 by species_pair
};

// The bonds of a frame: pairs closer than a1 sigma_ab, sigma_ab = (d_a +
// d_b) / 2 with d the diameter of each species (0 small, 1 large).
// Throws std::invalid_argument unless 0 < a1 < a2 and the diameters are > 0.
BondSet make_bonds(const double* pos, const std::uint8_t* species, long n, double box,
                   const std::array<double, 2>& diameter, double a1, double a2);

// Which bonds are intact at t: |b + dr_j - dr_i| <= A2 sigma_ij, with dr the
// unwrapped displacements since t0 (x y interleaved; never the minimum
// image, which is wrong once a displacement exceeds L/2). Writes intact[k]
// per bond (if not null) and returns how many are intact.
long bonds_intact(const BondSet& b, const std::uint8_t* species, const double* dr, std::uint8_t* intact);

} // namespace dynhet::analysis
