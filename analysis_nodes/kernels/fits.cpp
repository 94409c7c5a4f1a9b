#include "dynhet/analysis/fits.hpp"

#include <functional>

#include <algorithm>
#include <cmath>
#include <limits>

namespace dynhet::analysis {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = 3.14159265358979323846;

// Jacobian of r by central differences.
Eigen::MatrixXd jacobian(const Residuals& r, const Eigen::VectorXd& p, Eigen::Index m) {
  Eigen::MatrixXd j(m, p.size());
  for (Eigen::Index k = 0; k < p.size(); ++k) {
    const double h = 1e-6 * std::max(std::abs(p[k]), 1e-3);
    Eigen::VectorXd a = p, b = p;
    a[k] += h, b[k] -= h;
    j.col(k) = (r(a) - r(b)) / (2 * h);
  }
  return j;
}

// Covariance scale: 1 if the data carried errors, else chi2/dof.
double scale(const LmResult& f, bool have_errors) { return have_errors || f.dof <= 0 ? 1.0 : f.chi2 / f.dof; }

double error_of(const LmResult& f, int k, double s) { return std::sqrt(std::max(0.0, s * f.cov(k, k))); }

// Mean of f(n) over the integers lo..hi: summed when few, else integrated in
// ln n over [lo - 1/2, hi + 1/2] by Simpson's rule (the midpoint form of the
// sum; error far below the Poisson noise of a bin).
double bin_mean(const std::function<double(double)>& f, long lo, long hi) {
  if (hi - lo < 64) {
    double s = 0;
    for (long n = lo; n <= hi; ++n) s += f(double(n));
    return s / double(hi - lo + 1);
  }
  const int m = 128;
  const double u0 = std::log(lo - 0.5), u1 = std::log(hi + 0.5), h = (u1 - u0) / m;
  double s = 0;
  for (int k = 0; k <= m; ++k) {
    const double u = u0 + k * h, w = (k == 0 || k == m) ? 1 : (k % 2 ? 4 : 2);
    s += w * f(std::exp(u)) * std::exp(u);
  }
  return s * h / 3 / double(hi - lo + 1);
}

// Bins of h usable for a fit: inside [n_lo, n_hi] with at least min_count.
std::vector<int> usable_bins(const SizeHistogram& h, long n_lo, long n_hi, long min_count) {
  std::vector<int> b;
  for (size_t k = 0; k < h.count.size(); ++k)
    if (h.lo[k] >= n_lo && h.hi[k] <= n_hi && h.count[k] >= min_count && h.count[k] > 0)
      b.push_back(static_cast<int>(k));
  return b;
}

// Residuals sqrt(count) (ln p - ln model-bin-mean) for a size model f(n; params).
Residuals size_residuals(const SizeHistogram& h, const std::vector<int>& bins,
                         std::function<double(double, const Eigen::VectorXd&)> model) {
  return [&h, bins, model](const Eigen::VectorXd& p) {
    Eigen::VectorXd r(bins.size());
    for (size_t k = 0; k < bins.size(); ++k) {
      const int b = bins[k];
      const double m = bin_mean([&](double n) { return model(n, p); }, h.lo[b], h.hi[b]);
      r[k] = std::sqrt(double(h.count[b])) * (std::log(h.p[b]) - std::log(m));
    }
    return r;
  };
}

} // namespace

double jackknife_error(const std::vector<double>& x) {
  const size_t n = x.size();
  if (n < 2 || std::any_of(x.begin(), x.end(), [](double v) { return std::isnan(v); }))
    return std::numeric_limits<double>::quiet_NaN();
  double mean = 0, s2 = 0;
  for (double v : x) mean += v / n;
  for (double v : x) s2 += (v - mean) * (v - mean);
  return std::sqrt(s2 * (n - 1) / n);
}

std::vector<double> origin_jackknife(const std::vector<double>& table, int n_origins, int n_lags,
                                     const std::function<std::vector<double>(const std::vector<double>&)>& estimate,
                                     int block) {
  std::vector<int> used;
  for (int k = 0; k < n_origins; ++k)
    for (int j = 0; j < n_lags; ++j)
      if (!std::isnan(table[size_t(k) * n_lags + j])) {
        used.push_back(k);
        break;
      }
  const int u = static_cast<int>(used.size());
  if (u < 2) return {};
  const int b = std::clamp(block, 1, std::max(1, u / 2));
  const int blocks = (u + b - 1) / b;
  std::vector<std::vector<double>> rep; // [estimate][block]
  for (int blk = 0; blk < blocks; ++blk) {
    std::vector<char> skip(n_origins, 0);
    for (int i = blk * b; i < std::min(u, (blk + 1) * b); ++i) skip[used[i]] = 1;
    std::vector<double> mean(n_lags, std::numeric_limits<double>::quiet_NaN());
    for (int j = 0; j < n_lags; ++j) {
      double s = 0;
      int n = 0;
      for (int k : used)
        if (const double v = table[size_t(k) * n_lags + j]; !skip[k] && !std::isnan(v)) s += v, ++n;
      if (n) mean[j] = s / n;
    }
    const std::vector<double> e = estimate(mean);
    rep.resize(e.size());
    for (size_t i = 0; i < e.size(); ++i) rep[i].push_back(e[i]);
  }
  std::vector<double> err(rep.size());
  for (size_t i = 0; i < rep.size(); ++i) err[i] = jackknife_error(rep[i]);
  return err;
}

int origin_block(double longest_lag, double origin_spacing, int n_origins) {
  if (!(origin_spacing > 0) || !std::isfinite(longest_lag) || !(longest_lag > 0)) return 1;
  const int span = static_cast<int>(std::ceil(longest_lag / origin_spacing - 1e-9));
  return std::clamp(span, 1, std::max(1, n_origins / kMinJackknifeBlocks));
}

bool origin_blocks_span(double longest_lag, double origin_spacing, int n_origins) {
  if (!(origin_spacing > 0) || !std::isfinite(longest_lag) || !(longest_lag > 0)) return true;
  return std::ceil(longest_lag / origin_spacing - 1e-9) <= std::max(1, n_origins / kMinJackknifeBlocks);
}

std::vector<int> overlap_fit_lags(const std::vector<double>& q, double q_lo, double q_hi) {
  std::vector<int> out;
  for (size_t j = 0; j < q.size(); ++j)
    if (q[j] >= q_lo && q[j] <= q_hi) out.push_back(static_cast<int>(j));
  if (out.size() < 3) out.clear();
  return out;
}

LinearFit linear_fit(const std::vector<double>& x, const std::vector<double>& y,
                     const std::vector<double>& w) {
  double s = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  const int n = static_cast<int>(x.size());
  for (int i = 0; i < n; ++i) {
    const double wi = w.empty() ? 1.0 : w[i];
    s += wi, sx += wi * x[i], sy += wi * y[i], sxx += wi * x[i] * x[i], sxy += wi * x[i] * y[i];
  }
  LinearFit f{kNaN, kNaN, kNaN, kNaN, kNaN, n};
  const double det = s * sxx - sx * sx;
  if (n < 2 || det <= 0) return f;
  f.slope = (s * sxy - sx * sy) / det;
  f.intercept = (sxx * sy - sx * sxy) / det;
  f.chi2 = 0;
  for (int i = 0; i < n; ++i) {
    const double d = y[i] - f.slope * x[i] - f.intercept;
    f.chi2 += (w.empty() ? 1.0 : w[i]) * d * d;
  }
  // Without weights the errors come from the scatter (chi2/dof); with
  // weights 1/sigma^2 they are the formal ones.
  const double sc = w.empty() ? (n > 2 ? f.chi2 / (n - 2) : kNaN) : 1.0;
  f.slope_err = std::sqrt(sc * s / det);
  f.intercept_err = std::sqrt(sc * sxx / det);
  return f;
}

LmResult levenberg_marquardt(const Residuals& res, Eigen::VectorXd p, int max_iter) {
  Eigen::VectorXd r = res(p);
  double chi2 = r.squaredNorm(), lambda = 1e-3;
  bool converged = false;
  for (int it = 0; it < max_iter && !converged; ++it) {
    const Eigen::MatrixXd j = jacobian(res, p, r.size());
    const Eigen::MatrixXd a = j.transpose() * j;
    const Eigen::VectorXd g = j.transpose() * r;
    for (int tries = 0; tries < 20; ++tries) {
      Eigen::MatrixXd damped = a;
      damped.diagonal() += lambda * a.diagonal().cwiseMax(1e-12);
      const Eigen::VectorXd step = damped.ldlt().solve(-g);
      const Eigen::VectorXd pn = p + step;
      const Eigen::VectorXd rn = res(pn);
      const double c2 = rn.squaredNorm();
      if (std::isfinite(c2) && c2 <= chi2) {
        converged = chi2 - c2 <= 1e-12 * (chi2 + 1e-300) || step.norm() <= 1e-12 * (p.norm() + 1e-12);
        p = pn, r = rn, chi2 = c2, lambda = std::max(lambda / 10, 1e-12);
        break;
      }
      lambda *= 10;
      if (tries == 19) converged = true; // no downhill step left: at the minimum
    }
  }
  const Eigen::MatrixXd j = jacobian(res, p, r.size());
  const Eigen::MatrixXd a = j.transpose() * j;
  return {p, a.completeOrthogonalDecomposition().pseudoInverse(), chi2, static_cast<int>(r.size() - p.size()),
          converged};
}

OverlapFit fit_overlap(const std::vector<double>& t, const std::vector<double>& q,
                       const std::vector<double>& q_err) {
  std::vector<double> ts, qs, es, lx, ly;
  for (size_t j = 0; j < t.size(); ++j) {
    if (!std::isfinite(q[j]) || t[j] <= 0) continue;
    ts.push_back(t[j]), qs.push_back(q[j]), es.push_back(q_err.empty() ? 1.0 : q_err[j]);
    // Linearised: ln(1/Q - 1) = beta ln t - beta ln tau0.
    if (q[j] > 0.02 && q[j] < 0.98) lx.push_back(std::log(t[j])), ly.push_back(std::log(1 / q[j] - 1));
  }
  OverlapFit out{kNaN, kNaN, kNaN, kNaN, kNaN, static_cast<int>(ts.size())};
  // A lag where every origin gives the same Q (Q = 1 at the shortest lags)
  // has an error of 0 up to roundoff: weighted by 1/err^2 it would own the
  // fit. Such errors (below 1e-9 of the largest) count as the smallest of
  // the others; with no other, the fit is unweighted.
  if (!q_err.empty()) {
    const double big = *std::max_element(es.begin(), es.end());
    double floor = kNaN;
    for (double e : es)
      if (e > 1e-9 * big && !(e >= floor)) floor = e;
    for (double& e : es) e = std::isfinite(floor) ? std::max(e, floor) : 1.0;
  }
  const LinearFit lin = linear_fit(lx, ly);
  if (ts.size() < 3 || !std::isfinite(lin.slope) || lin.slope <= 0) return out;
  Eigen::VectorXd p0(2);
  p0 << lin.slope, -lin.intercept / lin.slope; // beta, ln tau0
  auto model = [](double t, const Eigen::VectorXd& p) {
    return 1 / (std::pow(t / std::exp(p[1]), p[0]) + 1);
  };
  const LmResult f = levenberg_marquardt(
      [&](const Eigen::VectorXd& p) {
        Eigen::VectorXd r(ts.size());
        for (size_t j = 0; j < ts.size(); ++j) r[j] = (qs[j] - model(ts[j], p)) / es[j]; // eq. (8)
        return r;
      },
      p0);
  const double s = scale(f, !q_err.empty());
  if (!(f.p[0] > 0) || !std::isfinite(f.p[1])) return out; // ran away: no fit (NaN)
  out.beta = f.p[0], out.beta_err = error_of(f, 0, s);
  out.tau0 = std::exp(f.p[1]), out.tau0_err = out.tau0 * error_of(f, 1, s);
  out.chi2 = f.chi2;
  return out;
}

DiffusionFit fit_diffusion(const std::vector<double>& t, const std::vector<double>& msd, double t_min,
                           double t_max, const std::vector<double>& msd_err) {
  std::vector<double> x, y, w;
  for (size_t j = 0; j < t.size(); ++j) {
    if (t[j] < t_min || t[j] > t_max || !std::isfinite(msd[j])) continue;
    x.push_back(t[j]), y.push_back(msd[j]);
    if (!msd_err.empty()) w.push_back(1 / (msd_err[j] * msd_err[j]));
  }
  const LinearFit f = linear_fit(x, y, w);
  return {f.slope / 4, f.slope_err / 4, f.intercept, t_min, t_max, f.n}; // Delta(t) = 4 D t + b
}

double diffusive_onset(const std::vector<double>& t, const std::vector<double>& msd, double tol) {
  double onset = kNaN;
  for (size_t j = t.size(); j-- > 1;) {
    const double slope = std::log(msd[j] / msd[j - 1]) / std::log(t[j] / t[j - 1]);
    if (!(std::abs(slope - 1) <= tol)) break;
    onset = t[j - 1];
  }
  return onset;
}

GaussianFit fit_gaussian_displacement(const std::vector<double>& x, const std::vector<double>& p,
                                      const std::vector<long>& count, double t) {
  std::vector<int> b;
  double s = 0, sx2 = 0;
  for (size_t k = 0; k < x.size(); ++k)
    if (count[k] > 0) b.push_back(static_cast<int>(k)), s += count[k], sx2 += count[k] * x[k] * x[k];
  GaussianFit out{kNaN, kNaN, static_cast<int>(b.size())};
  if (b.size() < 2) return out;
  Eigen::VectorXd p0(1);
  p0 << std::log(sx2 / s / (2 * t)); // ln D from <dx^2> = 2 D t
  const LmResult f = levenberg_marquardt(
      [&](const Eigen::VectorXd& q) {
        const double fourdt = 4 * std::exp(q[0]) * t;
        Eigen::VectorXd r(b.size());
        for (size_t k = 0; k < b.size(); ++k) {
          const double lnpg = -x[b[k]] * x[b[k]] / fourdt - 0.5 * std::log(kPi * fourdt); // ln P_g
          r[k] = std::sqrt(double(count[b[k]])) * (std::log(p[b[k]]) - lnpg);
        }
        return r;
      },
      p0);
  out.d = std::exp(f.p[0]);
  out.d_err = out.d * error_of(f, 0, scale(f, false));
  return out;
}

ExpTailFit fit_exponential_tail(const std::vector<double>& x, const std::vector<double>& p,
                                const std::vector<long>& count, double x_min) {
  std::vector<double> ax, lp, w;
  for (size_t k = 0; k < x.size(); ++k)
    if (count[k] > 0 && std::abs(x[k]) >= x_min)
      ax.push_back(std::abs(x[k])), lp.push_back(std::log(p[k])), w.push_back(double(count[k]));
  // ln P_e = ln A - |dx|/x0; var(ln count) = 1/count, hence weights count.
  const LinearFit f = linear_fit(ax, lp, w);
  const double x0 = -1 / f.slope;
  return {x0, f.slope_err / (f.slope * f.slope), std::exp(f.intercept), x_min, f.n};
}

PowerLawFit fit_power_law(const SizeHistogram& h, long n_lo, long n_hi, long min_count) {
  const std::vector<int> bins = usable_bins(h, n_lo, n_hi, min_count);
  PowerLawFit out{kNaN, kNaN, kNaN, static_cast<int>(bins.size())};
  if (bins.size() < 2) return out;
  std::vector<double> lx, ly;
  for (int b : bins) lx.push_back(std::log(h.centre[b])), ly.push_back(std::log(h.p[b]));
  const LinearFit lin = linear_fit(lx, ly);
  Eigen::VectorXd p0(2);
  p0 << lin.intercept, -lin.slope; // ln C, kappa
  const LmResult f = levenberg_marquardt(
      size_residuals(h, bins,
                     [](double n, const Eigen::VectorXd& p) { return std::exp(p[0]) * std::pow(n, -p[1]); }),
      p0);
  out.kappa = f.p[1], out.amplitude = std::exp(f.p[0]);
  out.kappa_err = error_of(f, 1, scale(f, false));
  return out;
}

LogNormalFit fit_log_normal(const SizeHistogram& h, long min_count) {
  const std::vector<int> bins = usable_bins(h, 1, std::numeric_limits<long>::max(), min_count);
  LogNormalFit out{kNaN, kNaN, kNaN, kNaN, kNaN, kNaN, static_cast<int>(bins.size())};
  if (bins.size() < 3) return out;
  // Start: ln P = c0 + c1 u + c2 u^2 with u = ln N_c (a parabola in log-log).
  Eigen::MatrixXd a(bins.size(), 3);
  Eigen::VectorXd y(bins.size());
  for (size_t k = 0; k < bins.size(); ++k) {
    const double u = std::log(h.centre[bins[k]]), s = std::sqrt(double(h.count[bins[k]]));
    a.row(k) << s, s * u, s * u * u;
    y[k] = s * std::log(h.p[bins[k]]);
  }
  const Eigen::Vector3d c = a.colPivHouseholderQr().solve(y);
  const double sigma2 = c[2] < 0 ? -1 / (2 * c[2]) : 1.0, u_sigma = c[1] * sigma2;
  Eigen::VectorXd p0(3);
  p0 << c[0] + u_sigma * u_sigma / (2 * sigma2), u_sigma,
      0.5 * std::log(sigma2); // ln P0, ln N_sigma, ln sigma
  const LmResult f =
      levenberg_marquardt(size_residuals(h, bins,
                                         [](double n, const Eigen::VectorXd& p) {
                                           const double v = std::log(n) - p[1], s = std::exp(p[2]);
                                           return std::exp(p[0] - v * v / (2 * s * s)); // eq. (13)
                                         }),
                          p0);
  const double s = scale(f, false);
  out.p0 = std::exp(f.p[0]), out.n_sigma = std::exp(f.p[1]), out.sigma = std::exp(f.p[2]);
  out.n0 = out.n_sigma * std::exp(out.sigma * out.sigma); // N_sigma = N0 exp(-sigma^2)
  out.sigma_err = out.sigma * error_of(f, 2, s);
  // ln N0 = ln N_sigma + sigma^2: propagate through both, with their covariance.
  const double ds = 2 * out.sigma * out.sigma; // d(sigma^2)/d(ln sigma)
  const double var = f.cov(1, 1) + ds * ds * f.cov(2, 2) + 2 * ds * f.cov(1, 2);
  out.n0_err = out.n0 * std::sqrt(std::max(0.0, s * var));
  return out;
}

namespace {

// Shells used by an OZ-type fit: q > 0, finite S4, q xi <= qxi_max, at least
// `min_points` (then the first ones, range_ok false).
std::vector<int> oz_range(const std::vector<double>& q, const std::vector<double>& s4, double xi,
                          double qxi_max, int min_points, bool& ok) {
  std::vector<int> all, in;
  for (size_t k = 0; k < q.size(); ++k)
    if (q[k] > 0 && std::isfinite(s4[k]) && s4[k] > 0) all.push_back(static_cast<int>(k));
  std::sort(all.begin(), all.end(), [&](int a, int b) { return q[a] < q[b]; });
  for (int k : all)
    if (q[k] * xi <= qxi_max) in.push_back(k);
  ok = static_cast<int>(in.size()) >= min_points;
  if (!ok) in.assign(all.begin(), all.begin() + std::min<size_t>(all.size(), min_points));
  return in;
}

// 1/S4 = c0 + c1 q^2 (+ c2 q^4): the linearised OZ forms, weighted for
// relative errors of S4.
Eigen::VectorXd inverse_fit(const std::vector<double>& q, const std::vector<double>& s4,
                            const std::vector<int>& k, int terms) {
  Eigen::MatrixXd a(k.size(), terms);
  Eigen::VectorXd y(k.size());
  for (size_t i = 0; i < k.size(); ++i) {
    const double q2 = q[k[i]] * q[k[i]], w = s4[k[i]]; // sigma(1/S4) = rel. err / S4
    for (int c = 0; c < terms; ++c) a(i, c) = w * std::pow(q2, c);
    y[i] = 1.0;
  }
  return a.colPivHouseholderQr().solve(y);
}

// Least squares of S4 against chi0 / (1 + (q xi)^2 + A^2 (q xi)^4) over the
// shells k; p = (ln chi0, ln xi[, A]).
LmResult oz_lm(const std::vector<double>& q, const std::vector<double>& s4, const std::vector<double>& err,
               const std::vector<int>& k, Eigen::VectorXd p0) {
  return levenberg_marquardt(
      [&](const Eigen::VectorXd& p) {
        Eigen::VectorXd r(k.size());
        for (size_t i = 0; i < k.size(); ++i) {
          const double x2 = std::pow(q[k[i]] * std::exp(p[1]), 2), a2 = p.size() > 2 ? p[2] * p[2] : 0.0;
          const double model = std::exp(p[0]) / (1 + x2 + a2 * x2 * x2); // eqs. (18), (20)
          r[i] = (s4[k[i]] - model) / (err.empty() ? s4[k[i]] : err[k[i]]);
        }
        return r;
      },
      p0);
}

OzFit oz_result(const LmResult& f, const std::vector<double>& q, const std::vector<int>& k, bool have_err,
                bool ok) {
  const double s = scale(f, have_err);
  OzFit o{};
  o.chi0 = std::exp(f.p[0]), o.chi0_err = o.chi0 * error_of(f, 0, s);
  o.xi = std::exp(f.p[1]), o.xi_err = o.xi * error_of(f, 1, s);
  o.a = f.p.size() > 2 ? std::abs(f.p[2]) : 0.0;
  o.a_err = f.p.size() > 2 ? error_of(f, 2, s) : 0.0;
  o.q_fit_max = 0;
  for (int i : k) o.q_fit_max = std::max(o.q_fit_max, q[i]);
  o.n = static_cast<int>(k.size()), o.range_ok = ok;
  return o;
}

} // namespace

OzFit fit_oz(const std::vector<double>& q, const std::vector<double>& s4, const std::vector<double>& s4_err,
             double qxi_max) {
  bool ok = false;
  // Start: the linearised form over the five smallest q.
  std::vector<int> k = oz_range(q, s4, 0.0, qxi_max, 5, ok);
  if (k.size() < 3) return OzFit{kNaN, kNaN, 0, kNaN, kNaN, 0, kNaN, static_cast<int>(k.size()), false, ""};
  Eigen::VectorXd c = inverse_fit(q, s4, k, 2);
  Eigen::VectorXd p(2);
  p << -std::log(c[0]), 0.5 * std::log(std::max(c[1] / c[0], 1e-12));
  LmResult f{};
  for (int it = 0; it < 20; ++it) {
    const std::vector<int> range = oz_range(q, s4, std::exp(p[1]), qxi_max, 3, ok);
    f = oz_lm(q, s4, s4_err, range, p);
    p = f.p;
    const bool stable = range == k;
    k = range;
    if (stable && it > 0) break;
  }
  return oz_result(f, q, k, !s4_err.empty(), ok);
}

OzFit fit_oz_a2(const std::vector<double>& q, const std::vector<double>& s4,
                const std::vector<double>& s4_err, double qxi_max) {
  const OzFit oz = fit_oz(q, s4, s4_err, qxi_max);
  if (!std::isfinite(oz.xi)) return oz;
  bool ok = false;
  const std::vector<int> k = oz_range(q, s4, oz.xi, qxi_max, 4, ok); // the OZ fit's range
  const Eigen::VectorXd c = inverse_fit(q, s4, k, 3);
  const double xi2 = c[1] / c[0], a2 = c[2] / (c[0] * xi2 * xi2);
  Eigen::VectorXd p(3);
  if (c[0] > 0 && xi2 > 0 && a2 > 0)
    p << -std::log(c[0]), 0.5 * std::log(xi2), std::sqrt(a2);
  else
    p << std::log(oz.chi0), std::log(oz.xi), 0.1; // A = 0 is a stationary point: start off it
  return oz_result(oz_lm(q, s4, s4_err, k, p), q, k, !s4_err.empty(), ok);
}

OzRangeScan scan_oz_range(const std::vector<double>& q, const std::vector<double>& s4,
                          const std::vector<double>& qxi_max) {
  OzRangeScan r;
  r.qxi_max = qxi_max;
  for (double c : qxi_max) {
    OzFit f{}, g{};
    f.xi = f.chi0 = g.xi = g.chi0 = kNaN;
    try {
      f = fit_oz(q, s4, {}, c);
      if (!f.range_ok) f.xi = f.chi0 = kNaN;
    } catch (const std::exception&) {
      f.xi = f.chi0 = kNaN;
    }
    try {
      g = fit_oz_a2(q, s4, {}, c);
      if (!g.range_ok) g.xi = g.chi0 = kNaN;
    } catch (const std::exception&) {
      g.xi = g.chi0 = kNaN;
    }
    r.xi.push_back(f.xi), r.chi0.push_back(f.chi0), r.xi_a2.push_back(g.xi), r.chi0_a2.push_back(g.chi0);
  }
  return r;
}

double half_range(const std::vector<double>& v) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  int n = 0;
  for (double x : v)
    if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x), ++n;
  return n >= 2 ? (hi - lo) / 2 : kNaN;
}

} // namespace dynhet::analysis
