// Mean and standard error from block averages: each value added is the
// average over one block (e.g. one status interval); the standard error
// assumes blocks are independent, true once a block outlasts the
// correlation time.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace dynhet {

class BlockAverage {
public:
  void add(double block_value) {
    ++n_;
    const double d = block_value - mean_;
    mean_ += d / n_;
    m2_ += d * (block_value - mean_); // Welford
  }
  void reset() { *this = BlockAverage{}; }
  long count() const { return n_; }
  double mean() const { return n_ ? mean_ : std::numeric_limits<double>::quiet_NaN(); }
  double standard_error() const {
    return n_ > 1 ? std::sqrt(m2_ / (n_ - 1) / n_) : std::numeric_limits<double>::quiet_NaN();
  }

private:
  long n_ = 0;
  double mean_ = 0, m2_ = 0;
};

// A ratio of two time integrals over a phase of a run, sum(num) / sum(den),
// and its standard error, from blocks of simulation time (never of wall
// clock, so the error does not depend on the machine or the schedule).
// Samples (num, den over a time dt) gather into fine blocks of at least
// `fine_length`; the error is that of batch means over groups of
// consecutive fine blocks, each group's ratio weighted by its den, for 16,
// 8 and 4 groups, and the largest of the three is taken (the plateau of
// Flyvbjerg and Petersen, J. Chem. Phys. 91, 461 (1989), read
// conservatively). The pressure of the driven fluid is correlated over
// tens of time units at phi = 0.78 (autocorrelation 0.12 at 10, 0.08 at 20,
// 0.02 at 50): 16 groups of a 165-unit production were a factor 2 short of
// the spread of independent windows, 4 groups 1.7. Where the correlations
// outlast a quarter of the phase the error is a lower bound
// (docs/analysis.md, "Honest errors"). With fewer than two fine blocks
// there is no error (NaN, and the caller says so).
class RatioBlocks {
public:
  static constexpr int kGroups = 16;
  void reset(double fine_length) {
    *this = RatioBlocks{};
    fine_ = fine_length;
  }
  void add(double num, double den, double dt) {
    cur_num_ += num, cur_den_ += den, cur_dt_ += dt;
    if (cur_dt_ >= fine_) {
      num_.push_back(cur_num_), den_.push_back(cur_den_);
      cur_num_ = cur_den_ = cur_dt_ = 0;
    }
  }
  // Fine blocks, the one still open included if it holds any time.
  long blocks() const { return static_cast<long>(num_.size()) + (cur_dt_ > 0); }
  double mean() const {
    double a = cur_num_, b = cur_den_;
    for (size_t i = 0; i < num_.size(); ++i) a += num_[i], b += den_[i];
    return b > 0 ? a / b : std::numeric_limits<double>::quiet_NaN();
  }
  double standard_error() const {
    std::vector<double> n(num_), d(den_);
    if (cur_dt_ > 0) n.push_back(cur_num_), d.push_back(cur_den_);
    const long f = static_cast<long>(n.size());
    double worst = std::numeric_limits<double>::quiet_NaN();
    for (long want : {kGroups, kGroups / 2, kGroups / 4}) {
      const long g = std::min<long>(want, f);
      if (g < 2) break;
      std::vector<double> gn(g, 0.0), gd(g, 0.0);
      for (long i = 0; i < f; ++i) {
        const long k = i * g / f; // consecutive, nearly equal groups
        gn[k] += n[i], gd[k] += d[i];
      }
      double a = 0, b = 0;
      for (long k = 0; k < g; ++k) a += gn[k], b += gd[k];
      if (!(b > 0)) return std::numeric_limits<double>::quiet_NaN();
      const double r = a / b;
      double s = 0;
      for (long k = 0; k < g; ++k)
        if (gd[k] > 0) s += gd[k] * gd[k] * (gn[k] / gd[k] - r) * (gn[k] / gd[k] - r);
      const double se = std::sqrt(s / (b * b) * g / (g - 1.0));
      if (!(se <= worst)) worst = se; // NaN-safe max
      if (g < want) break; // fewer fine blocks than groups: coarser levels repeat it
    }
    return worst;
  }

  template <class Ar> void state(Ar& ar) { ar(fine_, num_, den_, cur_num_, cur_den_, cur_dt_); } // checkpoints

private:
  double fine_ = 0;
  std::vector<double> num_, den_;
  double cur_num_ = 0, cur_den_ = 0, cur_dt_ = 0;
};

} // namespace dynhet
