// P(dx, t), the distribution of x displacements dx = x_i(t0+t) - x_i(t0)
// (paper sec. 3.2, fig. "tails"), from the histograms of the displacement
// pass (displacement.hpp), pooled over origins, with the paper's two forms:
//   Gaussian P_g = exp(-dx^2/(4Dt)) / sqrt(4 pi D t), D free;
//   exponential tail P_e = A exp(-|dx|/x0) over |dx| >= x_min.
// The histograms are tallied per block of consecutive origins, so that
// every estimate (P per bin, D, x0) gets a jackknife error over the blocks.
#pragma once

#include <vector>

#include "dynhet/analysis/displacement.hpp"

namespace dynhet::analysis {

// Which bins the fits use.
struct DistributionFitSpec {
  double tail_sigmas = 2.0; // exponential tail over |dx| >= tail_sigmas * sqrt(<dx^2>)
  long min_count = 5;       // bins with fewer displacements stay out of both fits
};

// The fits of one histogram (NaN where too few bins: 3 at least; the tail
// also NaN if its slope in ln P is not negative by more than one standard
// error, i.e. if it does not decay).
struct DistributionFit {
  double gauss_d, tail_x0, tail_amplitude;
  double tail_x_min, tail_x_max; // the tail fit's range in |dx|: x_min and the outermost bin used
  int gauss_bins, tail_bins;
};

// Fits to the counts of one histogram of `samples` displacements at lag t
// (counts outside the histogram are in samples, not in count). <dx^2> is
// the second moment of the counted displacements at the bin centres.
DistributionFit fit_distribution(const DisplacementSpec& spec, const std::vector<long>& count, long samples,
                                 double t, const DistributionFitSpec& fit);

// P(dx, t) at one lag for one set of particles, pooled over every origin,
// with jackknife errors over blocks of origins.
struct DistributionEstimate {
  std::vector<double> x, p, p_err; // bin centres; density, sum p * width = fraction inside
  std::vector<long> count;         // pooled counts
  long samples = 0;                // displacements in the set over all pairs
  long pairs = 0;                  // (origin, lag) pairs pooled
  DistributionFit fit;
  double gauss_d_err, tail_x0_err;
};

// Histogram counts per (block, lag, set): sets are what the caller names
// (e.g. 0 all particles, 1 small ones). Memory: 8 bytes x blocks x lags x
// sets x bins.
class DisplacementTally {
public:
  DisplacementTally(int blocks, int lags, int sets, int bins);
  // One (origin, lag) pair: `count` has `bins` entries, `samples` is the
  // number of displacements in the set (inside the histogram or not).
  void add(int block, int lag, int set, const long* count, long samples);
  DistributionEstimate estimate(const DisplacementSpec& spec, int lag, int set, double t,
                                const DistributionFitSpec& fit) const;
  long pairs(int lag) const; // pairs added at this lag (set 0)
  template <class Ar> void state(Ar& ar) { ar(cell_); } // what a checkpoint keeps

private:
  struct Cell {
    std::vector<long> count;
    long samples = 0, pairs = 0;
    template <class Ar> void state(Ar& ar) { ar(count, samples, pairs); }
  };
  int blocks_, lags_, sets_, bins_;
  std::vector<Cell> cell_; // [(block * lags + lag) * sets + set]
  const Cell& at(int block, int lag, int set) const { return cell_[(size_t(block) * lags_ + lag) * sets_ + set]; }
};

} // namespace dynhet::analysis
