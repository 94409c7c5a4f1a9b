// Stress test of the engine at the paper's hardest settings: phi = 0.805
// with eps = 0.7, and eps = 0.3 with the TC model, driven, N = 10^4; and an
// elastic undriven case at phi = 0.78 whose kinetic energy must not drift by
// more than 1e-10 (relative). Every `check_every` events per particle it
// scans for overlaps (cell based, O(N)), NaN, stalls (simulated time must
// advance), unbounded energy, and records the total momentum (the kicks
// conserve it: it must stay at roundoff).
// Prints a table; exits 1 if any check fails.
// Usage: stress_engine [--collisions 1e9] [--n 10000] [--case 0|1|2]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "dynhet/engine/engine.hpp"
#include "dynhet/model.hpp"

namespace {

struct Case {
  const char* name;
  double phi, eps, tc;
  bool driven;
};

bool run_case(const Case& c, long n, double collisions, double check_every) {
  dynhet::engine::Params p = dynhet::engine::paper_params(n, c.phi, c.eps, c.driven);
  p.tc = c.tc;
  p.seed = 11;
  dynhet::engine::Engine e(p);
  auto t0 = std::chrono::steady_clock::now();
  e.prepare();
  const double prep = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  t0 = std::chrono::steady_clock::now();

  const int64_t batch = static_cast<int64_t>(check_every * n);
  double worst_overlap = 0, ke_min = 1e300, ke_max = 0, p_max = 0;
  const double ke0 = e.kinetic_energy_per_particle();
  const bool elastic = c.eps == 1.0 && !c.driven;
  std::string failure;
  while (e.counters().collisions < collisions && failure.empty()) {
    const double t_before = e.time();
    const int64_t c_before = e.counters().collisions;
    // Run `batch` events, at whatever simulated time that takes.
    if (e.run_until(e.time() + 1e12, batch)) failure = "ran out of events (no collisions)";
    const double overlap = e.max_overlap(); // needs synchronised positions: they are computed at now
    worst_overlap = std::max(worst_overlap, overlap);
    const double ke = e.kinetic_energy_per_particle();
    ke_min = std::min(ke_min, ke);
    ke_max = std::max(ke_max, ke);
    std::vector<double> xy;
    e.unwrapped_positions(xy);
    for (double v : xy)
      if (!std::isfinite(v)) failure = "NaN or infinite position";
    if (!std::isfinite(ke)) failure = "NaN kinetic energy";
    if (overlap > 1e-9) failure = "overlap " + std::to_string(overlap) + " of a contact distance";
    if (!(e.time() > t_before)) failure = "stall: simulated time did not advance";
    if (e.counters().collisions - c_before > 0 &&
        (e.time() - t_before) * n < 1e-6 * (e.counters().collisions - c_before))
      failure = "stall: inelastic collapse (collisions without time)";
    if (ke < 1e-3 || ke > 1e3) failure = "kinetic energy per particle left [1e-3, 1e3]: " + std::to_string(ke);
    if (elastic && std::abs(ke / ke0 - 1) > 1e-10)
      failure = "elastic kinetic energy drifted by " + std::to_string(ke / ke0 - 1);
    double px, py;
    e.momentum(px, py);
    p_max = std::max(p_max, std::hypot(px, py));
  }
  const double drift = e.kinetic_energy_per_particle() / ke0 - 1;
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto& k = e.counters();
  std::printf("%-22s %6.3f %4.2f %8.0e %8.1f %12lld %12lld %10lld %10.3g %10.3g %10.2e %7.3f %7.3f %10.2e %9.1e  %s\n",
              c.name, c.phi, c.eps, c.tc, prep, static_cast<long long>(k.collisions),
              static_cast<long long>(k.kicks), static_cast<long long>(k.tc), k.collisions / wall,
              (k.collisions + k.kicks) / wall, std::max(0.0, worst_overlap), ke_min, ke_max, drift, p_max,
              failure.empty() ? "ok" : failure.c_str());
  std::fflush(stdout);
  return failure.empty();
}

} // namespace

int main(int argc, char** argv) {
  CLI::App app{"dynhet engine stress test"};
  double collisions = 1e9, check_every = 100;
  long n = 10000;
  app.add_option("--collisions", collisions, "collisions per case");
  app.add_option("--n", n, "particles");
  app.add_option("--check-every", check_every, "events per particle between checks");
  int only = -1;
  app.add_option("--case", only, "run only this case (0, 1 or 2)");
  CLI11_PARSE(app, argc, argv);

  std::printf("# stress test, N=%ld, %.3g collisions per case, checks every %g events per particle\n", n,
              collisions, check_every);
  std::printf("%-22s %6s %4s %8s %8s %12s %12s %10s %10s %10s %10s %7s %7s %10s %9s  %s\n", "case", "phi", "eps",
              "tc", "prep_s", "collisions", "kicks", "tc_acted", "coll/s", "events/s", "max_ovl", "KE_min",
              "KE_max", "dKE/KE", "max|P|", "result");
  const Case cases[] = {{"phi0.805_eps0.7", 0.805, 0.7, 0.0, true},
                        {"phi0.805_eps0.3_TC", 0.805, 0.3, 1e-4, true},
                        {"phi0.78_elastic", 0.78, 1.0, 0.0, false}};
  bool ok = true;
  for (int i = 0; i < 3; ++i)
    if (only < 0 || only == i) ok = run_case(cases[i], n, collisions, check_every) && ok;
  return ok ? 0 : 1;
}
