// Bond breaking (dynhet/analysis/bonds.hpp).
#include "dynhet/analysis/bonds.hpp"

#include <cmath>
#include <stdexcept>

namespace dynhet::analysis {

BondSet make_bonds(const double* pos, const std::uint8_t* species, long n, double box,
                   const std::array<double, 2>& diameter, double a1, double a2) {
  if (!(diameter[0] > 0 && diameter[1] > 0 && std::isfinite(diameter[0]) && std::isfinite(diameter[1])))
    throw std::invalid_argument("make_bonds: diameters must be finite and > 0");
  if (!(a1 > 0 && a2 > a1 && std::isfinite(a2)))
    throw std::invalid_argument("make_bonds: need 0 < A1 < A2 (A1 makes a bond, A2 breaks it)");
  NeighbourCutoffs cut;
  BondSet b;
  for (int si = 0; si < 2; ++si)
    for (int sj = si; sj < 2; ++sj) {
      const double sigma = 0.5 * (diameter[si] + diameter[sj]);
      cut.r[species_pair(si, sj)] = a1 * sigma;
      b.broken_sq[species_pair(si, sj)] = (a2 * sigma) * (a2 * sigma);
    }
  b.pairs = neighbour_pairs(pos, species, n, box, cut);
  return b;
}

long bonds_intact(const BondSet& b, const std::uint8_t* species, const double* dr, std::uint8_t* intact) {
  long count = 0;
  const auto& p = b.pairs.pairs;
  for (size_t k = 0; k < p.size(); ++k) {
    const std::int32_t i = p[k][0], j = p[k][1];
    const double x = b.pairs.bond[k][0] + dr[2 * j] - dr[2 * i], y = b.pairs.bond[k][1] + dr[2 * j + 1] - dr[2 * i + 1];
    const bool ok = x * x + y * y <= b.broken_sq[species_pair(species[i], species[j])];
    if (intact) intact[k] = ok;
    count += ok;
  }
  return count;
}

} // namespace dynhet::analysis
