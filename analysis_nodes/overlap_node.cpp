// overlap_node: the overlap Q(t), its error bars and tau_alpha, computed
// live from the frames on DYNHET_FRAME and published on DYNHET_OVERLAP_<a>
// (one channel per cutoff a, e.g. DYNHET_OVERLAP_a0.6) after every frame
// that adds a pair; if the run asks for chi4, also chi4(t) for every listed
// sub-box size on DYNHET_CHI4_<a>, from the same displacements, and the
// MSD (with the instantaneous fastest and slowest subsets) on DYNHET_MSD
// and P(dx, t) on DYNHET_DISPLACEMENT. With [observables] cage_relative,
// all of them again, in the same pass, of the cage-relative displacements
// dr_i - (mean dr of i's Voronoi neighbours in the origin frame), on the
// channels with _CR (DYNHET_OVERLAP_CR_a0.6, DYNHET_MSD_CR, ...). It holds
// only the origin frames that some later frame still needs (16 N bytes
// each, plus 4 N per origin for chi4's sub-box index and about 28 N for
// the neighbours of a cage).
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
#include "frame_node.hpp"

namespace {

namespace an = dynhet::analysis;

// One set of the node's accumulators: of the displacements as they are, or
// of the cage-relative ones.
struct Measures {
  bool cage_relative = false;
  std::vector<an::OverlapAccumulator> acc; // one per cutoff
  std::vector<double> msd_all, msd_small;  // per (origin, lag)
  std::vector<double> msd_extreme[4];      // per (origin, lag): fast all, slow all, fast small, slow small
  std::vector<double> flow_t, flow_l;      // per (origin, lag, mode): collective_modes
  std::vector<double> amp;                 // per (origin, mode): u_k . e at the last lag (t re, im, l re, im)
  std::vector<double> m4_all, m4_small;    // per (origin, lag): <|dr|^4> over the particles, for alpha_2
  std::vector<double> fs_all, fs_small;    // per (origin, lag, q): <J0(q |dr|)>
  std::unique_ptr<dynhet::DisplacementResults> displacement;
  std::chrono::steady_clock::time_point last_displacement{};
  std::vector<an::Chi4Accumulator> chi4_acc; // [grid * n_cutoffs + cutoff], cutoffs ascending
  template <class Ar> void io(Ar& ar) {
    ar(acc, msd_all, msd_small, msd_extreme, flow_t, flow_l, amp, m4_all, m4_small, fs_all, fs_small, chi4_acc);
    if (displacement) ar(*displacement);
  }
  const char* says() const { return cage_relative ? " (cage-relative)" : ""; }
};

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
        msd_spec_ = scene.msd;
        bond_spec_ = scene.bond_breaking;
        if (msd_spec_.fs) { // 2 pi / sigma_ab of the species' contact distances
          const double r0 = m.radius[0], r1 = m.radius[1];
          fs_q_ = {2 * M_PI / (2 * r0), 2 * M_PI / (r0 + r1), 2 * M_PI / (2 * r1)};
        }
        fs_q_.insert(fs_q_.end(), msd_spec_.fs_q.begin(), msd_spec_.fs_q.end());
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
    if (bonds_) {
      dr_.resize(n2);
      for (long i = 0; i < n2; ++i) dr_[i] = f.position[i] - pos0[i];
      bonds_->add(k, j, pos0, dr_.data());
    }
    if (!cage_) return;
    // The same pair again, the frame's positions replaced by
    // pos0 + dr^CR: every measure below sees cage-relative displacements.
    dr_cr_.resize(n2);
    an::cage_relative_positions(pos0.data(), f.position.data(), cages_->at(k), dr_, dr_cr_.data());
    add_pair(sets_[1], k, j, pos0, dr_cr_.data());
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
    if (want_msd_) {
      std::vector<int> nx, ny;
      an::wave_vectors(kFlowModes, nx, ny);
      n_modes_ = nx.size();
    }
    spec_.grids = an::nested_subbox_grids(m.n_particles, m.box_length, m.chi4_subbox_particles);
    spec_.cutoffs = m.cutoff_a;
    std::sort(spec_.cutoffs.begin(), spec_.cutoffs.end()); // the pass wants them ascending
    for (Measures& s : sets_) {
      s.msd_all.assign(pairs, std::numeric_limits<double>::quiet_NaN());
      s.msd_small = s.msd_all;
      for (auto& v : s.msd_extreme) v = s.msd_all;
      if (want_msd_) {
        s.m4_all.assign(pairs, std::numeric_limits<double>::quiet_NaN());
        s.m4_small = s.m4_all;
        s.fs_all.assign(pairs * fs_q_.size(), std::numeric_limits<double>::quiet_NaN());
        s.fs_small = s.fs_all;
        s.flow_t.assign(pairs * n_modes_, std::numeric_limits<double>::quiet_NaN());
        s.flow_l = s.flow_t;
        s.amp.assign(static_cast<size_t>(m.n_origins) * n_modes_ * 4, std::numeric_limits<double>::quiet_NaN());
      }
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
    if (want_msd_) {
      // The instantaneous fastest and slowest subsets of this pair.
      const auto [all, small] = an::msd_extremes_all_small(d2_.data(), species_.data(), n, msd_spec_.fraction_all,
                                                           msd_spec_.fraction_small, select_);
      s.msd_extreme[0][kj] = all.fast, s.msd_extreme[1][kj] = all.slow;
      s.msd_extreme[2][kj] = small.fast, s.msd_extreme[3][kj] = small.slow;
      self_part(s, kj);
      const an::WaveModes w =
          an::collective_modes(pos0.data(), pos, n, info().box_length, kFlowModes, pass_.msd_all);
      std::copy(w.transverse.begin(), w.transverse.end(), s.flow_t.begin() + kj * n_modes_);
      std::copy(w.longitudinal.begin(), w.longitudinal.end(), s.flow_l.begin() + kj * n_modes_);
      if (j == info().n_lags - 1) // the amplitudes at the last lag, for the modes' lifetimes
        for (size_t q = 0; q < n_modes_; ++q) {
          double* a = &s.amp[(static_cast<size_t>(k) * n_modes_ + q) * 4];
          a[0] = w.t_re[q], a[1] = w.t_im[q], a[2] = w.l_re[q], a[3] = w.l_im[q];
        }
    }
    if (s.displacement) s.displacement->add(k, j, pass_, pass_.n_small);
  }
  // <|dr|^4> and F_s(q) = <J0(q |dr|)> of all and of the small particles
  // from the pair's |dr|^2 (one pass: each particle's J0 counts for both).
  void self_part(Measures& s, size_t kj) {
    const long n = info().n_particles;
    const size_t nq = fs_q_.size();
    fs_sum_.assign(2 * nq, 0.0);
    double r4_all = 0, r4_small = 0;
    long n_small = 0;
    for (long i = 0; i < n; ++i) {
      const double r2 = d2_[i], r4 = r2 * r2;
      const bool small = species_[i] == 0;
      r4_all += r4;
      if (small) r4_small += r4, ++n_small;
      if (nq == 0) continue;
      const double r = std::sqrt(r2);
      for (size_t q = 0; q < nq; ++q) {
        const double j = ::j0(fs_q_[q] * r);
        fs_sum_[q] += j;
        if (small) fs_sum_[nq + q] += j;
      }
    }
    s.m4_all[kj] = r4_all / double(n);
    s.m4_small[kj] = n_small ? r4_small / double(n_small) : std::numeric_limits<double>::quiet_NaN();
    for (size_t q = 0; q < nq; ++q) {
      s.fs_all[kj * nq + q] = fs_sum_[q] / double(n);
      s.fs_small[kj * nq + q] = n_small ? fs_sum_[nq + q] / double(n_small) : std::numeric_limits<double>::quiet_NaN();
    }
  }
  // alpha_2(t) = <dr^4> / (2 <dr^2>^2) - 1, the means over particles and
  // origins; the error from a jackknife over blocks of origins spanning the
  // longest lag (the two tables side by side, so that each replicate leaves
  // the same origins out of both).
  void alpha2(const std::vector<double>& m4, const std::vector<double>& msd, std::vector<double>& a,
              std::vector<double>& err) const {
    const int no = info().n_origins, nl = static_cast<int>(info().lag_time.size());
    std::vector<double> table(static_cast<size_t>(no) * 2 * nl);
    for (int k = 0; k < no; ++k)
      for (int j = 0; j < nl; ++j) {
        table[static_cast<size_t>(k) * 2 * nl + j] = m4[static_cast<size_t>(k) * nl + j];
        table[static_cast<size_t>(k) * 2 * nl + nl + j] = msd[static_cast<size_t>(k) * nl + j];
      }
    auto estimate = [nl](const std::vector<double>& v) {
      std::vector<double> r(nl);
      for (int j = 0; j < nl; ++j) r[j] = v[j] / (2 * v[nl + j] * v[nl + j]) - 1;
      return r;
    };
    std::vector<double> mean, e;
    origin_mean(m4, mean, e);
    std::vector<double> m2;
    origin_mean(msd, m2, e);
    a.assign(nl, std::numeric_limits<double>::quiet_NaN());
    for (int j = 0; j < nl; ++j) a[j] = mean[j] / (2 * m2[j] * m2[j]) - 1;
    const int block = an::origin_block(info().lag_time.back(), dynhet::origin_spacing(info()), no);
    err = an::origin_jackknife(table, no, 2 * nl, estimate, block);
    if (err.size() != static_cast<size_t>(nl)) err.assign(nl, std::numeric_limits<double>::quiet_NaN());
  }
  // A per (origin, lag, q) table's mean over origins and its standard
  // error, [q][lag].
  void fs_mean(const std::vector<double>& table, std::vector<double>& mean, std::vector<double>& err) const {
    const size_t nq = fs_q_.size(), nl = info().lag_time.size(), no = info().n_origins;
    mean.assign(nq * nl, std::numeric_limits<double>::quiet_NaN());
    err = mean;
    std::vector<double> v(no * nl), m, e;
    for (size_t q = 0; q < nq; ++q) {
      for (size_t kj = 0; kj < no * nl; ++kj) v[kj] = table[kj * nq + q];
      origin_mean(v, m, e);
      std::copy(m.begin(), m.end(), mean.begin() + q * nl);
      std::copy(e.begin(), e.end(), err.begin() + q * nl);
    }
  }
  // Mean over the origins measured at each lag, and its standard error.
  void origin_mean(const std::vector<double>& v, std::vector<double>& mean, std::vector<double>& err) const {
    const size_t nj = info().lag_time.size();
    mean.assign(nj, std::numeric_limits<double>::quiet_NaN());
    err = mean;
    for (size_t j = 0; j < nj; ++j) {
      dynhet::BlockAverage b;
      for (int k = 0; k < info().n_origins; ++k)
        if (const double x = v[k * nj + j]; !std::isnan(x)) b.add(x);
      if (b.count()) mean[j] = b.mean(), err[j] = b.standard_error();
    }
  }
  void publish_msd(const Measures& s, bool final) {
    std::vector<double> frozen; // the waves' frozen shares (flow_part), for the final log line
    dynhet::msd_t m{};
    stamp(m, final);
    m.cage_relative = s.cage_relative;
    m.lag_time = info().lag_time;
    m.n_lags = static_cast<int32_t>(m.lag_time.size());
    origin_mean(s.msd_all, m.msd_all, m.msd_all_err);
    origin_mean(s.msd_small, m.msd_small, m.msd_small_err);
    // D from Delta = 4 D t + b where the MSD has become diffusive (local
    // log slope within 0.05 of 1 up to the end) or over the last decade of
    // lags, whichever range is longer.
    m.fit_t_max = m.lag_time.back();
    m.fit_t_min = m.fit_t_max / 10;
    if (const double onset = an::diffusive_onset(m.lag_time, m.msd_all); onset < m.fit_t_min) m.fit_t_min = onset;
    m.fraction_all = msd_spec_.fraction_all;
    m.fraction_small = msd_spec_.fraction_small;
    origin_mean(s.msd_extreme[0], m.msd_fast_all, m.msd_fast_all_err);
    origin_mean(s.msd_extreme[1], m.msd_slow_all, m.msd_slow_all_err);
    origin_mean(s.msd_extreme[2], m.msd_fast_small, m.msd_fast_small_err);
    origin_mean(s.msd_extreme[3], m.msd_slow_small, m.msd_slow_small_err);
    alpha2(s.m4_all, s.msd_all, m.alpha2_all, m.alpha2_all_err);
    alpha2(s.m4_small, s.msd_small, m.alpha2_small, m.alpha2_small_err);
    m.fs_q = fs_q_;
    m.n_q = static_cast<int32_t>(fs_q_.size());
    fs_mean(s.fs_all, m.fs_all, m.fs_all_err);
    fs_mean(s.fs_small, m.fs_small, m.fs_small_err);
    m.n_fs = static_cast<int32_t>(m.fs_all.size());
    m.diffusion = m.diffusion_err = m.diffusion_flow = m.diffusion_flow_err = std::numeric_limits<double>::quiet_NaN();
    if (std::isfinite(m.fit_t_min) && m.fit_t_min < m.fit_t_max) {
      // Unweighted over the range, the error from a jackknife over blocks
      // of origins (the lags of one origin are correlated).
      auto fit = [&](const std::vector<double>& msd) {
        const auto d = an::fit_diffusion(m.lag_time, msd, m.fit_t_min, m.fit_t_max);
        return std::vector<double>{d.n >= 3 ? d.d : std::numeric_limits<double>::quiet_NaN()};
      };
      m.diffusion = fit(m.msd_all)[0];
      // D = D_local + D_flow (flow_part). The local part's error: a
      // jackknife over blocks of origins spanning the fit's longest lag
      // (origin_block) of the MSD less the modes' share; the flows'
      // spread, which blocks of one run do not see, added in quadrature.
      // Without the modes (no waves measured), the jackknife of the MSD.
      const int block = an::origin_block(m.fit_t_max, dynhet::origin_spacing(info()), info().n_origins);
      const int nl = static_cast<int>(m.lag_time.size());
      frozen = flow_part(s, m);
      if (std::isfinite(m.diffusion_flow_err)) {
        std::vector<double> local(s.msd_all);
        for (size_t kj = 0; kj < local.size(); ++kj)
          for (size_t q = 0; q < n_modes_; ++q)
            local[kj] -= s.flow_t[kj * n_modes_ + q] + s.flow_l[kj * n_modes_ + q];
        const auto e = an::origin_jackknife(local, info().n_origins, nl, fit, block);
        if (std::isfinite(m.diffusion) && e.size() == 1) m.diffusion_err = std::hypot(e[0], m.diffusion_flow_err);
      } else {
        const auto e = an::origin_jackknife(s.msd_all, info().n_origins, nl, fit, block);
        if (std::isfinite(m.diffusion) && e.size() == 1) m.diffusion_err = e[0];
      }
    }
    out().publish(dynhet::result_channel(dynhet::kChanMsd, s.cage_relative), &m);
    if (final && std::isfinite(m.diffusion_flow)) {
      // The frozen share of the longest waves per |n| (median over the
      // waves; nan: no two origins the last lag apart, all taken as frozen).
      std::vector<int> nx, ny;
      an::wave_vectors(kFlowModes, nx, ny);
      std::string shells;
      for (int r = 1; r <= kFlowModes; ++r) {
        std::vector<double> g;
        for (size_t q = 0; q < n_modes_; ++q)
          if (nx[q] * nx[q] + ny[q] * ny[q] <= r * r && nx[q] * nx[q] + ny[q] * ny[q] > (r - 1) * (r - 1))
            g.push_back(frozen[q]);
        // NaN (no two origins far enough apart) for one wave is NaN for all
        if (std::any_of(g.begin(), g.end(), [](double x) { return std::isnan(x); })) g.assign(1, NAN);
        std::sort(g.begin(), g.end());
        if (!g.empty()) shells += " " + std::to_string(r) + ":" + std::to_string(g[g.size() / 2]).substr(0, 6);
      }
      std::fprintf(stderr,
                   "overlap_node%s: D=%.5g +- %.2g over t in [%.4g, %.4g]; D_flow=%.4g +- %.2g (waves |n| <= %d); "
                   "median frozen share of the transverse waves by |n|:%s\n",
                   s.says(), m.diffusion, m.diffusion_err, m.fit_t_min, m.fit_t_max, m.diffusion_flow, m.diffusion_flow_err,
                   kFlowModes, shells.c_str());
    }
  }
  // D_flow = sum over the modes of c = a quarter of the slope of the mode's
  // share of the MSD over D's fit range, and the spread of D_flow between
  // runs. Measured in a 96-origin run (N = 4096, phi = 0.76,
  // docs/analysis.md "D and the long-lived flows"): a long wave's amplitude
  // u_k . e is a part frozen over the run plus a part that renews within
  // about one window t (its energy decorrelates by d = t). The frozen share
  // f of the wave's energy is the correlation of u_k between origins whose
  // windows do not overlap (d >= t), clipped to [0, 1]; 1 where no two
  // origins are that far apart. The frozen part is one Gaussian sample per
  // run: exponential energy, variance (f c)^2 / 2 estimated; the renewing
  // part a Gamma over the T / t windows of the run: ((1 - f) c)^2 /
  // (1 + T / t).
  // Returns the frozen share f of each wave's transverse part (NaN where
  // not measured), for the log.
  std::vector<double> flow_part(const Measures& s, dynhet::msd_t& m) const {
    std::vector<double> frozen(n_modes_, std::numeric_limits<double>::quiet_NaN());
    if (n_modes_ == 0) return frozen;
    const int no = info().n_origins;
    const double t = m.lag_time.back();
    const double span = (no - 1) * dynhet::origin_spacing(info()) + t;
    std::vector<double> t0(no);
    for (int k = 0; k < no; ++k) t0[k] = info().frame_time[info().origin_frame[k]];
    double sum = 0, var = 0;
    std::vector<double> mean, err;
    for (size_t q = 0; q < n_modes_; ++q)
      for (int part = 0; part < 2; ++part) {
        const std::vector<double>& table = part == 0 ? s.flow_t : s.flow_l;
        std::vector<double> v(m.lag_time.size() * no);
        for (size_t kj = 0; kj < v.size(); ++kj) v[kj] = table[kj * n_modes_ + q];
        origin_mean(v, mean, err);
        const auto d = an::fit_diffusion(m.lag_time, mean, m.fit_t_min, m.fit_t_max);
        if (d.n < 3 || !std::isfinite(d.d)) return frozen;
        // The amplitude's correlation between origins at least t apart.
        double power = 0, cross = 0;
        int n_power = 0, n_cross = 0;
        for (int k = 0; k < no; ++k) {
          const double* a = &s.amp[(static_cast<size_t>(k) * n_modes_ + q) * 4 + 2 * part];
          if (std::isnan(a[0])) continue;
          power += a[0] * a[0] + a[1] * a[1], ++n_power;
          for (int l = k + 1; l < no; ++l) {
            const double* b = &s.amp[(static_cast<size_t>(l) * n_modes_ + q) * 4 + 2 * part];
            if (std::isnan(b[0]) || t0[l] - t0[k] < t * (1 - 1e-9)) continue;
            cross += a[0] * b[0] + a[1] * b[1], ++n_cross; // Re(a conj b)
          }
        }
        const bool measured = n_cross > 0 && power > 0;
        const double f = measured ? std::clamp((cross / n_cross) / (power / n_power), 0.0, 1.0) : 1.0;
        sum += d.d;
        var += std::pow(f * d.d, 2) / 2 + std::pow((1 - f) * d.d, 2) / (1 + span / t);
        if (part == 0 && measured) frozen[q] = f;
      }
    m.diffusion_flow = sum, m.diffusion_flow_err = std::sqrt(var);
    return frozen;
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
      out().publish(dynhet::cutoff_channel(dynhet::kChanChi4, m.cutoff_a, s.cage_relative), &m);
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
    out().publish(dynhet::result_channel(dynhet::kChanDisplacement, s.cage_relative), &m);
  }

  void publish_results(bool final) override {
    if (bonds_) {
      dynhet::bond_breaking_t m = bonds_->message();
      stamp(m, final);
      out().publish(dynhet::kChanBondBreaking, &m);
      if (final)
        std::fprintf(stderr, "overlap_node: bond breaking (a1 = %g, a2 = %g, %.3g bonds per particle): tau_B=%.5g +- %.2g\n",
                     m.a1, m.a2, m.bonds_per_particle, m.tau_b, m.tau_b_err);
    }
    for (Measures& s : sets_) {
      if (want_chi4_) publish_chi4(s, final);
      if (want_msd_) publish_msd(s, final);
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
      m.n_t0 = static_cast<int32_t>(m.t0.size());
      out().publish(dynhet::cutoff_channel(dynhet::kChanOverlap, m.cutoff_a, s.cage_relative), &m);
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
  static constexpr int kFlowModes = 4;       // |n| <= 4: waves of L / 4 and longer
  size_t n_modes_ = 0;
  std::vector<double> d2_, select_;          // |dr|^2 of the pair; the selection's buffer
  std::vector<double> fs_q_, fs_sum_;        // F_s's wave numbers; a pair's sums (all, then small)
  dynhet::Scene::Msd msd_spec_;
  an::DisplacementSpec spec_;
  std::vector<uint8_t> species_;
  std::map<int, std::unique_ptr<an::OriginIndex>> chi4_index_;
  an::DisplacementResult pass_;
};

} // namespace

int main(int argc, char** argv) {
  return dynhet::node_main<OverlapNode>("overlap_node", "dynhet overlap_node: Q(t), tau_alpha from frames on LCM", argc, argv);
}
