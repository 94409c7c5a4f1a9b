#include "dynhet/analysis/s4_average.hpp"

#include <cstdio>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace dynhet::analysis {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Jackknife standard error from the n leave-one-out estimates (fits.hpp's
// jackknife_error), NaN below 3 estimates: S4's errors need at least three
// origins.
double jackknife_error_3(const std::vector<double>& x) {
  return x.size() < 3 ? kNaN : jackknife_error(x);
}

} // namespace

S4Accumulator::S4Accumulator(int n_origins, int n_lags, std::vector<double> q, std::vector<int> n_vectors)
    : n_origins_(n_origins), n_lags_(n_lags), q_(std::move(q)), n_vectors_(std::move(n_vectors)),
      s4_(static_cast<size_t>(n_origins) * n_lags * q_.size(), kNaN),
      filled_(static_cast<size_t>(n_origins) * n_lags, 0) {}

void S4Accumulator::add(int k, int j, const S4Shells& s) {
  if (s.s4.size() != q_.size()) throw std::invalid_argument("S4Accumulator: shells of another grid");
  std::copy(s.s4.begin(), s.s4.end(), s4_.begin() + (static_cast<size_t>(k) * n_lags_ + j) * q_.size());
  filled_[static_cast<size_t>(k) * n_lags_ + j] = 1;
}

bool S4Accumulator::has(int k, int j) const { return filled_[static_cast<size_t>(k) * n_lags_ + j] != 0; }

S4Accumulator::Mean S4Accumulator::mean(int j, int skip_lo, int skip_hi) const {
  const size_t ns = q_.size();
  std::vector<double> sum(ns, 0.0), sum2(ns, 0.0);
  int n = 0;
  for (int k = 0; k < n_origins_; ++k) {
    if ((k >= skip_lo && k <= skip_hi) || !has(k, j)) continue;
    const double* v = at(k, j);
    for (size_t s = 0; s < ns; ++s) sum[s] += v[s], sum2[s] += v[s] * v[s];
    ++n;
  }
  Mean m{std::vector<double>(ns, kNaN), std::vector<double>(ns, kNaN), n};
  for (size_t s = 0; s < ns && n > 0; ++s) {
    m.s4[s] = sum[s] / n; // the overline of eq. (15)
    if (n > 1) m.s4_err[s] = std::sqrt(std::max(0.0, (sum2[s] / n - m.s4[s] * m.s4[s]) / (n - 1)));
  }
  return m;
}

namespace {

// fit_s4_at_lag without the notes: the fits to the origin mean at lag j,
// their errors the jackknife over origins.
S4FitAtLag jackknife_fits(const S4Accumulator& acc, int j, double qxi_max) {
  const S4Accumulator::Mean all = acc.mean(j);
  S4FitAtLag out{fit_oz(acc.q(), all.s4, {}, qxi_max), fit_oz_a2(acc.q(), all.s4, {}, qxi_max), all.n_origins};
  // Leave-one-out fits: chi0, xi (both forms) and A.
  std::vector<double> chi0, xi, chi0_a2, xi_a2, a;
  for (int k = 0; k < acc.n_origins(); ++k) {
    if (!acc.has(k, j)) continue;
    const std::vector<double> s4 = acc.mean(j, k).s4;
    const OzFit f = fit_oz(acc.q(), s4, {}, qxi_max), g = fit_oz_a2(acc.q(), s4, {}, qxi_max);
    chi0.push_back(f.chi0), xi.push_back(f.xi);
    chi0_a2.push_back(g.chi0), xi_a2.push_back(g.xi), a.push_back(g.a);
  }
  out.oz.chi0_err = jackknife_error_3(chi0), out.oz.xi_err = jackknife_error_3(xi);
  out.oz_a2.chi0_err = jackknife_error_3(chi0_a2), out.oz_a2.xi_err = jackknife_error_3(xi_a2);
  out.oz_a2.a_err = jackknife_error_3(a);
  return out;
}

// Where xi is not determined, say so instead of printing a number.
void flag_undetermined(S4FitAtLag& out, double qxi_max) {
  for (OzFit* f : {&out.oz, &out.oz_a2}) keep_determined_xi(*f, qxi_max);
}

// err and |a - b| in quadrature; err unchanged where a or b is not finite.
double with_difference(double err, double a, double b) {
  return std::isfinite(a) && std::isfinite(b) ? std::hypot(err, a - b) : err;
}

} // namespace

bool keep_determined_xi(OzFit& f, double qxi_max, bool check_error) {
  if (!std::isfinite(f.xi)) return false;
  char buf[200];
  if (!f.range_ok) {
    std::snprintf(buf, sizeof buf, "beyond the sub-box: fewer than 3 shells with q xi <= %g", qxi_max);
    f.note = buf, f.xi = f.xi_err = f.chi0 = f.chi0_err = kNaN;
  } else if (f.q_fit_max * f.xi < kQxiResolved) {
    std::snprintf(buf, sizeof buf, "below the q range: q xi reaches only %.2g at q_max", f.q_fit_max * f.xi);
    f.note = buf, f.xi = f.xi_err = kNaN;
  } else if (check_error && !(f.xi_err < f.xi)) {
    std::snprintf(buf, sizeof buf, "the jackknife error (%.3g) is not below xi (%.3g)", f.xi_err, f.xi);
    f.note = buf, f.xi = f.xi_err = kNaN;
  } else {
    return true;
  }
  return false;
}

S4FitAtLag fit_s4_at_lag(const S4Accumulator& acc, int j, double qxi_max) {
  S4FitAtLag out = jackknife_fits(acc, j, qxi_max);
  flag_undetermined(out, qxi_max);
  return out;
}

S4LagFit fit_s4_lag(const S4Accumulator& acc, int j, double lag_time, double origin_spacing, double qxi_max) {
  S4LagFit out{fit_oz(acc.q(), acc.mean(j).s4, {}, qxi_max), 0, 1};
  OzFit& f = out.oz;
  f.xi_err = f.chi0_err = kNaN;
  const bool fitted = std::isfinite(f.xi), range_ok = f.range_ok;
  const bool kept = keep_determined_xi(f, qxi_max, false);
  out.rule = !fitted ? 3 : kept ? 0 : !range_ok ? 1 : 2;
  if (!std::isfinite(f.chi0)) return out;
  std::vector<int> used; // the origins measured at lag j
  for (int k = 0; k < acc.n_origins(); ++k)
    if (acc.has(k, j)) used.push_back(k);
  const int n = static_cast<int>(used.size());
  out.block = origin_block(lag_time, origin_spacing, n);
  if (!origin_blocks_span(lag_time, origin_spacing, n)) return out;
  // Each block of consecutive measured origins left out in turn, the fit
  // made again by the same rule, its range included (as fit_s4_at_lag's
  // replicates). The range moves with xi, a shell at a time, and that is
  // part of the spread of independent runs: replicates held to the full
  // fit's shells gave 0.65-0.8 of the seeds' spread (a third of it where
  // xi rises through the q range). Moving with it, the jackknife scales up
  // a replicate's jump of the edge by one shell: 1.2-1.3 times the spread
  // with few shells in the range (N = 1024-2048), nearer 1 as the box
  // grows (docs/analysis.md, "Honest errors").
  std::vector<double> xi, chi0;
  for (int first = 0; first < n; first += out.block) {
    const int last = std::min(n, first + out.block) - 1;
    const OzFit r = fit_oz(acc.q(), acc.mean(j, used[first], used[last]).s4, {}, qxi_max);
    xi.push_back(r.xi), chi0.push_back(r.chi0);
  }
  f.chi0_err = jackknife_error_3(chi0);
  if (std::isfinite(f.xi)) f.xi_err = jackknife_error_3(xi);
  return out;
}

S4Accumulator interpolate_s4(const S4Accumulator& acc, const LagBracket& b) {
  if (!b.ok()) throw std::invalid_argument("interpolate_s4: the time is not between two lags");
  S4Accumulator out(acc.n_origins(), 1, acc.q(), acc.n_vectors());
  S4Shells s;
  for (int k = 0; k < acc.n_origins(); ++k) {
    if (!acc.has(k, b.lo) || !acc.has(k, b.hi)) continue;
    const double *lo = acc.at(k, b.lo), *hi = acc.at(k, b.hi);
    s.s4.resize(acc.q().size());
    for (size_t v = 0; v < s.s4.size(); ++v) s.s4[v] = interpolate(b, lo[v], hi[v]);
    out.add(k, 0, s);
  }
  return out;
}

S4AtTime fit_s4_at_time(const S4Accumulator& acc, const LagBracket& b, double qxi_max) {
  const S4Accumulator at = interpolate_s4(acc, b);
  S4AtTime out{at.mean(0), jackknife_fits(at, 0, qxi_max)};
  // The quadratic through the origin means at the three lags, per shell.
  const S4Accumulator::Mean lo = acc.mean(b.lo), hi = acc.mean(b.hi);
  const S4Accumulator::Mean third = b.third >= 0 ? acc.mean(b.third) : S4Accumulator::Mean{};
  std::vector<double> quad = out.mean.s4;
  for (size_t v = 0; v < quad.size(); ++v) {
    const double d = quadratic_minus_linear(b, lo.s4[v], hi.s4[v], b.third >= 0 ? third.s4[v] : kNaN);
    quad[v] += d;
    out.mean.s4_err[v] = std::hypot(out.mean.s4_err[v], d);
  }
  // The fits' interpolation error: linear against quadratic S4.
  const OzFit f = fit_oz(acc.q(), quad, {}, qxi_max), g = fit_oz_a2(acc.q(), quad, {}, qxi_max);
  OzFit &oz = out.fit.oz, &a2 = out.fit.oz_a2;
  oz.chi0_err = with_difference(oz.chi0_err, oz.chi0, f.chi0), oz.xi_err = with_difference(oz.xi_err, oz.xi, f.xi);
  a2.chi0_err = with_difference(a2.chi0_err, a2.chi0, g.chi0), a2.xi_err = with_difference(a2.xi_err, a2.xi, g.xi);
  a2.a_err = with_difference(a2.a_err, a2.a, g.a);
  flag_undetermined(out.fit, qxi_max);
  return out;
}

ValueErr whole_box_chi4(const std::vector<double>& q_per_origin, double n_total) {
  std::vector<double> q;
  for (double v : q_per_origin)
    if (!std::isnan(v)) q.push_back(v);
  // N_tot times the sample variance of the values other than `skip`.
  auto chi4 = [&](size_t skip) {
    double sum = 0, sum2 = 0;
    size_t n = 0;
    for (size_t k = 0; k < q.size(); ++k)
      if (k != skip) sum += q[k], sum2 += q[k] * q[k], ++n;
    return n > 1 ? n_total * (sum2 - sum * sum / n) / (n - 1) : kNaN;
  };
  std::vector<double> loo;
  for (size_t k = 0; k < q.size(); ++k) loo.push_back(chi4(k));
  return {chi4(q.size()), jackknife_error_3(loo)};
}

} // namespace dynhet::analysis

namespace dynhet::analysis {

ValueErr whole_box_chi4_at_time(const std::vector<double>& q_lo, const std::vector<double>& q_hi,
                                const std::vector<double>& q_third, const LagBracket& b, double n_total) {
  // The origins with Q at both lags.
  std::vector<double> lo, hi;
  for (size_t k = 0; k < q_lo.size() && k < q_hi.size(); ++k)
    if (!std::isnan(q_lo[k]) && !std::isnan(q_hi[k])) lo.push_back(q_lo[k]), hi.push_back(q_hi[k]);
  // N_tot times the sample variance of the values other than `skip`, interpolated.
  auto chi4 = [&](size_t skip) {
    double s_lo = 0, s2_lo = 0, s_hi = 0, s2_hi = 0;
    size_t n = 0;
    for (size_t k = 0; k < lo.size(); ++k)
      if (k != skip) s_lo += lo[k], s2_lo += lo[k] * lo[k], s_hi += hi[k], s2_hi += hi[k] * hi[k], ++n;
    if (n < 2) return kNaN;
    return interpolate(b, n_total * (s2_lo - s_lo * s_lo / n) / (n - 1), n_total * (s2_hi - s_hi * s_hi / n) / (n - 1));
  };
  std::vector<double> loo;
  for (size_t k = 0; k < lo.size(); ++k) loo.push_back(chi4(k));
  const double value = chi4(lo.size());
  const double v_lo = whole_box_chi4(lo, n_total).value, v_hi = whole_box_chi4(hi, n_total).value;
  const double d = b.third >= 0 ? quadratic_minus_linear(b, v_lo, v_hi, whole_box_chi4(q_third, n_total).value) : 0.0;
  return {value, std::hypot(jackknife_error_3(loo), d)};
}

} // namespace dynhet::analysis
