// The dynamic susceptibility chi4(t), paper eq. (14):
//   chi4(t) = overline{ N [<Q_r^2(t;t0)> - <Q_r(t;t0)>^2] },
// the variance of Q_r over the sub-boxes of one grid, times N = <N_r>,
// averaged over the origins t0; its peak chi4^P and the time tau4 of the peak.
#pragma once

#include <vector>

#include "dynhet/analysis/overlap.hpp"

namespace dynhet::analysis {

// chi4 of one sub-box grid and one cutoff, from the per-origin sub-box sums
// sum_r Q_r and sum_r Q_r^2 that displacement_pass returns.
class Chi4Accumulator {
public:
  // origin_spacing: the time between origins, for the jackknife blocks of
  // chi4^P and tau4 (origin_block); 0 if unknown (blocks of 1).
  Chi4Accumulator(int n_origins, std::vector<double> lag_time, const SubboxGrid& grid, double origin_spacing = 0);

  void add(int k, int j, double q_r_sum, double q_r_sum2);

  struct Result {
    std::vector<double> chi4, chi4_err; // eq. (14) and its standard error over origins
    // N times the variance of Q_r over all sub-boxes of all origins (with
    // the n/(n-1) correction): what chi4 means for the whole box (one
    // sub-box), where the within-origin variance is zero.
    std::vector<double> chi4_pooled;
    // Its jackknife error over origins (leave one origin out; NaN with
    // fewer than 3 origins).
    std::vector<double> chi4_pooled_err;
    std::vector<int> n_origins;
    // chi4^P and tau4 (of chi4, or of chi4_pooled for one sub-box): the
    // vertex of the parabola in ln t through the largest point and its two
    // neighbours (the largest point itself at either end of the lags), with
    // jackknife errors over blocks of origins (NaN below 3 origins): blocks
    // span the last of the three lags (origin_block), the peak found anew
    // in every replicate.
    double chi4_peak, tau4, chi4_peak_err, tau4_err;
  };
  Result result() const;
  template <class Ar> void state(Ar& ar) { ar(s1_, s2_); } // what a checkpoint keeps

private:
  std::size_t index(int k, int j) const { return static_cast<std::size_t>(k) * lag_.size() + j; }
  int n_origins_;
  std::vector<double> lag_;
  SubboxGrid grid_;
  double spacing_;
  std::vector<double> s1_, s2_; // per (origin, lag); NaN: not measured
};

} // namespace dynhet::analysis
