// overlap_node: the overlap Q(t), its error bars and tau_alpha, computed
// live from the frames on DYNHET_FRAME and published on DYNHET_OVERLAP_<a>
// (one channel per cutoff a, e.g. DYNHET_OVERLAP_a0.6) after every frame
// that adds a pair; if the run asks for chi4, also chi4(t) for every listed
// sub-box size on DYNHET_CHI4_<a>, from the same displacements, and the
// MSD (with the instantaneous fastest and slowest subsets, alpha_2 and
// F_s; msd_results.cpp) on DYNHET_MSD and P(dx, t) on DYNHET_DISPLACEMENT;
// with "bond_breaking", C_B(t), tau_B and chi_B on DYNHET_BOND_BREAKING.
// With [observables] cage_relative, all but bond breaking again, in the
// same pass, of the cage-relative displacements dr_i - (mean dr of i's
// cage in the origin frame; cages.cpp), on the channels with _CR
// (DYNHET_OVERLAP_CR_a0.6, DYNHET_MSD_CR, ...). It holds only the origin
// frames that some later frame still needs (16 N bytes each, plus 4 N per
// origin for chi4's sub-box index, about 28 N for the cages and 24 bytes
// per bond for the bonds, 1.3 to 2.2 bonds per particle).
//
// Usage: overlap_node [--lcm-url URL] [--publish-url URL]
// With --lcm-url file://LOG?speed=0 it re-runs the analysis from an
// lcm-logger log at full speed and publishes on --publish-url.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <string>

#include "dynhet/model.hpp"
#include "dynhet/analysis/cage.hpp"
#include "dynhet/analysis/chi4.hpp"
#include "dynhet/analysis/displacement.hpp"
#include "dynhet/analysis/fits.hpp"
#include "dynhet/analysis/overlap.hpp"
#include "dynhet/analysis/timescales.hpp"
#include "dynhet/chi4_t.hpp"
#include "dynhet/displacement_t.hpp"
#include "dynhet/msd_t.hpp"
#include "dynhet/overlap_t.hpp"
#include "dynhet/scene.hpp"
#include "dynhet/stats.hpp"
#include "bond_breaking_results.hpp"
#include "cages.hpp"
#include "displacement_results.hpp"
#include "msd_results.hpp"
#include "frame_node.hpp"

namespace {

namespace an = dynhet::analysis;
using dynhet::Measures;

class OverlapNode : public dynhet::FrameNode {
public:
  OverlapNode(lcm::LCM& out, int64_t run_filter) : FrameNode(out, run_filter, "overlap") {}

private:
  void start(const dynhet::run_info_t& m) override {
    grid_ = an::make_subbox_grid(m.n_particles, m.box_length, m.overlap_subbox_particles);
    // The cage-relative set, if any, does everything the standard one does.
    cage_ = wants("overlap_cr") || wants("chi4_cr") || wants("msd_cr") || wants("displacement_cr");
    if (cage_) cages_ = std::make_unique<dynhet::Cages>(m, dynhet::parse_scene_text(m.scene_toml, "run info scene"),
                                                       "overlap_node");
    sets_.resize(cage_ ? 2 : 1);
    sets_.back().cage_relative = cage_;
    for (Measures& s : sets_)
      for (int c = 0; c < m.n_cutoffs; ++c) s.acc.emplace_back(m.n_origins, m.lag_time, dynhet::origin_spacing(m));
    want_chi4_ = wants("chi4");
    want_msd_ = wants("msd");
    const bool want_displacement = wants("displacement");
    want_bonds_ = wants("bond_breaking");
    if (want_msd_ || want_displacement || want_bonds_) {
      try {
        const dynhet::Scene scene = dynhet::parse_scene_text(m.scene_toml, "run info scene");
        if (want_msd_) msd_ = std::make_unique<dynhet::MsdResults>(m, scene.msd);
        bond_spec_ = scene.bond_breaking;
        if (want_displacement)
          for (Measures& s : sets_) s.displacement = std::make_unique<dynhet::DisplacementResults>(m, scene.displacement);
      } catch (const std::exception& e) {
        throw std::runtime_error(std::string("cannot read the scene's [msd], [displacement] and [bond_breaking] tables: ") +
                                 e.what());
      }
    }
    if (want_chi4_ || want_msd_ || want_displacement || want_bonds_) start_pass(m);
    std::fprintf(stderr, "overlap_node: %dx%d sub-boxes of N=%.1f%s\n", grid_.per_side, grid_.per_side,
                 grid_.mean_particles,
                 cage_ ? ("; also of the cage-relative displacements (" + cages_->describe() + ")").c_str() : "");
  }

  void on_origin(int k, const std::vector<double>& pos0) override {
    if (pass_on_) chi4_index_[k] = std::make_unique<an::OriginIndex>(pos0.data(), info().n_particles, spec_);
    if (cage_) cages_->build(k, pos0);
    if (bonds_) bonds_->on_origin(k, pos0);
  }
  void on_origin_dropped(int k) override {
    chi4_index_.erase(k);
    if (cage_) cages_->drop(k);
    if (bonds_) bonds_->on_origin_dropped(k);
  }

  // Checkpoints: every accumulator; the sub-box index and the cages of each
  // held origin are rebuilt from its positions.
  void save_state(dynhet::StateOut& out) override {
    for (Measures& s : sets_) s.io(out);
    if (bonds_) out(*bonds_);
    if (cages_) out(*cages_);
  }
  void load_state(dynhet::StateIn& in) override {
    for (Measures& s : sets_) s.io(in);
    if (bonds_) in(*bonds_);
    if (cages_) in(*cages_); // the g_ab cutoffs, before the held origins' cages are rebuilt
    if (pass_on_ || cage_)
      for (const auto& [k, pos0] : held_origins()) on_origin(k, pos0);
  }

  void on_pair(int k, int j, const std::vector<double>& pos0, const dynhet::Frame& f) override {
    add_pair(sets_[0], k, j, pos0, f.position.data());
    const long n2 = 2L * info().n_particles;
    if (cage_) { // the frame's positions replaced by pos0 + dr^CR (dr_ left holding dr)
      dr_cr_.resize(n2);
      an::cage_relative_positions(pos0.data(), f.position.data(), cages_->at(k), dr_, dr_cr_.data());
    } else if (bonds_) {
      dr_.resize(n2);
      for (long i = 0; i < n2; ++i) dr_[i] = f.position[i] - pos0[i];
    }
    if (bonds_) bonds_->add(k, j, pos0, dr_.data());
    // The same pair again, every measure seeing cage-relative displacements.
    if (cage_) add_pair(sets_[1], k, j, pos0, dr_cr_.data());
  }
  void add_pair(Measures& s, int k, int j, const std::vector<double>& pos0, const double* pos) {
    an::overlap_subboxes(pos0.data(), pos, info().n_particles, grid_, info().cutoff_a, qr_);
    const int nb = grid_.per_side * grid_.per_side;
    for (size_t c = 0; c < s.acc.size(); ++c) s.acc[c].add(k, j, qr_.data() + c * nb, nb);
    if (pass_on_) add_pass(s, k, j, pos0, pos);
  }

  // Q(t) = 1/((t/tau0)^beta + 1), eq. (8), over the lags where
  // 0.1 <= Q <= 0.7 (overlap_fit_lags), unweighted: the errors of the lags
  // are correlated (the same origins), so beta and tau0 take theirs from a
  // jackknife over blocks of origins, each replicate fitted over the same lags.
  void fit_q(const an::OverlapAccumulator& acc, const an::OverlapAccumulator::Result& r,
             dynhet::overlap_t& m) const {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    m.beta = m.beta_err = m.tau0 = m.tau0_err = nan;
    const std::vector<int> lags = an::overlap_fit_lags(r.q);
    if (lags.empty()) return;
    auto fit = [&](const std::vector<double>& q) {
      std::vector<double> t, y;
      for (int j : lags) t.push_back(info().lag_time[j]), y.push_back(q[j]);
      try {
        const auto f = an::fit_overlap(t, y);
        return std::vector<double>{f.beta, f.tau0};
      } catch (const std::exception&) {
        return std::vector<double>{nan, nan}; // not converged: NaN
      }
    };
    const auto p = fit(r.q);
    m.beta = p[0], m.tau0 = p[1];
    if (std::isnan(m.beta)) return;
    // Blocks spanning the longest lag fitted (origin_block).
    const int block = an::origin_block(info().lag_time[lags.back()], acc.origin_spacing(), acc.n_origins());
    const auto e = an::origin_jackknife(acc.table(), acc.n_origins(), static_cast<int>(r.q.size()), fit, block);
    if (e.size() == 2) m.beta_err = e[0], m.tau0_err = e[1];
  }

  // chi4 for every listed sub-box size (nested grids: one pass, see
  // displacement.hpp) and every cutoff.
  void start_pass(const dynhet::run_info_t& m) {
    pass_on_ = true;
    const size_t pairs = static_cast<size_t>(m.n_origins) * m.lag_time.size();
    spec_.grids = an::nested_subbox_grids(m.n_particles, m.box_length, m.chi4_subbox_particles);
    spec_.cutoffs = m.cutoff_a;
    std::sort(spec_.cutoffs.begin(), spec_.cutoffs.end()); // the pass wants them ascending
    for (Measures& s : sets_) {
      s.msd_all.assign(pairs, std::numeric_limits<double>::quiet_NaN());
      s.msd_small = s.msd_all;
      for (auto& v : s.msd_extreme) v = s.msd_all;
      if (msd_) msd_->allocate(s);
      if (s.displacement) s.displacement->configure(spec_);
      for (const auto& g : spec_.grids)
        for (size_t c = 0; c < spec_.cutoffs.size(); ++c)
          s.chi4_acc.emplace_back(m.n_origins, m.lag_time, g, dynhet::origin_spacing(m));
    }
    if (want_msd_) d2_.resize(m.n_particles);
    species_ = dynhet::species_by_rule(m.n_particles, m.n_small);
    if (want_bonds_) bonds_ = std::make_unique<dynhet::BondBreaking>(m, bond_spec_, spec_.grids, species_);
  }
  void add_pass(Measures& s, int k, int j, const std::vector<double>& pos0, const double* pos) {
    const long n = info().n_particles;
    an::displacement_pass(pos0.data(), pos, species_.data(), n, *chi4_index_.at(k), spec_, pass_,
                          want_msd_ ? d2_.data() : nullptr);
    for (size_t i = 0; i < s.chi4_acc.size(); ++i) s.chi4_acc[i].add(k, j, pass_.q_r_sum[i], pass_.q_r_sum2[i]);
    const size_t kj = static_cast<size_t>(k) * info().lag_time.size() + j;
    s.msd_all[kj] = pass_.msd_all;
    s.msd_small[kj] = pass_.msd_small;
    if (msd_) msd_->add(s, k, j, pos0.data(), pos, d2_.data(), pass_.msd_all);
    if (s.displacement) s.displacement->add(k, j, pass_, pass_.n_small);
  }
  void publish_msd(const Measures& s, bool final) {
    std::vector<double> frozen; // the waves' frozen shares, for the final log line
    dynhet::msd_t m = msd_->message(s, frozen);
    stamp(m, final);
    publish(dynhet::result_channel(dynhet::kChanMsd, s.cage_relative), m);
    if (final) msd_->log_flows(m, frozen, s.says());
  }
  void publish_chi4(const Measures& s, bool final) {
    const size_t nc = spec_.cutoffs.size(), ng = spec_.grids.size(), nj = info().lag_time.size();
    for (size_t c = 0; c < nc; ++c) {
      dynhet::chi4_t m{};
      stamp(m, final);
      m.cage_relative = s.cage_relative;
      m.cutoff_a = spec_.cutoffs[c];
      m.n_grids = static_cast<int32_t>(ng);
      m.n_lags = static_cast<int32_t>(nj);
      m.lag_time = info().lag_time;
      for (size_t g = 0; g < ng; ++g) {
        const auto r = s.chi4_acc[g * nc + c].result();
        m.subbox_particles.push_back(spec_.grids[g].mean_particles);
        m.subbox_per_side.push_back(spec_.grids[g].per_side);
        m.chi4.insert(m.chi4.end(), r.chi4.begin(), r.chi4.end());
        m.chi4_err.insert(m.chi4_err.end(), r.chi4_err.begin(), r.chi4_err.end());
        m.chi4_per_origin.insert(m.chi4_per_origin.end(), r.chi4_per_origin.begin(), r.chi4_per_origin.end());
        m.chi4_per_origin_err.insert(m.chi4_per_origin_err.end(), r.chi4_per_origin_err.begin(),
                                     r.chi4_per_origin_err.end());
        m.tau4_interior.push_back(r.tau4_interior ? 1 : 0);
        m.chi4_peak.push_back(r.chi4_peak);
        m.tau4.push_back(r.tau4);
        m.chi4_peak_err.push_back(r.chi4_peak_err);
        m.tau4_err.push_back(r.tau4_err);
      }
      m.n_values = static_cast<int32_t>(m.chi4.size());
      publish(dynhet::cutoff_channel(dynhet::kChanChi4, m.cutoff_a, s.cage_relative), m);
    }
  }

  // P(dx, t) at the lags nearest the scene's targets, tau_alpha that of
  // the first cutoff listed. At most once a second before the final
  // message: each costs (1 + blocks) fits per target and set, and a record.
  // (The cage-relative P(dx, t) at multiples of the cage-relative tau_alpha.)
  void publish_displacement(Measures& s, bool final) {
    const auto now = std::chrono::steady_clock::now();
    if (!final && now - s.last_displacement < std::chrono::seconds(1)) return;
    s.last_displacement = now;
    dynhet::displacement_t m = s.displacement->message(s.acc[0].result().tau_alpha, info().cutoff_a[0]);
    stamp(m, final);
    m.cage_relative = s.cage_relative;
    publish(dynhet::result_channel(dynhet::kChanDisplacement, s.cage_relative), m);
  }

  void publish_results(bool final) override {
    if (bonds_) {
      dynhet::bond_breaking_t m = bonds_->message();
      stamp(m, final);
      publish(dynhet::kChanBondBreaking, m);
      if (final)
        std::fprintf(stderr, "overlap_node: bond breaking (a1 = %g, a2 = %g, %.3g bonds per particle): tau_B=%.5g +- %.2g\n",
                     m.a1, m.a2, m.bonds_per_particle, m.tau_b, m.tau_b_err);
    }
    for (Measures& s : sets_) {
      if (want_chi4_) publish_chi4(s, final);
      if (msd_) publish_msd(s, final);
      if (s.displacement) publish_displacement(s, final);
      publish_overlap(s, final);
    }
  }
  void publish_overlap(const Measures& s, bool final) {
    for (size_t c = 0; c < s.acc.size(); ++c) {
      const auto r = s.acc[c].result();
      dynhet::overlap_t m{};
      stamp(m, final);
      m.cage_relative = s.cage_relative;
      m.cutoff_a = info().cutoff_a[c];
      m.subbox_per_side = grid_.per_side;
      m.subbox_particles = grid_.mean_particles;
      m.n_lags = info().n_lags;
      m.lag_time = info().lag_time;
      m.q = r.q;
      m.q_err = r.q_err;
      m.n_origins = r.n_origins;
      m.qr_var = r.qr_var;
      m.tau_alpha = r.tau_alpha;
      m.tau_alpha_err = r.tau_alpha_err;
      fit_q(s.acc[c], r, m);
      for (int k = 0; k < info().n_origins; ++k) m.t0.push_back(info().frame_time[info().origin_frame[k]]);
      m.tau_alpha_t0 = an::tau_alpha_per_origin(s.acc[c], info().lag_time, info().n_origins);
      m.tau_alpha_t0_err = an::tau_alpha_per_origin_error(m.t0, m.tau_alpha_t0, info().lag_time, r.tau_alpha);
      m.n_t0 = static_cast<int32_t>(m.t0.size());
      publish(dynhet::cutoff_channel(dynhet::kChanOverlap, m.cutoff_a, s.cage_relative), m);
      if (final)
        std::fprintf(stderr, "overlap_node%s: a=%g tau_alpha=%.5g +- %.2g (%d pairs)\n", s.says(), m.cutoff_a,
                     m.tau_alpha, m.tau_alpha_err, pairs_done());
    }
  }

  an::SubboxGrid grid_{};
  std::vector<Measures> sets_; // [0] of the displacements, [1] of the cage-relative ones (cage_)
  bool cage_ = false;
  std::unique_ptr<dynhet::Cages> cages_; // the cages of the held origins (cage_)
  std::vector<double> dr_, dr_cr_;       // the pair's displacements; pos0 + dr^CR
  std::vector<double> qr_;
  // The displacement pass, for chi4 and the MSD (only if the run asks)
  bool pass_on_ = false, want_chi4_ = false, want_msd_ = false, want_bonds_ = false;
  dynhet::Scene::BondBreaking bond_spec_;
  std::unique_ptr<dynhet::BondBreaking> bonds_; // bond breaking, if the run asks
  std::vector<double> d2_;                   // |dr|^2 of the pair
  std::unique_ptr<dynhet::MsdResults> msd_; // the MSD's part (if the run asks)
  an::DisplacementSpec spec_;
  std::vector<uint8_t> species_;
  std::map<int, std::unique_ptr<an::OriginIndex>> chi4_index_;
  an::DisplacementResult pass_;
};

} // namespace

int main(int argc, char** argv) {
  return dynhet::node_main<OverlapNode>("overlap_node", "dynhet overlap_node: Q(t), tau_alpha from frames on LCM", argc, argv);
}
