// The dynamic susceptibility chi4(t), paper eq. (14):
//   chi4(t) = overline{ N [<Q_r^2(t;t0)> - <Q_r(t;t0)>^2] },
// the variance of Q_r over the sub-boxes of one grid, times N = <N_r>;
// its peak chi4^P and the time tau4 of the peak.
//
// Two estimators of it. Eq. (14) as written takes the variance about each
// origin's own mean over the n_b sub-boxes and averages it over origins:
// that misses the fluctuation of the mean itself, N var(Q_whole box) =
// chi4(whole box) / n_b, and divides by n_b, not n_b - 1; with the 3 x 3
// sub-boxes of a 4096-particle box it is low by about a ninth. The paper's
// boxes hold hundreds of sub-boxes, where the two agree. dynhet reports the
// pooled variance, about the mean over every sub-box of every origin, with
// n - 1 (n = n_b times the origins): unbiased for any grid (the whole box
// included), to within the variance of the grand mean over the run. Eq.
// (14) as written is kept beside it (chi4_per_origin).
#pragma once

#include <vector>

#include "dynhet/analysis/overlap.hpp"

namespace dynhet::analysis {

// chi4 of one sub-box grid and one cutoff, from the per-origin sub-box sums
// sum_r Q_r and sum_r Q_r^2 that displacement_pass returns.
class Chi4Accumulator {
public:
  // origin_spacing: the time between origins, for the jackknife blocks
  // (origin_block); 0 if unknown (blocks of 1).
  Chi4Accumulator(int n_origins, std::vector<double> lag_time, const SubboxGrid& grid, double origin_spacing = 0);

  void add(int k, int j, double q_r_sum, double q_r_sum2);

  struct Result {
    // N times the variance of Q_r over all sub-boxes of all origins (the
    // n/(n-1) correction), and its jackknife error over blocks of origins
    // spanning the lag (origin_block; NaN below 3 blocks).
    std::vector<double> chi4, chi4_err;
    // Eq. (14) as written (the variance about each origin's mean, averaged
    // over origins) and its standard error over origins; zero for the
    // whole box.
    std::vector<double> chi4_per_origin, chi4_per_origin_err;
    std::vector<int> n_origins;
    // chi4^P and tau4 of chi4: the half-maximum peak fit (find_peak), with
    // jackknife errors over blocks of origins (NaN below 3 blocks): blocks
    // span the last lag the fit reads, the peak found anew in every
    // replicate. tau4_interior: the peak lies inside the lags (false: the
    // largest chi4 is at the first or last lag, and chi4^P, tau4 are
    // bounds, not a peak).
    double chi4_peak, tau4, chi4_peak_err, tau4_err;
    bool tau4_interior;
  };
  Result result() const;
  template <class Ar> void state(Ar& ar) { ar(s1_, s2_); } // what a checkpoint keeps

private:
  std::vector<double> pooled() const;
  std::vector<std::vector<double>> replicates(int block) const;
  std::size_t index(int k, int j) const { return static_cast<std::size_t>(k) * lag_.size() + j; }
  int n_origins_;
  std::vector<double> lag_;
  SubboxGrid grid_;
  double spacing_;
  std::vector<double> s1_, s2_; // per (origin, lag); NaN: not measured
};

} // namespace dynhet::analysis
