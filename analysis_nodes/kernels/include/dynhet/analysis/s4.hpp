// The four-point structure factor S4(q,t) (paper, sec. 3.4):
//   W_r(q,t) = (1/N) sum_{i in B_r at t0} exp(i q.r_i(t0)) w_i,   eq. (16),
//   S4(q,t) = N { <W_r(q) W_r(-q)> - <W_r(q)><W_r(-q)> },          eq. (15),
// with w_i = theta(a - |dr_i|) (any real weights are accepted), <...> the
// average over the m x m sub-boxes B_r of side ell = L/m, and {...} the
// average over the lattice vectors q = (2 pi/ell)(nx, ny) of the sub-box
// in each shell round(|n|) = s, up to |q| <= q_max. Sub-box membership is
// the rule of overlap_subboxes; positions are taken relative to the
// sub-box corner (the same phases as absolute ones, q being a sub-box
// lattice vector). The origin average (overline) is the caller's.
// At q = 0, W_r = Q_r and S4 is the origin's term of chi4, eq. (14).
// Whole box (m = 1): there is no sub-box average; as <W(q)> = 0 for q != 0
// in a homogeneous system, S4(q) = N |W(q)|^2, and q = 0 is left out (NaN).
//
// Two ways to W_r(q):
//   s4_modes_direct: the exact sum, by separable phase tables and a complex
//   matrix product per sub-box (the reference; about 2 s for the whole box
//   at N = 10^5, q <= 1);
//   S4Grid: a non-uniform FFT of type 1. Each weight is spread on an M x M
//   periodic grid per sub-box with a Gaussian exp(-x^2/(4 tau)) truncated
//   at half_width grid points, the grids are transformed by FFTW, and each
//   mode is divided by the Gaussian's transform 4 pi tau exp(-q^2 tau).
//   With oversampling R = pi/(h q_max) (h = ell/M) and tau chosen to balance
//   aliasing and truncation (Greengard & Lee, SIAM Rev. 46, 443 (2004)),
//   the error of sum_i w_i exp(i q.r_i) is at most about
//   exp(-pi half_width (R-1)/(R-1/2)) sum_i |w_i|. The default (R = 2,
//   half_width 4) gives S4 within 1e-4 of the direct sum at N = 10^5, in
//   about 10 ms (bench_analysis prints the table against spacing).
// Constructing an S4Grid plans the FFT (FFTW's planner: one thread at a time).
#pragma once

#include <array>
#include <complex>
#include <memory>
#include <vector>

#include "dynhet/analysis/overlap.hpp"

namespace dynhet::analysis {

// W_r(q) for the sub-boxes of `grid` and the lattice vectors n of the half
// plane (ny > 0, or ny = 0 and nx >= 0) with |q| <= q_max: W(-q) = conj W(q).
struct S4Modes {
  SubboxGrid grid;
  double q_max;
  std::vector<std::array<int, 2>> n;   // (nx, ny) per mode
  std::vector<std::complex<double>> w; // W_r(q): [r * n.size() + mode]
  double dq() const;                   // 2 pi / ell
};

S4Modes s4_modes_direct(const double* pos0, const double* weight, long n, const SubboxGrid& grid,
                        double q_max);

struct S4GridParams {
  double spacing = 0; // grid spacing h (0: pi / (2 q_max), oversampling R = 2); rounded down to fit ell
  int half_width = 4; // the Gaussian covers 2 half_width points per dimension
  // FFTW_MEASURE (times candidate plans: best speed, ~0.1-1 s to plan, the
  // plan and so the last bits may differ between runs) or FFTW_ESTIMATE
  // (instant, the same plan every time: what a node that must not steal CPU
  // while frames arrive, and whose replays must match bit for bit, wants).
  bool measure_plan = true;
};

class S4Grid {
public:
  S4Grid(const SubboxGrid& grid, double q_max, S4GridParams p = {});
  ~S4Grid();
  S4Grid(const S4Grid&) = delete;
  S4Grid& operator=(const S4Grid&) = delete;

  S4Modes modes(const double* pos0, const double* weight, long n);
  int points() const;          // M, grid points per sub-box side
  double spacing() const;      // h = ell / M
  double oversampling() const; // R = pi / (h q_max)
  // The estimate above of max |error of sum_i w_i e^{iq.r_i}| / sum_i |w_i|;
  // a worst case: for random positions the errors are ~100 times smaller.
  double error_bound() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct S4Shells {
  std::vector<double> q;      // mean |q| of the shell's vectors
  std::vector<double> s4;     // S4(q), eq. (15)
  std::vector<int> n_vectors; // lattice vectors in the shell, q and -q both counted
};
S4Shells s4_shells(const S4Modes& m);

} // namespace dynhet::analysis
