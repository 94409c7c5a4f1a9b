// The box-scale flows of the driven granular fluid against N: how long the
// longest waves take to relax, and how strong they are in the steady state.
// The transverse momentum of the longest waves, j = sum_i m_i v_x,i
// exp(i k y_i) with k = 2 pi / L (and the same with x and y swapped: two
// modes), is sampled every --dt from the start of the run, where
// thermalize() has put every mode at equipartition. Printed per N:
//  - R = <|j|^2> / (T sum_i m_i) in windows of the run: 1 at equipartition
//    (an elastic fluid in equilibrium), larger where the driven steady state
//    carries stronger long waves; its approach to the steady value is the
//    build-up a run's equilibration must outlast;
//  - tau_k, the integral of the normalised autocorrelation Re <j(t)
//    j*(t+s)> / <|j|^2> (over the second half of the run) up to where it
//    first falls below 0.05 (an exponential exp(-s / tau) gives 0.95 tau),
//    and that integral up to lags S = 3 ... 1000, I(S): a slow tail of
//    small amplitude (a slow circulation of the box) is what the first
//    crossing hides, and keeps I(S) growing. Where the waves oscillate
//    (shear waves) the plateau of I is Gamma / (Gamma^2 + omega^2), shorter
//    than the time their amplitude takes to relax, so also
//  - tau_env, the envelope's time: the last lag at which |autocorrelation|
//    reaches 0.2, over ln 5 (1 / Gamma for an envelope exp(-Gamma s); 0.2
//    lies some 4 noise levels above 0 for these run lengths);
//  - errors: the spread of the --seeds seeds (the two modes pooled within a
//    run), none for one seed.
// One engine at a time, the paper's system (radius ratio 1.43, eps, kicks
// to neighbour pairs at the Enskog frequency).
//
//   bench_flows --phi 0.78 --n 1024 --n 4096 --dt 0.2 --time-per-l2 0.16 --seeds 2
#include <cmath>
#include <complex>
#include <cstdio>
#include <numeric>
#include <vector>

#include <CLI/CLI.hpp>

#include "dynhet/engine/engine.hpp"

namespace {

struct Series {
  std::vector<std::complex<double>> j[2]; // the two modes
  std::vector<double> norm;               // T sum_i m_i at each sample
};

// The normalised autocorrelation Re <j(t) j*(t+s)> / <|j|^2> of both
// modes over samples [from, size), at lags 0 .. a quarter of those samples.
std::vector<double> autocorrelation(const Series& s, size_t from) {
  const size_t n = s.norm.size() - from, max_lag = n / 4;
  std::vector<double> c(max_lag + 1, 0.0);
  for (int m = 0; m < 2; ++m)
    for (size_t lag = 0; lag <= max_lag; ++lag) {
      double sum = 0;
      for (size_t t = from; t + lag < s.norm.size(); ++t) sum += std::real(s.j[m][t] * std::conj(s.j[m][t + lag]));
      c[lag] += sum / double(n - lag);
    }
  for (size_t lag = 1; lag <= max_lag; ++lag) c[lag] /= c[0];
  c[0] = 1;
  return c;
}

// tau_k: the integral of c up to where it first falls below 0.05 (NaN if
// it does not); I(S): the running integral of c up to lag S (trapezoids),
// which keeps growing past tau_k if the modes have a slow tail.
double relaxation_time(const std::vector<double>& c, double dt) {
  double tau = 0;
  for (size_t lag = 0; lag < c.size(); ++lag) {
    if (c[lag] < 0.05) return tau + 0.5 * c[lag] * dt;
    tau += (lag == 0 ? 0.5 : 1.0) * c[lag] * dt;
  }
  return NAN;
}
double envelope_time(const std::vector<double>& c, double dt) {
  size_t last = 0;
  for (size_t lag = 0; lag < c.size(); ++lag)
    if (std::fabs(c[lag]) >= 0.2) last = lag;
  return last + 1 < c.size() ? double(last) * dt / std::log(5.0) : NAN; // NaN: still above at the last lag
}
double running_integral(const std::vector<double>& c, double dt, double upto) {
  const size_t last = size_t(std::lround(upto / dt));
  if (last >= c.size()) return NAN;
  double sum = 0;
  for (size_t lag = 0; lag <= last; ++lag) sum += (lag == 0 || lag == last ? 0.5 : 1.0) * c[lag] * dt;
  return sum;
}

double ratio(const Series& s, size_t a, size_t b) {
  double r = 0;
  for (size_t t = a; t < b; ++t) r += (std::norm(s.j[0][t]) + std::norm(s.j[1][t])) / (2 * s.norm[t]);
  return r / double(b - a);
}

double mean(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / double(v.size()); }
double sem(const std::vector<double>& v) {
  if (v.size() < 2) return NAN;
  const double m = mean(v);
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / double(v.size() - 1) / double(v.size()));
}

const std::vector<double> kUpto{3, 10, 30, 100, 300, 1000};

} // namespace

int main(int argc, char** argv) {
  CLI::App app{"Box-scale flows of the driven fluid against N: tau_k of the longest transverse waves and their "
               "strength"};
  double phi = 0.78, eps = 0.9, dt = 0.2, time_per_l2 = 0.16;
  std::vector<long> ns{1024, 4096};
  int seeds = 2, first_seed = 1, windows = 6;
  app.add_option("--phi", phi, "packing fraction");
  app.add_option("--eps", eps, "restitution");
  app.add_option("--n", ns, "particle numbers");
  app.add_option("--dt", dt, "sampling interval");
  app.add_option("--time-per-l2", time_per_l2, "run length in units of L^2 (diffusing momentum relaxes as L^2)");
  app.add_option("--seeds", seeds, "independent runs per N")->check(CLI::Range(1, 100));
  app.add_option("--first-seed", first_seed, "the first run's seed (then +1, +2, ...)");
  app.add_option("--windows", windows, "windows of R(t) printed over the run")->check(CLI::Range(2, 50));
  CLI11_PARSE(app, argc, argv);
  std::printf("# phi %.3f, eps %.2f, neighbour kick pairs; R = <|j_k|^2> / (T sum m), k = 2 pi / L; "
              "tau_k from the autocorrelation over the second half\n", phi, eps);
  std::printf("%7s %7s %9s %5s %9s %8s %9s %8s %9s %8s  R in windows of the run (first to last)\n", "N", "L",
              "run", "runs", "tau_k", "+-", "tau_env", "+-", "R", "+-");
  for (long n : ns) {
    std::vector<double> taus, envs, rs, window_r(windows, 0.0);
    std::vector<std::vector<double>> integrals(kUpto.size());
    double box = 0, t_run = 0;
    for (int seed = first_seed; seed < first_seed + seeds; ++seed) {
      auto p = dynhet::engine::paper_params(n, phi, eps, true);
      p.seed = uint64_t(seed);
      dynhet::engine::Engine e(p);
      e.prepare();
      box = e.box_length();
      t_run = time_per_l2 * box * box;
      const double k = 2 * M_PI / box;
      std::vector<double> mass(n);
      double total_mass = 0;
      for (long i = 0; i < n; ++i) total_mass += mass[i] = e.mass(e.species()[i]);
      Series s;
      for (double t = 0; t <= t_run; t += dt) {
        e.run_until(t);
        const auto st = e.state();
        std::complex<double> j0 = 0, j1 = 0;
        double ke = 0;
        for (long i = 0; i < n; ++i) {
          j0 += mass[i] * st.vx[i] * std::polar(1.0, k * st.y[i]);
          j1 += mass[i] * st.vy[i] * std::polar(1.0, k * st.x[i]);
          ke += 0.5 * mass[i] * (st.vx[i] * st.vx[i] + st.vy[i] * st.vy[i]);
        }
        s.j[0].push_back(j0), s.j[1].push_back(j1);
        s.norm.push_back(dynhet::engine::temperature(ke / n, n) * total_mass);
      }
      const size_t half = s.norm.size() / 2;
      const auto c = autocorrelation(s, half);
      taus.push_back(relaxation_time(c, dt));
      envs.push_back(envelope_time(c, dt));
      for (size_t u = 0; u < kUpto.size(); ++u) integrals[u].push_back(running_integral(c, dt, kUpto[u]));
      rs.push_back(ratio(s, half, s.norm.size()));
      for (int w = 0; w < windows; ++w)
        window_r[w] += ratio(s, s.norm.size() * w / windows, s.norm.size() * (w + 1) / windows) / seeds;
    }
    std::printf("%7ld %7.1f %9.0f %5d %9.4g %8.2g %9.4g %8.2g %9.3g %8.2g ", n, box, t_run, seeds, mean(taus),
                sem(taus), mean(envs), sem(envs), mean(rs), sem(rs));
    for (double r : window_r) std::printf(" %.3g", r);
    std::printf("\n%7s running integral of the autocorrelation I(S) (a slow tail keeps it growing past tau_k):", "");
    for (size_t u = 0; u < kUpto.size(); ++u)
      if (std::isfinite(mean(integrals[u])))
        std::printf("  I(%g) %.3g +- %.2g", kUpto[u], mean(integrals[u]), sem(integrals[u]));
    std::printf("\n");
    std::fflush(stdout);
  }
}
