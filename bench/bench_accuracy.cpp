// Run time against error: the statistical error of the reduced pressure Z
// and of tau_alpha (a = 0.6) as the production run grows, for the paper's
// driven system (eps = 0.9, bidisperse), so a user can pick a run length
// for a target error. The errors are the ones sim_node and the overlap
// node quote: Z as sim_node computes it for a production of that length
// (engine.hpp reduced_pressure; 256 fine blocks of simulation time, the
// largest batch-means error over 16, 8 and 4 groups: stats.hpp
// RatioBlocks); tau_alpha: Q(t) averaged over origins every `spacing`,
// error by jackknife over origins (analysis_nodes/kernels/overlap.cpp, as
// the node).
// Usage: bench_accuracy [--n 10000] [--phi 0.5,0.7] [--time 400]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

#include <CLI/CLI.hpp>

#include "dynhet/analysis/overlap.hpp"
#include "dynhet/engine/engine.hpp"
#include "dynhet/model.hpp"
#include "dynhet/schedule.hpp"
#include "dynhet/stats.hpp"

namespace an = dynhet::analysis;

int main(int argc, char** argv) {
  CLI::App app{"dynhet: statistical error against CPU time"};
  long n = 10000;
  std::vector<double> phis{0.5, 0.7};
  double t_max = 400, step = 0.05, spacing = 2.0, eps = 0.9;
  app.add_option("--n", n);
  app.add_option("--phi", phis)->delimiter(',');
  app.add_option("--time", t_max, "longest production run");
  app.add_option("--eps", eps);
  CLI11_PARSE(app, argc, argv);

  std::printf("# N=%ld eps=%g driven; Z as sim_node (256 fine blocks per production), tau_alpha (a=0.6) from "
              "origins every %g\n", n, eps, spacing);
  std::printf("%6s %8s %8s %9s %9s %8s %10s %10s %8s\n", "phi", "t_run", "cpu_s", "Z", "Z_err", "Z_rel%",
              "tau_alpha", "tau_err", "tau_rel%");
  for (double phi : phis) {
    dynhet::engine::Engine e(dynhet::engine::paper_params(n, phi, eps, true));
    e.prepare();
    const double t_eq = 50.0;
    e.run_until(t_eq);

    // Lags up to 20 (several tau_alpha at these densities); origins every `spacing`.
    dynhet::ScheduleSpec spec{static_cast<int>((t_max - 20.0) / spacing) + 1, spacing, 0.05, 20.0, 8, {}};
    const auto s = dynhet::make_schedule(spec, t_eq);
    an::OverlapAccumulator acc(s.n_origins(), s.lag_time, spacing); // the overlap node's jackknife blocks
    const auto grid = an::make_subbox_grid(n, e.box_length(), static_cast<int>(n)); // whole box
    std::map<int, std::vector<double>> origin_pos;
    std::vector<std::vector<std::pair<int, int>>> pairs_at(s.frame_time.size());
    for (int k = 0; k < s.n_origins(); ++k)
      for (int j = 0; j < s.n_lags(); ++j) pairs_at[s.pair(k, j)].push_back({k, j});

    const auto t0 = std::chrono::steady_clock::now();
    std::vector<double> rows;
    for (double r = 25; r <= t_max + 1e-9; r *= 2) rows.push_back(t_eq + r);
    // One accumulator per row: a production of that length, as sim_node blocks it.
    std::vector<dynhet::RatioBlocks> z(rows.size());
    for (size_t i = 0; i < rows.size(); ++i) z[i].reset((rows[i] - t_eq) / 256);
    double next_block = t_eq + step, last_virial = e.counters().virial, last_t = t_eq,
           last_ke = e.kinetic_energy_per_particle();
    size_t row = 0;
    std::vector<double> xy, qr;
    for (size_t f = 0; f < s.frame_time.size() && row < rows.size(); ++f) {
      const double tf = s.frame_time[f];
      // Pressure blocks that end before this frame.
      while (next_block <= tf) {
        e.run_until(next_block);
        const double ke = e.kinetic_energy_per_particle(), dt = next_block - last_t;
        for (auto& zi : z) zi.add((e.counters().virial - last_virial) / (2.0 * n), 0.5 * (ke + last_ke) * dt, dt);
        last_virial = e.counters().virial;
        last_t = next_block;
        last_ke = ke;
        next_block += step;
      }
      e.run_until(tf);
      e.unwrapped_positions(xy);
      for (int k = 0; k < s.n_origins(); ++k)
        if (s.origin_frame[k] == static_cast<int>(f)) origin_pos[k] = xy;
      for (auto [k, j] : pairs_at[f]) {
        an::overlap_subboxes(origin_pos[k].data(), xy.data(), n, grid, {0.6}, qr);
        acc.add(k, j, qr.data(), 1);
      }
      if (tf >= rows[row]) {
        const double cpu = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const auto r = acc.result();
        const double zm = dynhet::engine::reduced_pressure_from_ratio(z[row].mean(), n),
                     ze = (n - 1.0) / n * z[row].standard_error();
        std::printf("%6.3f %8.0f %8.1f %9.4f %9.4f %8.3f %10.4f %10.4f %8.3f\n", phi, rows[row] - t_eq, cpu, zm, ze,
                    100 * ze / zm, r.tau_alpha, r.tau_alpha_err, 100 * r.tau_alpha_err / r.tau_alpha);
        std::fflush(stdout);
        ++row;
      }
    }
  }
  return 0;
}
