// S4(q,t) over time origins (the overline of paper eq. 15) for one sub-box
// grid, with errors over origins, and the OZ fits (eqs. 18, 20) at a lag
// with jackknife errors over origins. Each origin's S4(q) is one
// measurement; origins spaced by more than tau_alpha are independent, so
// the errors are honest then and lower bounds otherwise.
#pragma once

#include <vector>

#include "dynhet/analysis/fits.hpp"
#include "dynhet/analysis/lag_interpolation.hpp"
#include "dynhet/analysis/s4.hpp"

namespace dynhet::analysis {

class S4Accumulator {
public:
  // The shells (q and vector counts) are those s4_shells gives for the grid.
  S4Accumulator(int n_origins, int n_lags, std::vector<double> q, std::vector<int> n_vectors);

  // S4(q) of origin k at lag j (s4_shells of that pair).
  void add(int k, int j, const S4Shells& s);

  struct Mean {
    std::vector<double> s4, s4_err; // per shell: mean over origins, standard error
    int n_origins;
  };
  // Over the origins measured at lag j, leaving out origin `skip` (-1: none).
  Mean mean(int j, int skip = -1) const { return mean(j, skip, skip); }
  // The same, leaving out the origins skip_lo..skip_hi (a block).
  Mean mean(int j, int skip_lo, int skip_hi) const;
  bool has(int k, int j) const;

  const std::vector<double>& q() const { return q_; }
  const std::vector<int>& n_vectors() const { return n_vectors_; }
  int n_origins() const { return n_origins_; }
  // Origin k's S4 per shell at lag j (meaningful where has(k, j)).
  const double* at(int k, int j) const { return s4_.data() + (static_cast<size_t>(k) * n_lags_ + j) * q_.size(); }
  template <class Ar> void state(Ar& ar) { ar(s4_, filled_); } // what a checkpoint keeps

private:
  int n_origins_, n_lags_;
  std::vector<double> q_;
  std::vector<int> n_vectors_;
  std::vector<double> s4_;    // [(k * n_lags + j) * n_shells + shell]
  std::vector<char> filled_;  // per (k, j)
};

// The OZ form (eq. 18) and the form with A^2 (q xi)^4 (eq. 20) fitted to the
// origin mean of S4 at lag j over q xi <= qxi_max (unweighted: relative
// residuals, since standard errors from a few origins are themselves
// noisy); the parameter errors are the jackknife over origins (each fit
// repeated without one origin), NaN with fewer than 3 origins.
// xi is not determined, and NaN with a note in the fit's `note`, where the
// sub-box cannot hold it (fewer than 3 shells with q xi <= qxi_max; chi0 is
// then NaN too), where it lies below the q range (q xi < kQxiResolved at
// the largest q fitted: S4 has hardly begun to fall; chi0 stays) or where
// its jackknife error is not below it.
constexpr double kQxiResolved = 0.5;
struct S4FitAtLag {
  OzFit oz, oz_a2; // chi0_err, xi_err, a_err replaced by the jackknife errors
  int n_origins;
};
S4FitAtLag fit_s4_at_lag(const S4Accumulator& acc, int j, double qxi_max = 1.0);

// The OZ fit (eq. 18) to the origin mean of S4 at lag j, time lag_time,
// with the errors of xi and chi0 from a jackknife over blocks of
// consecutive origins measured at that lag, each block spanning the lag
// (origin_block, fits.hpp: origins closer than the lag measure overlapping
// windows of the same trajectories, so single origins left out would miss
// their correlation). xi(t) at every lag, where fit_s4_at_lag gives it at
// t_s4 alone. xi follows keep_determined_xi without its error rule (the
// lag's xi is reported whatever its error; `rule` says why it is NaN: 0
// kept, 1 too few shells, 2 below the q range, 3 no fit). An error is NaN
// where its value is, where fewer than 3 blocks remain, where a
// replicate's fit fails, and where blocks spanning the lag do not fit
// kMinJackknifeBlocks times into the origins (origin_blocks_span: the
// capped blocks would be correlated and the error too small; the rule of
// tau_alpha's error).
struct S4LagFit {
  OzFit oz; // chi0, xi and their jackknife errors (no A^2 form)
  int rule;
  int block; // origins per jackknife block
};
S4LagFit fit_s4_lag(const S4Accumulator& acc, int j, double lag_time, double origin_spacing, double qxi_max = 1.0);

// The same rules for one fit, wherever a xi is reported (the fit at every
// lag included): xi (and chi0 where the sub-box cannot hold it) set to NaN
// with the reason in f.note, where the fit's range held too few shells or
// xi lies below the q range; with check_error, also where xi_err is not
// below xi. Returns false where xi was set to NaN.
bool keep_determined_xi(OzFit& f, double qxi_max, bool check_error = true);

// chi4 of the whole box at one lag, where the sub-box average of eq. (14)
// has one term: N_tot times the variance over origins of Q(t;t0) (n/(n-1)
// corrected), with its jackknife error. NaN below 2 (error 3) origins.
ValueErr whole_box_chi4(const std::vector<double>& q_per_origin, double n_total);

// At a time t between two computed lags (b from bracket_lag over the
// accumulator's lags): S4 per origin measured at both lags, (1 - w) S4(lo)
// + w S4(hi), linear in ln t, as the one lag of a new accumulator; so the
// mean, its standard error and the jackknife of the fits run over origins
// exactly as at a lag, and the correlation of the two lags (they share
// their origins) is kept.
S4Accumulator interpolate_s4(const S4Accumulator& acc, const LagBracket& b);

// The origin mean of S4 and the fits at t: fit_s4_at_lag on interpolate_s4,
// each error with the interpolation's own in quadrature: per shell
// |quadratic - linear| in ln t through the origin means at lo, hi and the
// third lag (quadratic_minus_linear), and for chi0, xi, A the difference of
// the fits to the linearly and to the quadratically interpolated mean
// (where the latter fit gives no number, none is added). xi's notes
// (fit_s4_at_lag) judge the total error.
struct S4AtTime {
  S4Accumulator::Mean mean; // s4_err: the standard error over origins and the interpolation error
  S4FitAtLag fit;
};
S4AtTime fit_s4_at_time(const S4Accumulator& acc, const LagBracket& b, double qxi_max = 1.0);

// whole_box_chi4 at t: (1 - w) chi4(lo) + w chi4(hi) over the origins with
// Q at both lags (chi4 is a variance over origins: Q is not interpolated per
// origin, which would lower it by w (1 - w) N var(Q_hi - Q_lo)); the
// jackknife over those origins of the interpolated value, and the
// interpolation error from chi4 at the third lag in quadrature.
ValueErr whole_box_chi4_at_time(const std::vector<double>& q_lo, const std::vector<double>& q_hi,
                                const std::vector<double>& q_third, const LagBracket& b, double n_total);

} // namespace dynhet::analysis
