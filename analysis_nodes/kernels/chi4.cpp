#include "dynhet/analysis/chi4.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "dynhet/analysis/fits.hpp"
#include "dynhet/analysis/timescales.hpp"

namespace dynhet::analysis {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}

Chi4Accumulator::Chi4Accumulator(int n_origins, std::vector<double> lag_time, const SubboxGrid& grid,
                                 double origin_spacing)
    : n_origins_(n_origins), lag_(std::move(lag_time)), grid_(grid), spacing_(origin_spacing),
      s1_(static_cast<size_t>(n_origins) * lag_.size(), kNaN), s2_(s1_) {}

void Chi4Accumulator::add(int k, int j, double q_r_sum, double q_r_sum2) {
  s1_[index(k, j)] = q_r_sum, s2_[index(k, j)] = q_r_sum2;
}

Chi4Accumulator::Result Chi4Accumulator::result() const {
  const size_t nj = lag_.size();
  const double nb = double(grid_.per_side) * grid_.per_side, big_n = grid_.mean_particles;
  Result r;
  r.chi4.assign(nj, kNaN), r.chi4_err.assign(nj, kNaN), r.chi4_pooled.assign(nj, kNaN);
  r.chi4_pooled_err.assign(nj, kNaN);
  r.n_origins.assign(nj, 0);
  for (size_t j = 0; j < nj; ++j) {
    double sum = 0, sum_sq = 0, t1 = 0, t2 = 0;
    int n = 0;
    for (int k = 0; k < n_origins_; ++k) {
      const double s1 = s1_[index(k, static_cast<int>(j))], s2 = s2_[index(k, static_cast<int>(j))];
      if (std::isnan(s1)) continue;
      const double mean = s1 / nb;
      const double c = big_n * (s2 / nb - mean * mean); // N[<Q_r^2> - <Q_r>^2] of origin k
      sum += c, sum_sq += c * c, t1 += s1, t2 += s2, ++n;
    }
    r.n_origins[j] = n;
    if (n == 0) continue;
    r.chi4[j] = sum / n; // eq. (14): the average over origins
    if (n > 1) r.chi4_err[j] = std::sqrt(std::max(0.0, (sum_sq / n - r.chi4[j] * r.chi4[j]) / (n - 1)));
    const double boxes = n * nb;
    if (boxes > 1) r.chi4_pooled[j] = big_n * (t2 - t1 * t1 / boxes) / (boxes - 1);
    if (n >= 3) {
      std::vector<double> loo; // the pooled estimate without origin k
      const double b = (n - 1) * nb;
      for (int k = 0; k < n_origins_; ++k) {
        const double s1 = s1_[index(k, static_cast<int>(j))], s2 = s2_[index(k, static_cast<int>(j))];
        if (std::isnan(s1)) continue;
        const double u1 = t1 - s1, u2 = t2 - s2;
        loo.push_back(big_n * (u2 - u1 * u1 / b) / (b - 1));
      }
      r.chi4_pooled_err[j] = jackknife_error(loo);
    }
  }
  const Peak p = find_peak(lag_, nb > 1 ? r.chi4 : r.chi4_pooled); // chi4^P at tau4
  r.chi4_peak = p.y, r.tau4 = p.t;
  r.chi4_peak_err = r.tau4_err = kNaN;
  if (std::isnan(p.y)) return r;
  // Their errors: a jackknife over blocks of origins (fits.hpp,
  // origin_jackknife), blocks spanning the last lag the fit reads, the peak
  // found anew in every replicate. The fit over the half maximum is
  // continuous in the data, so the jackknife holds; for the parabola through
  // the largest point and its neighbours it did not (an error that varied
  // 50-fold between seeds, 1.45 times their spread on 455-particle boxes).
  const int nl = static_cast<int>(nj);
  const int block = origin_block(lag_[p.last], spacing_, n_origins_);
  std::vector<double> e;
  if (nb > 1) {
    std::vector<double> c(s1_.size(), kNaN); // per-origin chi4, the terms of eq. (14)
    for (size_t i = 0; i < c.size(); ++i)
      if (!std::isnan(s1_[i])) c[i] = big_n * (s2_[i] / nb - (s1_[i] / nb) * (s1_[i] / nb));
    e = origin_jackknife(c, n_origins_, nl, [&](const std::vector<double>& chi4) {
      const Peak q = find_peak(lag_, chi4);
      return std::vector<double>{q.y, q.t};
    }, block);
  } else {
    // The whole box: the pooled variance is no mean over origins, so the
    // replicates (the same blocks) are made here.
    std::vector<int> used;
    for (int k = 0; k < n_origins_; ++k)
      for (size_t j = 0; j < nj; ++j)
        if (!std::isnan(s1_[index(k, static_cast<int>(j))])) {
          used.push_back(k);
          break;
        }
    const int u = static_cast<int>(used.size());
    const int b = std::clamp(block, 1, std::max(1, u / 2));
    const int blocks = (u + b - 1) / b;
    if (blocks >= 3) {
      std::vector<double> ys, ts;
      for (int blk = 0; blk < blocks; ++blk) {
        std::vector<double> v(nj, kNaN);
        for (size_t j = 0; j < nj; ++j) {
          double t1 = 0, t2 = 0;
          int n = 0;
          for (int i = 0; i < u; ++i) {
            if (i / b == blk) continue;
            const double a = s1_[index(used[i], static_cast<int>(j))];
            if (std::isnan(a)) continue;
            t1 += a, t2 += s2_[index(used[i], static_cast<int>(j))], ++n;
          }
          if (n > 1) v[j] = big_n * (t2 - t1 * t1 / n) / (n - 1);
        }
        const Peak q = find_peak(lag_, v);
        ys.push_back(q.y), ts.push_back(q.t);
      }
      e = {jackknife_error(ys), jackknife_error(ts)};
    }
  }
  if (e.size() == 2) r.chi4_peak_err = e[0], r.tau4_err = e[1];
  return r;
}

} // namespace dynhet::analysis
