// The reduced pressure Z of elastic monodisperse hard disks against N, as
// sim_node computes it (engine.hpp reduced_pressure: the canonical Z at T =
// K/(N-1), blocks of simulation time, common/include/dynhet/stats.hpp
// RatioBlocks), the mechanical P A / (N T) of the fixed-momentum system
// (1/N lower), and as an earlier version computed it (T = K/N): a
// table per packing fraction. Each N runs for the same particle-time (N x T
// fixed), so the errors are comparable. bench/pressure_reference.py
// compares sim_node's Z with published high-precision data.
//
//   bench_pressure --phi 0.5 --phi 0.67 --n 100 --n 400 --n 900 --n 6400 --particle-time 6.4e6
#include <cmath>
#include <cstdio>
#include <vector>

#include <CLI/CLI.hpp>

#include "dynhet/engine/engine.hpp"
#include "dynhet/stats.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Z of elastic monodisperse hard disks against N (the N - 1 of a fixed total momentum)"};
  std::vector<double> phis{0.5, 0.67};
  std::vector<long> ns{100, 400, 900, 6400};
  double particle_time = 6.4e6, equilibrate = 50;
  uint64_t seed = 1;
  app.add_option("--phi", phis, "packing fractions");
  app.add_option("--n", ns, "particle numbers");
  app.add_option("--particle-time", particle_time, "N x measuring time per run");
  app.add_option("--seed", seed);
  CLI11_PARSE(app, argc, argv);
  std::printf("%6s %7s %10s %12s %10s %16s %14s\n", "phi", "N", "time", "Z (sim_node)", "+-", "P A/(N T) (MD)",
              "Z with K/N");
  for (double phi : phis)
    for (long n : ns) {
      dynhet::engine::Params p;
      p.n_particles = n;
      p.packing_fraction = phi;
      p.restitution = 1.0;
      p.driving = false;
      p.radius_ratio = 1.0;
      p.seed = seed;
      dynhet::engine::Engine e(p);
      e.prepare();
      e.run_until(equilibrate);
      const double t_run = particle_time / n;
      dynhet::RatioBlocks z;
      z.reset(t_run / 256);
      double t0 = e.time();
      auto c0 = e.counters();
      const double t_end = t0 + t_run;
      while (e.time() < t_end) {
        e.run_until(t_end, 2 * n);
        const auto c = e.counters();
        const double ke = e.kinetic_energy_per_particle(); // conserved
        z.add((c.virial - c0.virial) / (2.0 * n), ke * (e.time() - t0), e.time() - t0);
        c0 = c, t0 = e.time();
      }
      const double f = (n - 1.0) / n;
      std::printf("%6.3f %7ld %10.1f %12.5f %10.5f %16.5f %14.5f\n", phi, n, t_run, dynhet::engine::reduced_pressure_from_ratio(z.mean(), n),
                  f * z.standard_error(), f * (1 + z.mean()), 1 + z.mean());
    }
}
