// Bond breaking for the overlap node (bond_breaking_results.hpp).
#include "bond_breaking_results.hpp"

#include <cmath>
#include <limits>

#include "dynhet/analysis/fits.hpp"
#include "dynhet/stats.hpp"
#include "frame_node.hpp" // origin_spacing

namespace dynhet {

namespace an = analysis;
namespace {
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
}

BondBreaking::BondBreaking(const run_info_t& run, const Scene::BondBreaking& scene,
                           std::vector<an::SubboxGrid> grids, const std::vector<std::uint8_t>& species)
    : run_(run), scene_(scene), grids_(std::move(grids)), species_(species) {
  c_b_.assign(static_cast<size_t>(run.n_origins) * run.lag_time.size(), kNan);
  bonds_per_particle_.assign(run.n_origins, kNan);
  for (const auto& g : grids_) chi_b_.emplace_back(run.n_origins, run.lag_time, g, origin_spacing(run));
}

void BondBreaking::on_origin(int k, const std::vector<double>& pos0) {
  const std::array<double, 2> diameter{2 * run_.radius[0], 2 * run_.radius[1]};
  an::BondSet b = an::make_bonds(pos0.data(), species_.data(), run_.n_particles, run_.box_length, diameter,
                                 scene_.a1, scene_.a2);
  bonds_per_particle_[k] = double(b.pairs.pairs.size()) / double(run_.n_particles);
  bonds_[k] = std::move(b);
}

void BondBreaking::add(int k, int j, const std::vector<double>& pos0, const double* dr) {
  const an::BondSet& b = bonds_.at(k);
  const size_t nb = b.pairs.pairs.size();
  intact_.resize(nb);
  const long intact = an::bonds_intact(b, species_.data(), dr, intact_.data());
  c_b_[static_cast<size_t>(k) * run_.lag_time.size() + j] = nb ? double(intact) / double(nb) : kNan;
  // C_B,r per sub-box of each grid: the bonds whose first particle was in
  // box r at t0 (folded); a box without bonds counts as unbroken (1).
  const double box = run_.box_length;
  for (size_t g = 0; g < grids_.size(); ++g) {
    const int m = grids_[g].per_side;
    box_bonds_.assign(static_cast<size_t>(m) * m, 0.0);
    box_intact_ = box_bonds_;
    for (size_t q = 0; q < nb; ++q) {
      const long i = b.pairs.pairs[q][0];
      const double x = pos0[2 * i] - box * std::floor(pos0[2 * i] / box);
      const double y = pos0[2 * i + 1] - box * std::floor(pos0[2 * i + 1] / box);
      const int bx = std::min(m - 1, static_cast<int>(x / box * m)), by = std::min(m - 1, static_cast<int>(y / box * m));
      const size_t r = static_cast<size_t>(by) * m + bx;
      box_bonds_[r] += 1;
      box_intact_[r] += intact_[q];
    }
    double sum = 0, sum2 = 0;
    for (size_t r = 0; r < box_bonds_.size(); ++r) {
      const double c = box_bonds_[r] > 0 ? box_intact_[r] / box_bonds_[r] : 1.0;
      sum += c, sum2 += c * c;
    }
    chi_b_[g].add(k, j, sum, sum2);
  }
}

bond_breaking_t BondBreaking::message() const {
  bond_breaking_t m{};
  m.a1 = scene_.a1, m.a2 = scene_.a2;
  BlockAverage per_particle;
  for (double x : bonds_per_particle_)
    if (!std::isnan(x)) per_particle.add(x);
  m.bonds_per_particle = per_particle.count() ? per_particle.mean() : kNan;
  m.lag_time = run_.lag_time;
  const int nl = static_cast<int>(m.lag_time.size()), no = run_.n_origins;
  m.n_lags = nl;
  m.c_b.assign(nl, kNan), m.c_b_err.assign(nl, kNan);
  for (int j = 0; j < nl; ++j) {
    BlockAverage a;
    for (int k = 0; k < no; ++k)
      if (const double x = c_b_[static_cast<size_t>(k) * nl + j]; !std::isnan(x)) a.add(x);
    if (a.count()) m.c_b[j] = a.mean(), m.c_b_err[j] = a.standard_error();
  }
  // tau_B: where C_B crosses 1/e (as tau_alpha), its error a jackknife over
  // blocks of origins spanning it; none where the run's origins do not hold
  // kMinJackknifeBlocks such blocks (a bond lives many origin spacings: the
  // capped blocks gave errors a third of the seeds' spread, docs/analysis.md),
  // and a study then takes the spread of its seeds.
  auto tau = [&](const std::vector<double>& c) { return std::vector<double>{an::crossing_time(m.lag_time, c, std::exp(-1.0))}; };
  m.tau_b = tau(m.c_b)[0];
  m.tau_b_err = kNan;
  if (std::isfinite(m.tau_b) && an::origin_blocks_span(m.tau_b, origin_spacing(run_), no)) {
    const int block = an::origin_block(m.tau_b, origin_spacing(run_), no);
    const auto e = an::origin_jackknife(c_b_, no, nl, tau, block);
    if (e.size() == 1) m.tau_b_err = e[0];
  }
  m.n_grids = static_cast<int32_t>(grids_.size());
  for (size_t g = 0; g < grids_.size(); ++g) {
    const auto r = chi_b_[g].result();
    m.subbox_particles.push_back(grids_[g].mean_particles);
    m.subbox_per_side.push_back(grids_[g].per_side);
    m.chi_b.insert(m.chi_b.end(), r.chi4.begin(), r.chi4.end());
    m.chi_b_err.insert(m.chi_b_err.end(), r.chi4_err.begin(), r.chi4_err.end());
    m.chi_b_peak.push_back(r.chi4_peak), m.tau_chi_b.push_back(r.tau4);
    m.chi_b_peak_err.push_back(r.chi4_peak_err), m.tau_chi_b_err.push_back(r.tau4_err);
  }
  m.n_values = static_cast<int32_t>(m.chi_b.size());
  return m;
}

} // namespace dynhet
