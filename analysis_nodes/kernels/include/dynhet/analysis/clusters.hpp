// Clusters of slow and fast particles (paper, sec. 3.3).
//   g_ab(r): partial pair distributions of the species pairs 11, 12, 22; the
//   first minimum of each (smoothed) is the neighbour cutoff r^min_ab.
//   Neighbour pairs: |r_i - r_j| < r^min_{a_i b_j}, minimum image, found
//   once per frame with a cell list and shared by every selection.
//   Clusters: connected components of the selected particles over the
//   neighbour pairs (slow: |dr| < a, fast: |dr| > 3a), with N_c and the
//   radius of gyration R_g, eq. (10), computed on positions unwrapped along
//   the cluster's breadth-first tree. A cluster joined to its own periodic
//   image (a bond closes a loop that winds around the box) spans the box:
//   it is flagged and has no R_g.
//   P(N_c) in log bins (eq. 11-13 fits are in fits.hpp) and the fractal
//   dimension d_f from R_g ~ N_c^(1/d_f).
// Positions x0 y0 x1 y1 ..., folded or not; periodic square box of side box.
// Which frame: the paper does not say at which time two particles must be
// neighbours; eq. (10) takes r_i(tau_alpha), the end of the interval. The
// two-frame ClusterFinder::find takes the neighbours at t0 (so they are
// found once per origin frame and shared by every lag, cutoff and
// selection) and R_g at t0 + t, from the same bonds carried along by the
// displacements (both frames unwrapped continuously). The one-frame find
// takes both from one frame.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "dynhet/analysis/fits.hpp"

namespace dynhet::analysis {

// Species pair index: 0 = small-small (11), 1 = small-large (12), 2 = large-large (22).
inline int species_pair(int si, int sj) { return si + sj; }

// g_ab(r) on bins [k dr, (k+1) dr) up to r_max <= box/2, normalised by the
// ideal-gas count of each pair type: g = 1 for uncorrelated positions.
struct PairDistribution {
  double dr;
  std::vector<double> r;                // bin centres
  std::array<std::vector<double>, 3> g; // by species_pair
  template <class Ar> void state(Ar& ar) { ar(dr, r, g); }
};
PairDistribution pair_distribution(const double* pos, const std::uint8_t* species, long n, double box,
                                   double r_max, double dr);

// First minimum after the first peak (g > 1) of g smoothed with a Gaussian
// of width `smooth` (in r), refined by a parabola through the three bins
// around it. NaN if there is none.
double first_minimum(const std::vector<double>& r, const std::vector<double>& g, double smooth);

struct NeighbourCutoffs {
  std::array<double, 3> r; // by species_pair
  double max() const { return std::max(r[0], std::max(r[1], r[2])); }
  template <class Ar> void state(Ar& ar) { ar(r); }
};
NeighbourCutoffs neighbour_cutoffs(const PairDistribution& g, double smooth);

// Pairs i < j closer than their species' cutoff, and the bond r_j - r_i
// (minimum image) of each.
struct NeighbourPairs {
  long n = 0; // particles
  std::vector<std::array<std::int32_t, 2>> pairs;
  std::vector<std::array<double, 2>> bond;
};
NeighbourPairs neighbour_pairs(const double* pos, const std::uint8_t* species, long n, double box,
                               const NeighbourCutoffs& cut);

// The same, frame after frame, reusing its memory (a node keeps one).
struct CellList;
class NeighbourFinder {
public:
  explicit NeighbourFinder(const NeighbourCutoffs& cut);
  ~NeighbourFinder();
  const NeighbourPairs& find(const double* pos, const std::uint8_t* species, long n, double box);

private:
  NeighbourCutoffs cut_;
  std::unique_ptr<CellList> cells_;
  NeighbourPairs out_;
};

// Selections over one (origin, lag) pair from |dr|^2.
std::vector<std::uint8_t> slow_particles(const double* d2, long n, double a); // |dr| < a
std::vector<std::uint8_t> fast_particles(const double* d2, long n, double a); // |dr| > 3a

struct Cluster {
  long size;                 // N_c
  double radius_of_gyration; // R_g, eq. (10); NaN if the cluster spans the box
  double cx, cy;             // centre of mass, folded into the box (NaN if spanning)
  bool spans;
};
struct ClusterSet {
  std::vector<std::int32_t> label; // per particle: its cluster, -1 if not selected
  std::vector<Cluster> clusters;
};
ClusterSet find_clusters(const NeighbourPairs& nb, const double* pos, double box,
                         const std::uint8_t* selected);

// The neighbour pairs of one frame as adjacency lists (CSR, each pair stored
// from both ends): built once per origin frame, walked by every selection
// of every lag and cutoff. 4 bytes per particle and 8 per pair.
struct NeighbourGraph {
  std::vector<std::int32_t> start; // n + 1: the neighbours of i are to[start[i] .. start[i+1])
  std::vector<std::int32_t> to;
  long n() const { return start.empty() ? 0 : static_cast<long>(start.size()) - 1; }
  void build(const NeighbourPairs& nb);
};

// The same, selection after selection, reusing its memory.
class ClusterFinder {
public:
  ClusterFinder();
  ~ClusterFinder();
  // Neighbours over the graph of the frame pos0; R_g and the centre at the
  // frame pos_t (eq. 10 at t = t0 + tau), each bond r_j - r_i taken as the
  // minimum image at t0 plus the difference of the two displacements.
  const ClusterSet& find(const NeighbourGraph& g, const double* pos0, const double* pos_t, double box,
                         const std::uint8_t* selected);
  // Neighbours and R_g both at the frame pos.
  const ClusterSet& find(const NeighbourPairs& nb, const double* pos, double box,
                         const std::uint8_t* selected);

private:
  std::vector<std::int32_t> queue_;
  std::vector<std::array<double, 2>> u_; // positions at t0 unwrapped along the tree
  NeighbourGraph graph_;                 // for the one-frame find
  ClusterSet out_;
};

// Sizes of the clusters (spanning ones included).
std::vector<long> cluster_sizes(const ClusterSet& c);

// Integer log-bin edges 1 = e_0 < e_1 < ... (round(10^(k/b)), duplicates
// merged), the last one above max_size: bin k holds the sizes e_k .. e_{k+1}-1.
std::vector<long> log_bin_edges(long max_size, int bins_per_decade);

// P(N_c): the fraction of clusters of each size, in bins_per_decade log bins
// of integers (log_bin_edges).
SizeHistogram cluster_size_distribution(const std::vector<long>& sizes, int bins_per_decade);

// What P(N_c), the R_g - N_c bins and d_f need of many cluster sets (one per
// origin, say), on fixed log bins of N_c: counts and sums that add up, so
// a node keeps one per block of origins instead of the cluster lists, and
// leaves a block out for a jackknife error by adding the others.
struct ClusterTally {
  ClusterTally() = default;
  // Bins up to max_size; R_g sums over the non-spanning clusters with N_c >= rg_min_size.
  ClusterTally(long max_size, int bins_per_decade, long rg_min_size);
  void add(const ClusterSet& c);
  void add(const ClusterTally& other); // same bins
  // Mean N_c over all clusters (particles / clusters); NaN if none.
  double mean_size() const;
  // P(N_c) over the bins up to the largest cluster seen (as cluster_size_distribution).
  SizeHistogram histogram() const;

  std::vector<long> edges;
  long rg_min_size = 10;
  long sets = 0;                          // cluster sets added
  long particles = 0, clusters = 0, spanning = 0, largest = 0;
  std::vector<long> count;                // clusters per bin, spanning ones included
  std::vector<long> rg_count;             // clusters in the R_g sums, per bin
  std::vector<double> sum_ln_n, sum_ln_rg; // sum of ln N_c and ln R_g, per bin
  template <class Ar> void state(Ar& ar) {
    ar(edges, rg_min_size, sets, particles, clusters, spanning, largest, count, rg_count, sum_ln_n, sum_ln_rg);
  }
};

// d_f from R_g ~ N_c^(1/d_f): a straight line through the mean ln R_g against
// the mean ln N_c in each log bin of N_c (bins equally weighted, so the
// many small clusters do not dominate), over the non-spanning clusters
// with N_c >= n_min. NaN (not determined) with fewer than 3 such bins.
struct FractalFit {
  double d_f, d_f_err;
  int n_bins;
  long n_clusters;
};
FractalFit fit_fractal_dimension(const std::vector<Cluster>& clusters, long n_min = 10,
                                 int bins_per_decade = 5);
FractalFit fit_fractal_dimension(const ClusterTally& t); // n_min = t.rg_min_size

} // namespace dynhet::analysis
