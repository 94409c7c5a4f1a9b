// Mean and standard error from block averages: each value added is the
// average over one block (e.g. one status interval); the standard error
// assumes blocks are independent, true once a block outlasts the
// correlation time.
#pragma once

#include <cmath>
#include <limits>

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

} // namespace dynhet
