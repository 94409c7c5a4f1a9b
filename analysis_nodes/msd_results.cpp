// The overlap node's MSD results (msd_results.hpp).
#include "msd_results.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "dynhet/analysis/fits.hpp"
#include "dynhet/analysis/self_scattering.hpp"
#include "dynhet/analysis/timescales.hpp"
#include "dynhet/model.hpp"
#include "dynhet/stats.hpp"
#include "frame_node.hpp" // origin_spacing

namespace dynhet {

namespace an = analysis;
namespace {
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
}

// The MSD part of one (origin, lag) pair of set s: the instantaneous
// fastest and slowest subsets, <|dr|^4> and F_s, the waves.
void MsdResults::add(Measures& s, int k, int j, const double* pos0, const double* pos, const double* d2,
                     double msd_all) {
  const long n = run_.n_particles;
  const size_t kj = static_cast<size_t>(k) * run_.lag_time.size() + j;
  const auto [all, small] =
      an::msd_extremes_all_small(d2, species_.data(), n, spec_.fraction_all, spec_.fraction_small, select_);
  s.msd_extreme[0][kj] = all.fast, s.msd_extreme[1][kj] = all.slow;
  s.msd_extreme[2][kj] = small.fast, s.msd_extreme[3][kj] = small.slow;
  self_part(s, kj, d2);
  const an::WaveModes w = an::collective_modes(pos0, pos, n, run_.box_length, kFlowModes, msd_all);
  std::copy(w.transverse.begin(), w.transverse.end(), s.flow_t.begin() + kj * n_modes_);
  std::copy(w.longitudinal.begin(), w.longitudinal.end(), s.flow_l.begin() + kj * n_modes_);
  if (j == run_.n_lags - 1) // the amplitudes at the last lag, for the modes' lifetimes
    for (size_t q = 0; q < n_modes_; ++q) {
      double* a = &s.amp[(static_cast<size_t>(k) * n_modes_ + q) * 4];
      a[0] = w.t_re[q], a[1] = w.t_im[q], a[2] = w.l_re[q], a[3] = w.l_im[q];
    }
}

void MsdResults::allocate(Measures& s) const {
  const size_t pairs = static_cast<size_t>(run_.n_origins) * run_.lag_time.size();
  s.m4_all.assign(pairs, kNan);
  s.m4_small = s.m4_all;
  s.fs_all.assign(pairs * fs_q_.size(), kNan);
  s.fs_small = s.fs_all;
  s.flow_t.assign(pairs * n_modes_, kNan);
  s.flow_l = s.flow_t;
  s.amp.assign(static_cast<size_t>(run_.n_origins) * n_modes_ * 4, kNan);
}

MsdResults::MsdResults(const run_info_t& run, const Scene::Msd& spec)
    : run_(run), spec_(spec), species_(species_by_rule(run.n_particles, run.n_small)) {
  std::vector<int> nx, ny;
  an::wave_vectors(kFlowModes, nx, ny);
  n_modes_ = nx.size();
  if (spec_.fs) { // 2 pi / sigma_ab of the species' contact distances
    const double r0 = run.radius[0], r1 = run.radius[1];
    fs_q_ = {2 * M_PI / (2 * r0), 2 * M_PI / (r0 + r1), 2 * M_PI / (2 * r1)};
  }
  fs_q_.insert(fs_q_.end(), spec_.fs_q.begin(), spec_.fs_q.end());
}

// <|dr|^4> and F_s(q) = <J0(q |dr|)> of all and of the small particles
// from the pair's |dr|^2 (one pass: each particle's J0 counts for both).
void MsdResults::self_part(Measures& s, size_t kj, const double* d2) {
  const an::SelfScatteringAllSmall r = an::self_scattering_all_small(d2, species_.data(), run_.n_particles, fs_q_);
  s.m4_all[kj] = r.all.m4, s.m4_small[kj] = r.small.m4;
  const size_t nq = fs_q_.size();
  for (size_t q = 0; q < nq; ++q) s.fs_all[kj * nq + q] = r.all.fs[q], s.fs_small[kj * nq + q] = r.small.fs[q];
}
// alpha_2(t) = <dr^4> / (2 <dr^2>^2) - 1, the means over particles and
// origins; the error from a jackknife over blocks of origins spanning the
// longest lag (the two tables side by side, so that each replicate leaves
// the same origins out of both).
void MsdResults::alpha2(const std::vector<double>& m4, const std::vector<double>& msd, std::vector<double>& a,
            std::vector<double>& err) const {
  const int no = run_.n_origins, nl = static_cast<int>(run_.lag_time.size());
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
  const int block = an::origin_block(run_.lag_time.back(), origin_spacing(run_), no);
  err = an::origin_jackknife(table, no, 2 * nl, estimate, block);
  if (err.size() != static_cast<size_t>(nl)) err.assign(nl, std::numeric_limits<double>::quiet_NaN());
}
// A per (origin, lag, q) table's mean over origins and its standard
// error, [q][lag].
void MsdResults::fs_mean(const std::vector<double>& table, std::vector<double>& mean, std::vector<double>& err) const {
  const size_t nq = fs_q_.size(), nl = run_.lag_time.size(), no = run_.n_origins;
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
void MsdResults::origin_mean(const std::vector<double>& v, std::vector<double>& mean, std::vector<double>& err) const {
  const size_t nj = run_.lag_time.size();
  mean.assign(nj, std::numeric_limits<double>::quiet_NaN());
  err = mean;
  for (size_t j = 0; j < nj; ++j) {
    dynhet::BlockAverage b;
    for (int k = 0; k < run_.n_origins; ++k)
      if (const double x = v[k * nj + j]; !std::isnan(x)) b.add(x);
    if (b.count()) mean[j] = b.mean(), err[j] = b.standard_error();
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
std::vector<double> MsdResults::flow_part(const Measures& s, msd_t& m) const {
  std::vector<double> frozen(n_modes_, std::numeric_limits<double>::quiet_NaN());
  if (n_modes_ == 0) return frozen;
  const int no = run_.n_origins;
  const double t = m.lag_time.back();
  const double span = (no - 1) * origin_spacing(run_) + t;
  std::vector<double> t0(no);
  for (int k = 0; k < no; ++k) t0[k] = run_.frame_time[run_.origin_frame[k]];
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

msd_t MsdResults::message(const Measures& s, std::vector<double>& frozen) const {
  msd_t m{};
  m.cage_relative = s.cage_relative;
  m.lag_time = run_.lag_time;
  m.n_lags = static_cast<int32_t>(m.lag_time.size());
  origin_mean(s.msd_all, m.msd_all, m.msd_all_err);
  origin_mean(s.msd_small, m.msd_small, m.msd_small_err);
  // D from Delta = 4 D t + b where the MSD has become diffusive (local
  // log slope within 0.05 of 1 up to the end) or over the last decade of
  // lags, whichever range is longer.
  m.fit_t_max = m.lag_time.back();
  m.fit_t_min = m.fit_t_max / 10;
  if (const double onset = an::diffusive_onset(m.lag_time, m.msd_all); onset < m.fit_t_min) m.fit_t_min = onset;
  m.fraction_all = spec_.fraction_all;
  m.fraction_small = spec_.fraction_small;
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
    const int block = an::origin_block(m.fit_t_max, origin_spacing(run_), run_.n_origins);
    const int nl = static_cast<int>(m.lag_time.size());
    frozen = flow_part(s, m);
    if (std::isfinite(m.diffusion_flow_err)) {
      std::vector<double> local(s.msd_all);
      for (size_t kj = 0; kj < local.size(); ++kj)
        for (size_t q = 0; q < n_modes_; ++q)
          local[kj] -= s.flow_t[kj * n_modes_ + q] + s.flow_l[kj * n_modes_ + q];
      const auto e = an::origin_jackknife(local, run_.n_origins, nl, fit, block);
      if (std::isfinite(m.diffusion) && e.size() == 1) m.diffusion_err = std::hypot(e[0], m.diffusion_flow_err);
    } else {
      const auto e = an::origin_jackknife(s.msd_all, run_.n_origins, nl, fit, block);
      if (std::isfinite(m.diffusion) && e.size() == 1) m.diffusion_err = e[0];
    }
  }
  return m;
}

void MsdResults::log_flows(const msd_t& m, const std::vector<double>& frozen, const char* says) const {
  if (std::isfinite(m.diffusion_flow)) {
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
                 says, m.diffusion, m.diffusion_err, m.fit_t_min, m.fit_t_max, m.diffusion_flow, m.diffusion_flow_err,
                 kFlowModes, shells.c_str());
  }
}

} // namespace dynhet
