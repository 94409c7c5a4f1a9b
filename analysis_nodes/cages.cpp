// The cages of the origin frames (cages.hpp).
#include "cages.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

#include "dynhet/model.hpp"

namespace dynhet {

namespace an = analysis;

Cages::Cages(const run_info_t& run, const Scene& scene, std::string name)
    : n_(run.n_particles), box_(run.box_length), kind_(scene.cage), name_(std::move(name)), spec_(scene.clusters),
      species_(species_by_rule(run.n_particles, run.n_small)) {
  if (kind_ == "g_ab" && spec_.neighbour_cutoffs.size() == 3)
    cut_ = an::NeighbourCutoffs{{spec_.neighbour_cutoffs[0], spec_.neighbour_cutoffs[1], spec_.neighbour_cutoffs[2]}};
}

void Cages::build(int k, const std::vector<double>& pos0) {
  if (kind_ != "g_ab") {
    cages_[k] = an::voronoi_neighbours(pos0.data(), n_, box_);
    return;
  }
  if (!cut_) {
    const an::PairDistribution g = an::pair_distribution(pos0.data(), species_.data(), n_, box_,
                                                         std::min(spec_.gr_r_max, box_ / 2), spec_.gr_bin);
    const an::NeighbourCutoffs c = an::neighbour_cutoffs(g, spec_.gr_smoothing);
    if (!(std::isfinite(c.r[0]) && std::isfinite(c.r[1]) && std::isfinite(c.r[2])))
      throw std::runtime_error("cage = \"g_ab\": no first minimum of g_ab in the first origin frame; "
                               "give clusters.neighbour_cutoffs");
    cut_ = c;
    std::fprintf(stderr, "%s: %s from the first origin frame\n", name_.c_str(), describe().c_str());
  }
  cages_[k] = neighbours_from_pairs(an::neighbour_pairs(pos0.data(), species_.data(), n_, box_, *cut_), n_);
}

std::string Cages::describe() const {
  if (kind_ != "g_ab") return "Voronoi cages";
  if (!cut_) return "g_ab cages (cutoffs from the first origin frame)";
  char buf[128];
  std::snprintf(buf, sizeof buf, "g_ab cages (r11 %.4g, r12 %.4g, r22 %.4g)", cut_->r[0], cut_->r[1], cut_->r[2]);
  return buf;
}

an::Neighbours neighbours_from_pairs(const an::NeighbourPairs& p, long n) {
  an::Neighbours v;
  v.offset.assign(n + 1, 0);
  for (const auto& ij : p.pairs) ++v.offset[ij[0] + 1], ++v.offset[ij[1] + 1];
  for (long i = 0; i < n; ++i) v.offset[i + 1] += v.offset[i];
  v.list.resize(v.offset[n]);
  std::vector<std::int64_t> fill(v.offset.begin(), v.offset.end() - 1);
  for (const auto& ij : p.pairs) v.list[fill[ij[0]]++] = ij[1], v.list[fill[ij[1]]++] = ij[0];
  for (long i = 0; i < n; ++i) std::sort(v.list.begin() + v.offset[i], v.list.begin() + v.offset[i + 1]);
  return v;
}

} // namespace dynhet
