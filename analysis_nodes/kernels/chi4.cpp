#include "dynhet/analysis/chi4.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

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

namespace {
// N var over `boxes` values whose sum is t1 and sum of squares t2.
double pooled_variance(double big_n, double t1, double t2, double boxes) {
  return boxes > 1 ? big_n * (t2 - t1 * t1 / boxes) / (boxes - 1) : kNaN;
}
} // namespace

// The pooled chi4 of every lag over every measured origin.
std::vector<double> Chi4Accumulator::pooled() const {
  const size_t nj = lag_.size();
  const double nb = double(grid_.per_side) * grid_.per_side;
  std::vector<double> v(nj, kNaN);
  for (size_t j = 0; j < nj; ++j) {
    double t1 = 0, t2 = 0;
    int n = 0;
    for (int k = 0; k < n_origins_; ++k) {
      const double s1 = s1_[index(k, static_cast<int>(j))];
      if (std::isnan(s1)) continue;
      t1 += s1, t2 += s2_[index(k, static_cast<int>(j))], ++n;
    }
    v[j] = pooled_variance(grid_.mean_particles, t1, t2, n * nb);
  }
  return v;
}

// Jackknife replicates over blocks of `block` consecutive measured origins:
// the pooled chi4 without each block (empty below 3 blocks), from the
// totals less each block's sums.
std::vector<std::vector<double>> Chi4Accumulator::replicates(int block) const {
  const size_t nj = lag_.size();
  const double nb = double(grid_.per_side) * grid_.per_side;
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
  if (blocks < 3) return {};
  std::vector<std::vector<double>> out(blocks, std::vector<double>(nj, kNaN));
  for (size_t j = 0; j < nj; ++j) {
    std::vector<double> b1(blocks, 0), b2(blocks, 0);
    std::vector<int> bn(blocks, 0);
    double t1 = 0, t2 = 0;
    int n = 0;
    for (int i = 0; i < u; ++i) {
      const double s1 = s1_[index(used[i], static_cast<int>(j))];
      if (std::isnan(s1)) continue;
      const double s2 = s2_[index(used[i], static_cast<int>(j))];
      b1[i / b] += s1, b2[i / b] += s2, ++bn[i / b];
      t1 += s1, t2 += s2, ++n;
    }
    for (int blk = 0; blk < blocks; ++blk)
      out[blk][j] = pooled_variance(grid_.mean_particles, t1 - b1[blk], t2 - b2[blk], (n - bn[blk]) * nb);
  }
  return out;
}

Chi4Accumulator::Result Chi4Accumulator::result() const {
  const size_t nj = lag_.size();
  const double nb = double(grid_.per_side) * grid_.per_side, big_n = grid_.mean_particles;
  Result r;
  r.chi4_err.assign(nj, kNaN), r.chi4_per_origin.assign(nj, kNaN), r.chi4_per_origin_err.assign(nj, kNaN);
  r.n_origins.assign(nj, 0);
  for (size_t j = 0; j < nj; ++j) {
    double sum = 0, sum_sq = 0;
    int n = 0;
    for (int k = 0; k < n_origins_; ++k) {
      const double s1 = s1_[index(k, static_cast<int>(j))], s2 = s2_[index(k, static_cast<int>(j))];
      if (std::isnan(s1)) continue;
      const double mean = s1 / nb;
      const double c = big_n * (s2 / nb - mean * mean); // N[<Q_r^2> - <Q_r>^2] of origin k
      sum += c, sum_sq += c * c, ++n;
    }
    r.n_origins[j] = n;
    if (n == 0) continue;
    r.chi4_per_origin[j] = sum / n; // eq. (14) as written
    if (n > 1)
      r.chi4_per_origin_err[j] =
          std::sqrt(std::max(0.0, (sum_sq / n - r.chi4_per_origin[j] * r.chi4_per_origin[j]) / (n - 1)));
  }
  r.chi4 = pooled();
  // Errors per lag: blocks of origins spanning that lag.
  std::map<int, std::vector<std::vector<double>>> by_block;
  for (size_t j = 0; j < nj; ++j) {
    const int block = origin_block(lag_[j], spacing_, n_origins_);
    auto it = by_block.find(block);
    if (it == by_block.end()) it = by_block.emplace(block, replicates(block)).first;
    if (it->second.empty()) continue;
    std::vector<double> x;
    for (const auto& rep : it->second) x.push_back(rep[j]);
    r.chi4_err[j] = jackknife_error(x);
  }
  const Peak p = find_peak(lag_, r.chi4); // chi4^P at tau4
  r.chi4_peak = p.y, r.tau4 = p.t, r.tau4_interior = p.interior;
  r.chi4_peak_err = r.tau4_err = kNaN;
  if (std::isnan(p.y)) return r;
  // Their errors: a jackknife over blocks of origins (fits.hpp), blocks
  // spanning the last lag the fit reads, the peak found anew in every
  // replicate. The fit over the half maximum is continuous in the data, so
  // the jackknife holds; for the parabola through the largest point and its
  // neighbours it did not (an error that varied 50-fold between seeds, 1.45
  // times their spread on 455-particle boxes).
  const auto reps = replicates(origin_block(lag_[p.last], spacing_, n_origins_));
  if (reps.empty()) return r;
  std::vector<double> ys, ts;
  for (const auto& v : reps) {
    const Peak q = find_peak(lag_, v);
    ys.push_back(q.y), ts.push_back(q.t);
  }
  r.chi4_peak_err = jackknife_error(ys), r.tau4_err = jackknife_error(ts);
  return r;
}

} // namespace dynhet::analysis
