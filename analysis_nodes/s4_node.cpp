// s4_node: the four-point structure factor S4(q,t) (paper eqs. 15-16) and
// the correlation length xi, live from the frames on DYNHET_FRAME, published
// on DYNHET_S4_<a> (one channel per cutoff a) at most once a second and at
// the end.
//
// For each (origin, lag) pair it uses, the node computes the displacements
// |r_i(t0+t) - r_i(t0)|^2 once, and for every cutoff a of the scene weighs
// every particle by w_i = theta(a - |dr_i|) and computes W_r(q) on every
// sub-box grid (the [s4] sizes, by default chi4's, and always the whole
// box) by the Gaussian NUFFT on FFTW grids (kernels/s4.cpp), then S4 per |q|
// shell: one pass over the frames for all cutoffs. The grids (FFTW plans
// and buffers) are shared by the cutoffs: only the weights and the
// transforms are per cutoff, so the cost per pair is the number of cutoffs
// times that of one. One message per cutoff (cutoff_a says which). Lags: every scheduled lag by
// default (the grid costs a few ms per pair at N = 10^4, so S4(q,t) and
// xi(t) come at every t; xi(t) and chi0(t) with errors from a jackknife
// over blocks of origins spanning each lag), or the scheduled lags nearest the times in
// s4.lags (to bound the cost at N = 10^5, ~70 ms per pair for six grids).
// The fits with jackknife errors and the chi4 comparison are made, per
// cutoff, at t_s4 = that cutoff's running tau_alpha of the node's own (Q(t)
// from the same weights, W(q = 0) of the whole box; the paper evaluates S4
// at tau_alpha): S4 per origin interpolated linearly in ln t between the two
// computed lags that bracket tau_alpha, the interpolation error (quadratic
// through a third lag minus linear) in quadrature with the jackknife's. At
// the computed lag nearest tau_alpha where it is not bracketed or the scene
// lists s4.lags; before Q(t) crosses 1/e, at the last lag with data.
//
// Memory: the origin frames some later used lag still needs, 16 N bytes
// each: at most (largest used lag) / origin_spacing + 1 of them; the S4
// shells of every (cutoff, origin, lag, grid), a few hundred doubles per
// pair and cutoff; and the FFT grids, 16 (L/h)^2 bytes per grid (h the grid
// spacing), one set for all cutoffs.
//
// With [observables] cage_relative, every cutoff again with the weights of
// the cage-relative displacements, w_i = theta(a - |dr_i^CR|) (Voronoi cages
// of the origin frame, as the overlap node's), on DYNHET_S4_CR_<a>, its
// t_s4 the cage-relative tau_alpha; positions are those at t0 both ways.
//
// Usage: s4_node [--lcm-url URL] [--publish-url URL] (as overlap_node)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <string>

#include "dynhet/analysis/cage.hpp"
#include "dynhet/analysis/displacement.hpp"
#include "dynhet/analysis/lag_interpolation.hpp"
#include "dynhet/analysis/overlap.hpp"
#include "dynhet/analysis/s4.hpp"
#include "dynhet/analysis/s4_average.hpp"
#include "dynhet/analysis/timescales.hpp"
#include "dynhet/s4_t.hpp"
#include "dynhet/scene.hpp"
#include "cages.hpp"
#include "frame_node.hpp"

namespace {

namespace an = dynhet::analysis;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kQxiMax = 1.0; // fits over q xi <= 1, as the paper's small-q OZ regime

// The sub-box grids of S4: the listed sizes, nested as chi4's (so that S4
// at q = 0 is chi4 of the same grid), each side once, fine to coarse, and
// the whole box.
std::vector<an::SubboxGrid> s4_grids(long n, double box, const std::vector<int>& sizes) {
  std::vector<an::SubboxGrid> g = an::nested_subbox_grids(n, box, sizes);
  g.push_back(an::SubboxGrid{1, box, double(n)});
  std::sort(g.begin(), g.end(), [](const auto& a, const auto& b) { return a.per_side > b.per_side; });
  g.erase(std::unique(g.begin(), g.end(), [](const auto& a, const auto& b) { return a.per_side == b.per_side; }),
          g.end());
  return g;
}

class S4Node : public dynhet::FrameNode {
public:
  S4Node(lcm::LCM& out, int64_t run_filter) : FrameNode(out, run_filter, "s4") {}

private:
  void start(const dynhet::run_info_t& m) override {
    const dynhet::Scene scene = dynhet::parse_scene_text(m.scene_toml, "the run's scene");
    q_max_ = scene.s4_q_max;
    origin_spacing_ = dynhet::origin_spacing(m);
    const std::vector<int> sizes = scene.s4_subbox_particles.empty()
                                       ? std::vector<int>(m.chi4_subbox_particles.begin(), m.chi4_subbox_particles.end())
                                       : scene.s4_subbox_particles;
    // The lags used: all, or the scheduled ones nearest the listed times.
    slot_.assign(m.n_lags, -1);
    for (int j = 0; j < m.n_lags; ++j)
      if (scene.s4_lags.empty()) slot_[j] = 0;
    for (double t : scene.s4_lags) slot_[an::nearest_lag(m.lag_time, t)] = 0;
    interpolate_ = scene.s4_lags.empty(); // listed lags: results at the one nearest tau_alpha
    for (int j = 0; j < m.n_lags; ++j)
      if (slot_[j] == 0) slot_[j] = static_cast<int>(lags_.size()), lags_.push_back(m.lag_time[j]);
    cage_ = std::find(m.observables.begin(), m.observables.end(), "s4_cr") != m.observables.end();
    if (cage_) cages_ = std::make_unique<dynhet::Cages>(m, scene, "s4_node");
    for (bool cr : {false, true})
      if (!cr || cage_)
        for (double a : m.cutoff_a)
          cuts_.push_back(Cutoff{a, cr, {}, std::make_unique<an::OverlapAccumulator>(m.n_origins, m.lag_time)});
    const std::vector<double> none;
    for (const an::SubboxGrid& g : s4_grids(m.n_particles, m.box_length, sizes)) {
      grids_.push_back(g);
      fft_.push_back(std::make_unique<an::S4Grid>(g, q_max_, an::S4GridParams{scene.s4_grid_spacing, scene.s4_half_width, false}));
      // The shells of this grid (from zero weights: only q and the vector counts matter).
      const an::S4Shells shells = an::s4_shells(fft_.back()->modes(none.data(), none.data(), 0));
      for (Cutoff& c : cuts_) c.acc.emplace_back(m.n_origins, static_cast<int>(lags_.size()), shells.q, shells.n_vectors);
    }
    std::fprintf(stderr, "s4_node: a =");
    for (const Cutoff& c : cuts_) std::fprintf(stderr, " %g%s", c.a, c.cr ? " (cage-relative)" : "");
    std::fprintf(stderr, ", q <= %g, %zu of %d lags, grids (m: points):", q_max_, lags_.size(), m.n_lags);
    for (size_t g = 0; g < grids_.size(); ++g) std::fprintf(stderr, " %d: %d", grids_[g].per_side, fft_[g]->points());
    std::fprintf(stderr, "\n");
  }

  bool uses_lag(int j) const override { return slot_[j] >= 0; }

  // Checkpoints: S4 per (origin, lag) on every grid and Q(t;t0), per cutoff.
  void save_state(dynhet::StateOut& out) override {
    for (Cutoff& c : cuts_) out(c.acc, *c.q_acc);
    if (cages_) out(*cages_);
  }
  void load_state(dynhet::StateIn& in) override {
    for (Cutoff& c : cuts_) in(c.acc, *c.q_acc);
    if (cages_) in(*cages_);
    if (cage_) // the cages of the held origins, rebuilt from their positions
      for (const auto& [k, pos0] : held_origins()) on_origin(k, pos0);
  }
  void on_origin(int k, const std::vector<double>& pos0) override {
    if (cage_) cages_->build(k, pos0);
  }
  void on_origin_dropped(int k) override {
    if (cage_) cages_->drop(k);
  }

  void on_pair(int k, int j, const std::vector<double>& pos0, const dynhet::Frame& f) override {
    const long n = info().n_particles;
    d2_.resize(n);
    for (long i = 0; i < n; ++i)
      d2_[i] = std::pow(f.position[2 * i] - pos0[2 * i], 2) + std::pow(f.position[2 * i + 1] - pos0[2 * i + 1], 2);
    if (cage_) { // |dr^CR|^2, from the positions pos0 + dr^CR
      pos_cr_.resize(2 * n), d2_cr_.resize(n);
      an::cage_relative_positions(pos0.data(), f.position.data(), cages_->at(k), dr_, pos_cr_.data());
      for (long i = 0; i < n; ++i)
        d2_cr_[i] = std::pow(pos_cr_[2 * i] - pos0[2 * i], 2) + std::pow(pos_cr_[2 * i + 1] - pos0[2 * i + 1], 2);
    }
    // Per cutoff: the weights and the transforms, on the grids (plans and
    // buffers) all cutoffs share; d2 is the same for every cutoff.
    for (Cutoff& c : cuts_) {
      an::overlap_weights((c.cr ? d2_cr_ : d2_).data(), n, c.a, w_); // w_i = theta(a - |dr_i|)
      const double q = std::accumulate(w_.begin(), w_.end(), 0.0) / n; // Q(t;t0) = W(0) of the whole box
      c.q_acc->add(k, j, &q, 1);
      for (size_t g = 0; g < grids_.size(); ++g)
        c.acc[g].add(k, slot_[j], an::s4_shells(fft_[g]->modes(pos0.data(), w_.data(), n)));
    }
  }

  // What the node keeps per cutoff a: S4 per grid and Q(t;t0) of the whole box.
  struct Cutoff {
    double a;
    bool cr; // of the cage-relative displacements
    std::vector<an::S4Accumulator> acc;            // per grid
    std::unique_ptr<an::OverlapAccumulator> q_acc; // Q(t;t0) of the whole box, for tau_alpha and chi4
  };

  // The computed lags bracketing tau_alpha, both with data (not ok(): not
  // bracketed, or the scene lists the lags).
  an::LagBracket bracket(const Cutoff& c, double tau_alpha) const {
    if (!interpolate_) return {};
    return an::bracket_lag(lags_, tau_alpha, [&](int l) {
      for (int k = 0; k < info().n_origins; ++k)
        if (c.acc[0].has(k, l)) return true;
      return false;
    });
  }

  // The computed lag nearest tau_alpha (in ln t), else the last one with data.
  int fit_slot(const Cutoff& c, double tau_alpha) const {
    if (std::isfinite(tau_alpha)) return an::nearest_lag(lags_, tau_alpha);
    for (int l = static_cast<int>(lags_.size()) - 1; l >= 0; --l)
      if (c.acc[0].mean(l).n_origins > 0) return l;
    return 0;
  }

  void publish_results(bool final) override {
    // Fits with jackknife errors cost tens of ms per cutoff (at every lag
    // and grid, one fit per block of origins: ~0.3 ms per lag and grid with
    // 20 origins): at most once a second, and at most a tenth of the
    // node's time (with many cutoffs a message set can take a second).
    const auto since = Clock::now() - last_publish_;
    if (!final && (since < std::chrono::seconds(1) || since < 9 * publish_cost_)) return;
    last_publish_ = Clock::now();
    for (const Cutoff& c : cuts_) publish_cutoff(c, final);
    publish_cost_ = Clock::now() - last_publish_;
  }

  // One message: cutoff c's S4, fits and chi4.
  void publish_cutoff(const Cutoff& c, bool final) {
    dynhet::s4_t m{};
    stamp(m, final);
    m.cage_relative = c.cr;
    m.cutoff_a = c.a, m.q_max = q_max_, m.qxi_max = kQxiMax;
    m.tau_alpha = c.q_acc->result().tau_alpha;
    const int l = fit_slot(c, m.tau_alpha);
    const an::LagBracket b = bracket(c, m.tau_alpha);
    m.lag_index = l, m.t_s4 = b.ok() ? m.tau_alpha : lags_[l];
    m.lag_lo = b.ok() ? b.lo : -1, m.lag_hi = b.ok() ? b.hi : -1, m.lag_weight = b.ok() ? b.w : kNaN;
    m.lag_third = b.ok() ? b.third : -1;
    m.lag_time = lags_;
    std::vector<std::string> notes;
    for (size_t g = 0; g < grids_.size(); ++g) add_grid(m, c, g, l, b, notes);
    const size_t whole = grids_.size() - 1;
    m.xi = m.oz_xi[whole], m.xi_err = m.oz_xi_err[whole], m.chi0 = m.oz_chi0[whole], m.chi0_err = m.oz_chi0_err[whole];
    m.chi4_box = m.chi4[whole], m.chi4_box_err = m.chi4_err[whole];
    // S4(q) and the OZ fit at every computed lag.
    for (size_t t = 0; t < lags_.size(); ++t)
      for (size_t g = 0; g < grids_.size(); ++g) {
        const std::vector<double> s4 = c.acc[g].mean(static_cast<int>(t)).s4;
        m.s4_lag.insert(m.s4_lag.end(), s4.begin(), s4.end());
        // One rule for xi wherever it is reported: the fit at each lag
        // gives no xi where the whole box's fit at t_s4 would give none
        // (but for the error rule: xi(t) is drawn with its error bar).
        const an::S4LagFit f = an::fit_s4_lag(c.acc[g], static_cast<int>(t), lags_[t], origin_spacing_, kQxiMax);
        m.xi_lag.push_back(f.oz.xi), m.chi0_lag.push_back(f.oz.chi0);
        m.xi_lag_err.push_back(f.oz.xi_err), m.chi0_lag_err.push_back(f.oz.chi0_err);
        m.xi_lag_rule.push_back(static_cast<int8_t>(f.rule));
      }
    m.n_grids = static_cast<int32_t>(grids_.size());
    m.scan_qxi_max = an::kOzRangeScan;
    m.n_scan = static_cast<int32_t>(m.scan_qxi_max.size());
    m.n_scan_values = static_cast<int32_t>(m.scan_oz_xi.size());
    m.n_values = static_cast<int32_t>(m.q.size());
    m.n_lags = static_cast<int32_t>(lags_.size());
    m.n_lag_values = static_cast<int32_t>(m.s4_lag.size());
    m.n_lag_fits = static_cast<int32_t>(m.xi_lag.size());
    const char* cr = c.cr ? " (cage-relative)" : "";
    if (publish(dynhet::cutoff_channel(dynhet::kChanS4, m.cutoff_a, c.cr), m) != 0)
      std::fprintf(stderr, "s4_node: could not publish S4 (%d bytes)\n", m.getEncodedSize());
    if (final)
      std::fprintf(stderr, "s4_node%s: a=%g t_s4=%.4g (tau_alpha %.4g; %s), whole box xi=%.4g +- %.2g chi0=%.4g +- %.2g, chi4=%.4g +- %.2g (%d origins)\n",
                   cr, m.cutoff_a, m.t_s4, m.tau_alpha,
                   m.lag_lo >= 0 ? "interpolated between two lags" : "the lag nearest", m.xi, m.xi_err, m.chi0, m.chi0_err, m.chi4_box, m.chi4_box_err, m.n_origins);
    if (final)
      for (const auto& n : notes) std::fprintf(stderr, "s4_node%s: a=%g %s\n", cr, m.cutoff_a, n.c_str());
    if (final) {
      // The whole box's xi against the fit range (q xi <= 0.5 .. 2).
      std::string xs;
      for (int r = 0; r < m.n_scan; ++r) {
        char buf[48];
        std::snprintf(buf, sizeof buf, " %g:%.4g", m.scan_qxi_max[r], m.scan_oz_xi[whole * m.n_scan + r]);
        xs += buf;
      }
      const std::vector<double> v(m.scan_oz_xi.begin() + whole * m.n_scan, m.scan_oz_xi.begin() + (whole + 1) * m.n_scan);
      std::fprintf(stderr, "s4_node%s: a=%g whole box OZ xi by fit range (q xi <=):%s; half their range %.2g against the error %.2g\n",
                   cr, m.cutoff_a, xs.c_str(), an::half_range(v), m.xi_err);
    }
  }

  // Q(t;t0) of cutoff c per origin at computed lag l.
  std::vector<double> q_per_origin(const Cutoff& c, int l) const {
    const int j = static_cast<int>(std::find(slot_.begin(), slot_.end(), l) - slot_.begin());
    std::vector<double> q(info().n_origins);
    for (int k = 0; k < info().n_origins; ++k) q[k] = c.q_acc->q(k, j);
    return q;
  }

  // Grid g's shells, fits and chi4 of cutoff c at t_s4: interpolated
  // between the lags of b if b.ok(), else at computed lag l.
  void add_grid(dynhet::s4_t& m, const Cutoff& c, size_t g, int l, const an::LagBracket& b,
                std::vector<std::string>& notes) const {
    const an::S4Accumulator& a = c.acc[g];
    const an::S4AtTime at = b.ok() ? an::fit_s4_at_time(a, b, kQxiMax) : an::S4AtTime{a.mean(l), an::fit_s4_at_lag(a, l, kQxiMax)};
    const an::S4Accumulator::Mean& mean = at.mean;
    if (g + 1 == grids_.size()) m.n_origins = mean.n_origins;
    m.subbox_particles.push_back(grids_[g].mean_particles);
    m.subbox_per_side.push_back(grids_[g].per_side);
    m.grid_spacing.push_back(fft_[g]->spacing());
    m.grid_points.push_back(fft_[g]->points());
    m.n_shells.push_back(static_cast<int32_t>(a.q().size()));
    m.q.insert(m.q.end(), a.q().begin(), a.q().end());
    m.shell_vectors.insert(m.shell_vectors.end(), a.n_vectors().begin(), a.n_vectors().end());
    m.s4.insert(m.s4.end(), mean.s4.begin(), mean.s4.end());
    m.s4_err.insert(m.s4_err.end(), mean.s4_err.begin(), mean.s4_err.end());
    const an::S4FitAtLag& f = at.fit;
    for (const auto* o : {&f.oz, &f.oz_a2})
      if (!o->note.empty())
        notes.push_back("N_box " + std::to_string(static_cast<long>(grids_[g].mean_particles + 0.5)) + ": xi of the " +
                        (o == &f.oz ? "OZ" : "OZ + A^2") + " fit not determined (" + o->note + ")");
    const an::OzRangeScan scan = an::scan_oz_range(a.q(), mean.s4);
    m.scan_oz_xi.insert(m.scan_oz_xi.end(), scan.xi.begin(), scan.xi.end());
    m.scan_oz_chi0.insert(m.scan_oz_chi0.end(), scan.chi0.begin(), scan.chi0.end());
    m.scan_a2_xi.insert(m.scan_a2_xi.end(), scan.xi_a2.begin(), scan.xi_a2.end());
    m.scan_a2_chi0.insert(m.scan_a2_chi0.end(), scan.chi0_a2.begin(), scan.chi0_a2.end());
    m.oz_chi0.push_back(f.oz.chi0), m.oz_chi0_err.push_back(f.oz.chi0_err);
    m.oz_xi.push_back(f.oz.xi), m.oz_xi_err.push_back(f.oz.xi_err);
    m.oz_q_fit_max.push_back(f.oz.q_fit_max), m.oz_n_fit.push_back(f.oz.n);
    m.a2_chi0.push_back(f.oz_a2.chi0), m.a2_chi0_err.push_back(f.oz_a2.chi0_err);
    m.a2_xi.push_back(f.oz_a2.xi), m.a2_xi_err.push_back(f.oz_a2.xi_err);
    m.a2_a.push_back(f.oz_a2.a), m.a2_a_err.push_back(f.oz_a2.a_err);
    m.a2_q_fit_max.push_back(f.oz_a2.q_fit_max), m.a2_n_fit.push_back(f.oz_a2.n);
    // chi4 at the same t: S4 at q = 0 is eq. (14) for sub-boxes (W_r(0) = Q_r);
    // the whole box has no q = 0 shell: N_tot var(Q) over origins.
    if (grids_[g].per_side > 1) {
      m.chi4.push_back(mean.s4[0]), m.chi4_err.push_back(mean.s4_err[0]);
    } else {
      const double n = static_cast<double>(info().n_particles);
      const an::ValueErr x = b.ok() ? an::whole_box_chi4_at_time(q_per_origin(c, b.lo), q_per_origin(c, b.hi),
                                                                 b.third >= 0 ? q_per_origin(c, b.third) : std::vector<double>{}, b, n)
                                    : an::whole_box_chi4(q_per_origin(c, l), n);
      m.chi4.push_back(x.value), m.chi4_err.push_back(x.err);
    }
  }

  double q_max_ = 1;
  double origin_spacing_ = 0; // the time between origins: the per-lag jackknife's blocks span the lag
  bool interpolate_ = true;   // at tau_alpha between computed lags (false: the scene lists s4.lags)
  std::vector<int> slot_;     // per scheduled lag: index among the computed lags, or -1
  std::vector<double> lags_;  // the computed lags
  std::vector<an::SubboxGrid> grids_;
  std::vector<std::unique_ptr<an::S4Grid>> fft_; // per grid, shared by the cutoffs
  std::vector<Cutoff> cuts_;                     // per cutoff of the scene, in its order
  std::vector<double> d2_, w_;                   // per pair, reused (w_: one cutoff at a time)
  bool cage_ = false;                            // also the cage-relative cutoffs (s4_cr)
  std::unique_ptr<dynhet::Cages> cages_;         // the cages of the held origins (cage_)
  std::vector<double> dr_, pos_cr_, d2_cr_;      // per pair, reused: the cage-relative |dr|^2
  Clock::time_point last_publish_{};
  Clock::duration publish_cost_{}; // how long the last set of messages took
};

} // namespace

int main(int argc, char** argv) {
  return dynhet::node_main<S4Node>("s4_node", "dynhet s4_node: S4(q,t), xi and chi0 from frames on LCM", argc, argv);
}
