// The overlap Q_r(t;t0) over sub-boxes and its averages (paper, sec. 3.1).
// Pure functions and a small accumulator over arrays of positions.
#pragma once

#include <cstddef>
#include <vector>

namespace dynhet::analysis {

// The box split into m x m sub-boxes B_r holding on average
// N = <N_r> = n_total / m^2 particles, m chosen so N is close to the target.
struct SubboxGrid {
  int per_side;
  double box;
  double mean_particles; // N = <N_r>
};
SubboxGrid make_subbox_grid(long n_total, double box, int target_particles);

// Paper eq. (5): Q_r(t;t0) = (1/N) sum_{i in B_r at t0} theta(a - |r_i(t0+t) - r_i(t0)|)
// for every sub-box r (row-major, m*m values) and every cutoff a in one pass
// over the particles. Positions are unwrapped, x0 y0 x1 y1 ...; a particle
// belongs to the sub-box holding its position at t0 folded into the box.
// Output q_r[c * m*m + r] for cutoff c.
void overlap_subboxes(const double* pos0, const double* pos_t, long n, const SubboxGrid& grid,
                      const std::vector<double>& cutoffs, std::vector<double>& q_r);

// First time where q crosses `level` from above, interpolated linearly in
// ln t between the bracketing lags; NaN if q never crosses. Lags with a NaN
// q are skipped.
double crossing_time(const std::vector<double>& t, const std::vector<double>& q, double level);

// Q(t;t0) = <Q_r(t;t0)> per (origin, lag), for one cutoff, and the averages
// over origins: Q(t) (eq. 7), its standard error, and tau_alpha with a
// jackknife error over blocks of origins (origin_jackknife, fits.hpp).
class OverlapAccumulator {
public:
  // origin_spacing: the time between origins (jackknife blocks span the
  // lag tau_alpha is read at, origin_block); 0 if unknown (blocks of 1).
  OverlapAccumulator(int n_origins, std::vector<double> lag_time, double origin_spacing = 0);

  // Q_r over the sub-boxes (m*m values) for origin k at lag j.
  void add(int k, int j, const double* q_r, int n_subboxes);

  struct Result {
    std::vector<double> q, q_err, qr_var; // per lag
    std::vector<int> n_origins;           // per lag
    double tau_alpha, tau_alpha_err;
  };
  Result result() const;

  // Q(t;t0) of origin k at lag j (NaN if not yet measured).
  double q(int k, int j) const { return q_[index(k, j)]; }
  // All of them, origin-major, for origin_jackknife.
  const std::vector<double>& table() const { return q_; }
  int n_origins() const { return n_origins_; }
  double origin_spacing() const { return spacing_; }
  // What a checkpoint keeps (the sizes are the run's, set by the constructor).
  template <class Ar> void state(Ar& ar) { ar(q_, var_); }

private:
  std::size_t index(int k, int j) const { return static_cast<size_t>(k) * lag_.size() + j; }
  std::vector<double> mean_over_origins(int skip) const;
  int n_origins_;
  std::vector<double> lag_;
  double spacing_;
  std::vector<double> q_, var_; // per (k, j): <Q_r> and <Q_r^2> - <Q_r>^2
};

} // namespace dynhet::analysis
