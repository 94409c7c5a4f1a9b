#include "dynhet/analysis/displacement_distribution.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "dynhet/analysis/fits.hpp"

namespace dynhet::analysis {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}

DistributionFit fit_distribution(const DisplacementSpec& spec, const std::vector<long>& count, long samples,
                                 double t, const DistributionFitSpec& fit) {
  DistributionFit out{kNaN, kNaN, kNaN, kNaN, kNaN, 0, 0};
  const DisplacementDensity d = displacement_density(spec, count, samples);
  // The bins both fits may use, and <dx^2> of the counted displacements.
  std::vector<double> x, p;
  std::vector<long> c;
  double inside = 0, dx2 = 0;
  for (size_t b = 0; b < d.x.size(); ++b) {
    inside += count[b], dx2 += count[b] * d.x[b] * d.x[b];
    if (count[b] >= fit.min_count) x.push_back(d.x[b]), p.push_back(d.p[b]), c.push_back(count[b]);
  }
  if (x.size() >= 3) {
    const GaussianFit g = fit_gaussian_displacement(x, p, c, t);
    out.gauss_d = g.d, out.gauss_bins = g.n;
  }
  if (inside <= 0) return out;
  out.tail_x_min = fit.tail_sigmas * std::sqrt(dx2 / inside);
  std::vector<double> tx, tp;
  std::vector<long> tc;
  double x_max = 0;
  for (size_t k = 0; k < x.size(); ++k)
    if (std::abs(x[k]) >= out.tail_x_min)
      tx.push_back(x[k]), tp.push_back(p[k]), tc.push_back(c[k]), x_max = std::max(x_max, std::abs(x[k]));
  if (tx.size() >= 3) {
    // A tail whose slope in ln P is not negative by more than its own
    // (Poisson) standard error does not decay: no x0 (NaN), not a huge one.
    const ExpTailFit e = fit_exponential_tail(tx, tp, tc, out.tail_x_min);
    if (e.x0 > 0 && e.x0_err < e.x0)
      out.tail_x0 = e.x0, out.tail_amplitude = e.amplitude, out.tail_bins = e.n, out.tail_x_max = x_max;
  }
  return out;
}

DisplacementTally::DisplacementTally(int blocks, int lags, int sets, int bins)
    : blocks_(blocks), lags_(lags), sets_(sets), bins_(bins), cell_(size_t(blocks) * lags * sets) {
  if (blocks < 1 || lags < 0 || sets < 1 || bins < 1) throw std::invalid_argument("DisplacementTally: bad sizes");
  for (Cell& c : cell_) c.count.assign(bins, 0);
}

void DisplacementTally::add(int block, int lag, int set, const long* count, long samples) {
  Cell& c = cell_[(size_t(block) * lags_ + lag) * sets_ + set];
  for (int b = 0; b < bins_; ++b) c.count[b] += count[b];
  c.samples += samples;
  ++c.pairs;
}

long DisplacementTally::pairs(int lag) const {
  long n = 0;
  for (int k = 0; k < blocks_; ++k) n += at(k, lag, 0).pairs;
  return n;
}

DistributionEstimate DisplacementTally::estimate(const DisplacementSpec& spec, int lag, int set, double t,
                                                 const DistributionFitSpec& fit) const {
  // The pooled counts, and those of all blocks but one for every block with data.
  DistributionEstimate e;
  e.count.assign(bins_, 0);
  std::vector<int> with_data;
  for (int k = 0; k < blocks_; ++k) {
    const Cell& c = at(k, lag, set);
    for (int b = 0; b < bins_; ++b) e.count[b] += c.count[b];
    e.samples += c.samples, e.pairs += c.pairs;
    if (c.pairs > 0) with_data.push_back(k);
  }
  const DisplacementDensity pooled = displacement_density(spec, e.count, e.samples);
  e.x = pooled.x, e.p = pooled.p;
  e.fit = fit_distribution(spec, e.count, e.samples, t, fit);
  std::vector<std::vector<double>> p_loo(bins_);
  std::vector<double> d_loo, x0_loo;
  for (int skip : with_data) {
    const Cell& c = at(skip, lag, set);
    std::vector<long> count(bins_);
    for (int b = 0; b < bins_; ++b) count[b] = e.count[b] - c.count[b];
    const long samples = e.samples - c.samples;
    const DisplacementDensity d = displacement_density(spec, count, samples);
    for (int b = 0; b < bins_; ++b) p_loo[b].push_back(d.p[b]);
    const DistributionFit f = fit_distribution(spec, count, samples, t, fit);
    d_loo.push_back(f.gauss_d), x0_loo.push_back(f.tail_x0);
  }
  e.p_err.resize(bins_);
  for (int b = 0; b < bins_; ++b) e.p_err[b] = jackknife_error(p_loo[b]);
  e.gauss_d_err = jackknife_error(d_loo);
  e.tail_x0_err = jackknife_error(x0_loo);
  return e;
}

} // namespace dynhet::analysis
