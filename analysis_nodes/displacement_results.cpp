#include "displacement_results.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "dynhet/analysis/timescales.hpp"

namespace dynhet {

namespace an = analysis;

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}

DisplacementResults::DisplacementResults(const run_info_t& run, const Scene::Displacement& scene)
    : run_(run), scene_(scene), blocks_(std::min(scene.error_blocks, run.n_origins)),
      tally_(blocks_, run.n_lags, kSets, scene.bins()) {
  configure(spec_);
  fit_.tail_sigmas = scene.tail_sigmas;
  fit_.min_count = scene.min_bin_count;
  all_.resize(scene.bins());
}

// Bins of bin_width over [-bins w / 2, bins w / 2), bins = round(2 x_max / w):
// symmetric about dx = 0.
void DisplacementResults::configure(an::DisplacementSpec& spec) const {
  spec.hist_bins = scene_.bins();
  spec.hist_width = scene_.bin_width;
  spec.hist_lo = -0.5 * spec.hist_bins * spec.hist_width;
}

void DisplacementResults::add(int origin, int lag, const an::DisplacementResult& pass, long n_small) {
  // Blocks of consecutive origins, as the clusters node cuts them.
  const int block = static_cast<int>(static_cast<long>(origin) * blocks_ / run_.n_origins);
  for (size_t b = 0; b < all_.size(); ++b) all_[b] = pass.hist[0][b] + pass.hist[1][b];
  tally_.add(block, lag, kAll, all_.data(), run_.n_particles);
  tally_.add(block, lag, kSmall, pass.hist[0].data(), n_small);
}

displacement_t DisplacementResults::message(double tau_alpha, double cutoff_a) const {
  displacement_t m{};
  m.tau_alpha = tau_alpha;
  m.cutoff_a = cutoff_a;
  m.n_blocks = blocks_;
  m.tail_sigmas = fit_.tail_sigmas;
  m.min_bin_count = static_cast<int32_t>(fit_.min_count);
  m.n_bins = spec_.hist_bins;
  m.bin_width = spec_.hist_width;
  for (int b = 0; b < m.n_bins; ++b) m.x.push_back(spec_.hist_lo + (b + 0.5) * spec_.hist_width);
  for (double k : scene_.lags_tau_alpha) m.target_tau_alpha.push_back(k), m.target_time.push_back(k * tau_alpha);
  for (double t : scene_.lags) m.target_tau_alpha.push_back(kNaN), m.target_time.push_back(t);
  m.n_targets = static_cast<int32_t>(m.target_time.size());
  for (double t : m.target_time) {
    const int j = std::isfinite(t) ? an::nearest_lag(run_.lag_time, t) : -1;
    m.lag_index.push_back(j);
    m.lag_time.push_back(j >= 0 ? run_.lag_time[j] : kNaN);
  }
  m.n_sets = kSets;
  m.n_series = m.n_sets * m.n_targets;
  m.gauss_d_small_tau_alpha = m.tail_x0_small_tau_alpha = kNaN;
  for (int s = 0; s < kSets; ++s)
    for (int l = 0; l < m.n_targets; ++l) {
      const int j = m.lag_index[l];
      an::DistributionEstimate e;
      if (j >= 0) e = tally_.estimate(spec_, j, s, run_.lag_time[j], fit_);
      if (j < 0 || e.pairs == 0) { // nothing yet: NaN of the right shape
        e.p.assign(m.n_bins, kNaN), e.p_err = e.p, e.count.assign(m.n_bins, 0);
        e.fit = {kNaN, kNaN, kNaN, kNaN, kNaN, 0, 0}, e.gauss_d_err = e.tail_x0_err = kNaN;
      }
      long inside = 0;
      for (long c : e.count) inside += c;
      m.n_pairs.push_back(static_cast<int32_t>(e.pairs));
      m.samples.push_back(e.samples);
      m.fraction_outside.push_back(e.samples > 0 ? double(e.samples - inside) / e.samples : kNaN);
      m.p.insert(m.p.end(), e.p.begin(), e.p.end());
      m.p_err.insert(m.p_err.end(), e.p_err.begin(), e.p_err.end());
      m.count.insert(m.count.end(), e.count.begin(), e.count.end());
      m.gauss_d.push_back(e.fit.gauss_d), m.gauss_d_err.push_back(e.gauss_d_err);
      m.gauss_bins.push_back(e.fit.gauss_bins);
      m.tail_x0.push_back(e.fit.tail_x0), m.tail_x0_err.push_back(e.tail_x0_err);
      m.tail_amplitude.push_back(e.fit.tail_amplitude);
      m.tail_x_min.push_back(e.fit.tail_x_min), m.tail_x_max.push_back(e.fit.tail_x_max);
      m.tail_bins.push_back(e.fit.tail_bins);
      if (s == kSmall && l < static_cast<int>(scene_.lags_tau_alpha.size()) && scene_.lags_tau_alpha[l] == 1.0)
        m.gauss_d_small_tau_alpha = e.fit.gauss_d, m.tail_x0_small_tau_alpha = e.fit.tail_x0;
    }
  m.n_values = static_cast<int32_t>(m.p.size());
  return m;
}

} // namespace dynhet
