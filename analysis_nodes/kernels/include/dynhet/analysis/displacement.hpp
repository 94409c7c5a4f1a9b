// Everything one displacement dr_i = r_i(t0+t) - r_i(t0) feeds, for one
// (origin, lag) pair, in one pass over the particles (paper, secs. 3.1, 3.2
// and 3.4):
//   Q_r(t;t0), eq. (5), on every sub-box grid and for every cutoff a;
//   from it Q(t;t0) = <Q_r>, eq. (6), and N[<Q_r^2> - <Q_r>^2], the origin's
//   term of chi4(t), eq. (14);
//   the MSD Delta(t), eq. (9), of all particles and of the small ones;
//   the histogram of x displacements behind P(dx, t).
// Equation numbers count the paper's numbered equations in source order
// (eq. 5 is \label{Q(t)-eq}, eq. 14 is \label{chi_4-eq}).
// Positions are unwrapped, x0 y0 x1 y1 ...; species 0 = small, 1 = large.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "dynhet/analysis/overlap.hpp"

namespace dynhet::analysis {

// The sub-box B_r holding a position at t0, folded into [0, box): the rule
// of overlap_subboxes (row-major index by * m + bx).
inline std::uint32_t subbox_index(double x, double y, const SubboxGrid& g) {
  const int m = g.per_side;
  const double width = g.box / m;
  const double fx = x - g.box * std::floor(x / g.box), fy = y - g.box * std::floor(y / g.box);
  const int bx = std::min(m - 1, static_cast<int>(fx / width));
  const int by = std::min(m - 1, static_cast<int>(fy / width));
  return static_cast<std::uint32_t>(by * m + bx);
}

// Sub-box grids for a list of target sizes (N per box), nested so that each
// side divides the next finer one: the finest side is the 2^a 3^b nearest
// sqrt(n_total / target) in ln, every coarser one the divisor of the finer
// side nearest its own ideal. N per box then differs from a target by at
// most a few tens of percent (a factor 2 at worst for lone large targets)
// and the whole list costs one counter increment per particle in a pass.
// A target >= n_total gives the whole box. Returned in the order given.
std::vector<SubboxGrid> nested_subbox_grids(long n_total, double box, const std::vector<int>& targets);

// What a displacement pass needs to know, fixed for a run.
struct DisplacementSpec {
  std::vector<SubboxGrid> grids; // one per listed sub-box size
  std::vector<double> cutoffs;   // the cutoffs a, ascending
  double hist_lo = -10.0;        // x-displacement histogram: first bin edge,
  double hist_width = 0.05;      //   bin width
  int hist_bins = 400;           //   and number of bins
};

// The sub-box of every particle, from the origin frame: computed once per
// origin and reused by every lag. A grid whose side m divides that of a
// finer grid (the whole box always does) has no index of its own: its
// counts are sums over the finer grid's boxes, so nested sizes (m, m/2,
// m/4, ...) cost one counter increment per particle in all; every other
// ("indexed") grid costs one more.
class OriginIndex {
public:
  OriginIndex(const double* pos0, long n, const DisplacementSpec& spec);
  long size() const { return n_; }
  int indexed_grids() const { return static_cast<int>(sides_.size()); }
  int indexed_side(int k) const { return sides_[k]; } // m of indexed grid k
  int ranks() const { return ranks_; }                // n_cutoffs + 1
  // First counter of particle i's box on each indexed grid; a box has one
  // counter per rank 0..n_cutoffs (rank = cutoffs the particle moved beyond).
  const std::uint32_t* offsets(long i) const { return offset_.data() + i * sides_.size(); }
  std::size_t base(int k) const { return base_[k]; } // first counter of indexed grid k
  std::size_t counters() const { return counters_; }
  // Grid g is indexed grid `indexed`, or (indexed = -1) the sum of grid
  // `from`'s boxes, `factor` x `factor` per box.
  struct Source {
    int indexed, from, factor;
  };
  const Source& source(int g) const { return source_[g]; }
  const std::vector<int>& order() const { return order_; } // grids from the finest down

private:
  long n_;
  int ranks_;
  std::vector<int> sides_;     // m of each indexed grid
  std::vector<Source> source_; // per grid of the spec
  std::vector<int> order_;
  std::vector<std::size_t> base_;     // first counter of each indexed grid
  std::vector<std::uint32_t> offset_; // offset_[i * indexed + k]
  std::size_t counters_;
};

// The results of one pass. Arrays over (grid g, cutoff c) use [g * nc + c].
struct DisplacementResult {
  std::vector<std::vector<double>> q_r;  // Q_r per sub-box (row-major, as overlap_subboxes)
  std::vector<double> q;                 // Q(t;t0) per cutoff, eq. (6)
  std::vector<double> q_r_sum, q_r_sum2; // sum_r Q_r and sum_r Q_r^2
  std::vector<double> chi4;              // N[<Q_r^2> - <Q_r>^2], eq. (14) before the origin average
  double msd_all = 0, msd_small = 0;     // Delta(t), eq. (9)
  long n_small = 0;
  // x-displacement counts per species: hist[s][b], bin b covers
  // [hist_lo + b w, hist_lo + (b+1) w); displacements outside are in hist_out.
  std::vector<long> hist[2];
  long hist_out = 0;
};

// One pass over the particles. If d2 is not null it receives |dr_i|^2 for
// later use (fastest/slowest subsets, overlap weights, cluster selection).
void displacement_pass(const double* pos0, const double* pos_t, const std::uint8_t* species, long n,
                       const OriginIndex& origin, const DisplacementSpec& spec, DisplacementResult& out,
                       double* d2 = nullptr);

// Mean of |dr|^2 over the instantaneous fastest and slowest `fraction` of a
// set of particles (species -1: all, else that species), e.g. 10% of all,
// 20% of small ones (paper, fig. MSD). "Instantaneous": the subsets are
// chosen anew for every (origin, lag) pair, by the particles' own |dr|^2
// over that lag; each holds round(fraction * set size) particles (at least
// one). Exact: the same subsets as a full sort (up to ties, so the same
// sums to roundoff). From 4096 particles on, a strided sample of about
// 8 sqrt(n) values brackets each subset's bound; one pass over d2 sums the
// values surely inside a subset and copies the band around each bound into
// `buffer`, and nth_element runs on the bands only. A side whose bound the
// band turns out not to hold (the counts say so) is redone for its set by
// nth_element on a copy of the whole set, as are sets under 4096 particles.
// `buffer` is reused: no allocation once it has grown.
struct ExtremeMsd {
  double fast, slow;
  long count;              // particles in each subset
  int full_selections = 0; // 1 if the set needed the whole-set fallback (diagnostic)
};
ExtremeMsd msd_extremes(const double* d2, const std::uint8_t* species, long n, double fraction,
                        int which_species, std::vector<double>& buffer);
ExtremeMsd msd_extremes(const double* d2, const std::uint8_t* species, long n, double fraction,
                        int which_species = -1);

// The two sets the overlap node publishes, all particles and small ones
// (species 0), in one pass over d2: the same results as two calls above.
struct ExtremeMsdAllSmall {
  ExtremeMsd all, small;
};
ExtremeMsdAllSmall msd_extremes_all_small(const double* d2, const std::uint8_t* species, long n,
                                          double fraction_all, double fraction_small,
                                          std::vector<double>& buffer);

// theta(a - |dr_i|) for every particle: the weights of W_r(q,t), eq. (16).
void overlap_weights(const double* d2, long n, double cutoff_a, std::vector<double>& weight);

// P(dx, t) as a density from the counts of one pass: centres x and p with
// sum p * width = fraction of displacements inside the histogram.
struct DisplacementDensity {
  std::vector<double> x, p;
  std::vector<long> count;
};
DisplacementDensity displacement_density(const DisplacementSpec& spec, const std::vector<long>& counts,
                                         long n_total);

// The displacement field's longest waves: for every wave vector
// k = 2 pi n / L with 0 < |n| <= n_max (one of each pair n, -n), the
// Fourier amplitude u_k = (1/N) sum_i dr_i exp(-i k . r_i(t0)) of one
// (origin, lag) pair, split into its transverse (flow, shear) and
// longitudinal parts. By Parseval the MSD is the sum of 2 |u_k|^2 over all
// k; independent displacements give each part of each pair an expected
// 2 |u_k . e|^2 = MSD / N, which is subtracted: what remains is the MSD the
// collective motion at that wavelength carries. In a momentum-conserving
// fluid the transverse modes decay as exp(-nu k^2 t), far slower than a run
// at the smallest k of a large box: they are the long-lived flows behind
// D's spread between runs (docs/analysis.md "D and the long-lived flows").
struct WaveModes {
  std::vector<int> nx, ny; // the n of each mode
  std::vector<double> transverse, longitudinal; // 2 |u_k . e|^2 - MSD / N per mode
  std::vector<double> t_re, t_im, l_re, l_im;    // u_k . e itself (transverse, longitudinal)
};
// The wave vectors of collective_modes, in its order.
void wave_vectors(int n_max, std::vector<int>& nx, std::vector<int>& ny);
// One pair's modes (positions unwrapped, x0 y0 x1 y1 ...; msd the pair's
// mean squared displacement). The displacements are summed on a 64 x 64
// grid of cells by r_i(t0) (O(N), a few ns a particle), the Fourier sums
// taken over the cell centres and divided by the cells' window (exact on
// average for positions spread over a cell; the window is 0.99 or more
// for |n| <= 4 of L/64 cells).
WaveModes collective_modes(const double* pos0, const double* pos_t, long n, double box, int n_max, double msd);

} // namespace dynhet::analysis
