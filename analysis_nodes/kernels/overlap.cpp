#include "dynhet/analysis/overlap.hpp"

#include "dynhet/analysis/fits.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dynhet::analysis {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}

SubboxGrid make_subbox_grid(long n_total, double box, int target_particles) {
  const int m = std::max(1, static_cast<int>(std::lround(std::sqrt(double(n_total) / target_particles))));
  return SubboxGrid{m, box, double(n_total) / (double(m) * m)};
}

void overlap_subboxes(const double* pos0, const double* pos_t, long n, const SubboxGrid& g,
                      const std::vector<double>& cutoffs, std::vector<double>& q_r) {
  const int m = g.per_side, nb = m * m, nc = static_cast<int>(cutoffs.size());
  q_r.assign(static_cast<size_t>(nc) * nb, 0.0);
  std::vector<double> a2(nc);
  for (int c = 0; c < nc; ++c) a2[c] = cutoffs[c] * cutoffs[c];
  const double width = g.box / m;
  for (long i = 0; i < n; ++i) {
    const double x0 = pos0[2 * i], y0 = pos0[2 * i + 1];
    const double dx = pos_t[2 * i] - x0, dy = pos_t[2 * i + 1] - y0;
    const double d2 = dx * dx + dy * dy;
    // Sub-box of the position at t0, folded into [0, box).
    const double fx = x0 - g.box * std::floor(x0 / g.box), fy = y0 - g.box * std::floor(y0 / g.box);
    const int bx = std::min(m - 1, static_cast<int>(fx / width));
    const int by = std::min(m - 1, static_cast<int>(fy / width));
    const int r = by * m + bx;
    for (int c = 0; c < nc; ++c)
      if (d2 < a2[c]) q_r[static_cast<size_t>(c) * nb + r] += 1.0; // theta(a - |dr|)
  }
  for (double& v : q_r) v /= g.mean_particles; // 1/N with N = <N_r>
}

double crossing_time(const std::vector<double>& t, const std::vector<double>& q, double level) {
  int prev = -1;
  for (size_t j = 0; j < q.size(); ++j) {
    if (std::isnan(q[j])) continue;
    if (q[j] < level) {
      if (prev < 0) return kNaN; // already below at the first lag: not bracketed
      const double f = (q[prev] - level) / (q[prev] - q[j]);
      return std::exp(std::log(t[prev]) + f * (std::log(t[j]) - std::log(t[prev])));
    }
    prev = static_cast<int>(j);
  }
  return kNaN;
}

OverlapAccumulator::OverlapAccumulator(int n_origins, std::vector<double> lag_time, double origin_spacing)
    : n_origins_(n_origins), lag_(std::move(lag_time)), spacing_(origin_spacing),
      q_(static_cast<size_t>(n_origins) * lag_.size(), kNaN),
      var_(static_cast<size_t>(n_origins) * lag_.size(), kNaN) {}

void OverlapAccumulator::add(int k, int j, const double* q_r, int nb) {
  double s = 0, s2 = 0;
  for (int r = 0; r < nb; ++r) s += q_r[r], s2 += q_r[r] * q_r[r];
  const double mean = s / nb;
  q_[index(k, j)] = mean;              // eq. (6): Q(t;t0) = <Q_r(t;t0)>
  var_[index(k, j)] = s2 / nb - mean * mean; // <Q_r^2> - <Q_r>^2
}

// Q(t) averaged over the origins measured at each lag, leaving out origin
// `skip` (-1: none).
std::vector<double> OverlapAccumulator::mean_over_origins(int skip) const {
  std::vector<double> q(lag_.size(), kNaN);
  for (size_t j = 0; j < lag_.size(); ++j) {
    double s = 0;
    int n = 0;
    for (int k = 0; k < n_origins_; ++k) {
      const double v = q_[index(k, static_cast<int>(j))];
      if (k == skip || std::isnan(v)) continue;
      s += v;
      ++n;
    }
    if (n > 0) q[j] = s / n;
  }
  return q;
}

OverlapAccumulator::Result OverlapAccumulator::result() const {
  const size_t nj = lag_.size();
  Result r;
  r.q = mean_over_origins(-1);
  r.q_err.assign(nj, kNaN);
  r.qr_var.assign(nj, kNaN);
  r.n_origins.assign(nj, 0);
  for (size_t j = 0; j < nj; ++j) {
    double s2 = 0, sv = 0;
    int n = 0;
    for (int k = 0; k < n_origins_; ++k) {
      const double v = q_[index(k, static_cast<int>(j))];
      if (std::isnan(v)) continue;
      s2 += (v - r.q[j]) * (v - r.q[j]);
      sv += var_[index(k, static_cast<int>(j))];
      ++n;
    }
    r.n_origins[j] = n;
    if (n > 0) r.qr_var[j] = sv / n;
    if (n > 1) r.q_err[j] = std::sqrt(s2 / (n - 1) / n); // standard error of the mean
  }
  const double level = std::exp(-1.0); // Q(tau_alpha) = 1/e
  r.tau_alpha = crossing_time(lag_, r.q, level);

  // Jackknife over blocks of the origins that contributed, each block
  // spanning the lag just beyond the crossing (the longest one it reads).
  double longest = kNaN;
  for (double t : lag_)
    if (t >= r.tau_alpha) {
      longest = t;
      break;
    }
  const auto e = origin_jackknife(q_, n_origins_, static_cast<int>(nj), [&](const std::vector<double>& q) {
    return std::vector<double>{crossing_time(lag_, q, level)};
  }, origin_block(longest, spacing_, n_origins_));
  r.tau_alpha_err = std::isnan(r.tau_alpha) || e.empty() ? kNaN : e[0];
  // None where blocks spanning that lag do not fit four times into the
  // origins (origin_blocks_span): the capped blocks are correlated and the
  // error too small (tau_alpha^CR of runs whose origins are one standard
  // tau_alpha apart: a third to a half of the seeds' spread). A study then
  // takes the spread of its seeds.
  if (!origin_blocks_span(longest, spacing_, n_origins_)) r.tau_alpha_err = kNaN;
  return r;
}

} // namespace dynhet::analysis
