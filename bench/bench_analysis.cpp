// Analysis kernel benchmark, per (origin, lag) pair, on a synthetic frame
// pair: a disordered lattice of N disks (shuffled, so particle order says
// nothing about position, as in the simulation) at packing fraction phi, and
// Gaussian displacements whose width follows a smooth random mobility
// field (correlation length ~5), tuned so Q(a = 0.6) is near 1/e.
// Prints three tables: the one-pass kernel (overlap, MSD, chi4, P(dx)) in
// ns per particle; S4 on the grid against the direct sum (time and max
// relative error over the |q| <= q_max shells) for several grid spacings;
// clusters with R_g.
// Usage: bench_analysis [--n 100000] [--phi 0.76] [--reps 20] [--q-max 1]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>
#include <vector>

#include <CLI/CLI.hpp>

#include "dynhet/analysis/clusters.hpp"
#include "dynhet/analysis/displacement.hpp"
#include "dynhet/analysis/s4.hpp"

namespace an = dynhet::analysis;

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Frames {
  long n;
  double box;
  std::vector<double> p0, pt;
  std::vector<std::uint8_t> species;
};

// Smooth field: unit Gaussians on a coarse periodic grid of spacing ~corr,
// bilinearly interpolated.
struct SmoothField {
  int m;
  double box;
  std::vector<double> v;
  double at(double x, double y) const {
    const double gx = x / box * m, gy = y / box * m;
    const int ix = static_cast<int>(gx), iy = static_cast<int>(gy);
    const double fx = gx - ix, fy = gy - iy;
    auto g = [&](int a, int b) { return v[(a % m) * m + b % m]; };
    return (1 - fx) * ((1 - fy) * g(ix, iy) + fy * g(ix, iy + 1)) + fx * ((1 - fy) * g(ix + 1, iy) + fy * g(ix + 1, iy + 1));
  }
};

Frames make_frames(long n, double phi, unsigned seed) {
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g(0, 1);
  const double r2 = 1.43;
  Frames f{n, std::sqrt(n * kPi * (1 + r2 * r2) / 2 / phi), std::vector<double>(2 * n), std::vector<double>(2 * n),
           std::vector<std::uint8_t>(n)};
  const long side = static_cast<long>(std::ceil(std::sqrt(double(n))));
  const double a = f.box / side;
  std::vector<long> site(side * side);
  std::iota(site.begin(), site.end(), 0);
  std::shuffle(site.begin(), site.end(), gen);
  SmoothField mob{std::max(1, static_cast<int>(f.box / 5.0)), f.box, {}};
  for (int k = 0; k < mob.m * mob.m; ++k) mob.v.push_back(0.7 * g(gen));
  for (long i = 0; i < n; ++i) {
    const double x = (site[i] % side + 0.5 + 0.6 * (u(gen) - 0.5)) * a;
    const double y = (site[i] / side + 0.5 + 0.6 * (u(gen) - 0.5)) * a;
    const double sd = 0.55 * std::exp(mob.at(x, y)); // per-component width of the displacement
    f.p0[2 * i] = x, f.p0[2 * i + 1] = y;
    f.pt[2 * i] = x + sd * g(gen), f.pt[2 * i + 1] = y + sd * g(gen);
    f.species[i] = i < n - n / 2 ? 0 : 1;
  }
  return f;
}

// Median wall time of reps calls, in seconds.
template <class F> double time_median(int reps, F&& f) {
  std::vector<double> t;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::nth_element(t.begin(), t.begin() + reps / 2, t.end());
  return t[reps / 2];
}

void bench_pass(const Frames& f, int reps) {
  std::printf("\n# one pass per (origin, lag): Q_r and chi4 on every grid for every cutoff, MSD all/small, "
              "P(dx) histogram\n");
  std::printf("%8s %-30s %8s %11s %11s %11s %10s\n", "N", "sub-box N (grids)", "cutoffs", "index_ms", "pass_ns/p",
              "+d2_ns/p", "Q(a0)");
  const std::vector<std::vector<int>> sets{{100}, {25, 100, 400}, {25, 100, 400, 1600, 6400, int(f.n)},
                                           {25, 50, 100, 200, 400, 800, 1600, 6400, int(f.n)}};
  std::vector<double> d2(f.n);
  for (const auto& targets : sets)
    for (const std::vector<double>& cutoffs : {std::vector<double>{0.6}, std::vector<double>{0.6, 1.0}}) {
      an::DisplacementSpec spec;
      std::string label;
      for (int t : targets) {
        spec.grids.push_back(an::make_subbox_grid(f.n, f.box, t));
        label += (label.empty() ? "" : ",") + (t == f.n ? std::string("all") : std::to_string(t));
      }
      spec.cutoffs = cutoffs;
      spec.hist_lo = -10, spec.hist_width = 0.05, spec.hist_bins = 400;
      const double t_index = time_median(5, [&] { an::OriginIndex o(f.p0.data(), f.n, spec); });
      const an::OriginIndex origin(f.p0.data(), f.n, spec);
      an::DisplacementResult r;
      const double t_pass = time_median(reps, [&] {
        an::displacement_pass(f.p0.data(), f.pt.data(), f.species.data(), f.n, origin, spec, r);
      });
      const double t_d2 = time_median(reps, [&] {
        an::displacement_pass(f.p0.data(), f.pt.data(), f.species.data(), f.n, origin, spec, r, d2.data());
      });
      std::printf("%8ld %-30s %8zu %11.2f %11.2f %11.2f %10.3f\n", f.n, label.c_str(), cutoffs.size(), 1e3 * t_index,
                  1e9 * t_pass / f.n, 1e9 * t_d2 / f.n, r.q[0]);
    }
  const double t_ext = time_median(reps, [&] {
    an::msd_extremes(d2.data(), f.species.data(), f.n, 0.1, -1);
    an::msd_extremes(d2.data(), f.species.data(), f.n, 0.2, 0);
  });
  std::printf("# fastest/slowest 10%% of all and 20%% of small (nth_element): %.2f ns/particle\n",
              1e9 * t_ext / f.n);
}

// Largest relative difference of S4 over the shells with 0 < q <= q_max
// (and q = 0 where defined).
double max_rel_error(const an::S4Shells& a, const an::S4Shells& ref) {
  double e = 0;
  for (size_t s = 0; s < ref.q.size(); ++s)
    if (std::isfinite(ref.s4[s])) e = std::max(e, std::abs(a.s4[s] - ref.s4[s]) / std::abs(ref.s4[s]));
  return e;
}

void bench_s4(const Frames& f, double q_max, int reps) {
  std::vector<double> d2(f.n), w;
  for (long i = 0; i < f.n; ++i)
    d2[i] = std::pow(f.pt[2 * i] - f.p0[2 * i], 2) + std::pow(f.pt[2 * i + 1] - f.p0[2 * i + 1], 2);
  an::overlap_weights(d2.data(), f.n, 0.6, w);
  std::printf("\n# S4(q) for |q| <= %g, weights theta(0.6 - |dr|) (%.0f slow particles); grid: Gaussian "
              "NUFFT + FFTW; direct: exact sum\n",
              q_max, std::accumulate(w.begin(), w.end(), 0.0));
  std::printf("%8s %6s %8s %7s %5s %5s %6s %10s %10s %11s %11s\n", "sub-N", "m", "spacing", "R", "hw", "M", "shells",
              "grid_ms", "direct_ms", "max_relerr", "est_bound");
  for (int target : {int(f.n), 6400, 1600}) {
    const an::SubboxGrid grid = an::make_subbox_grid(f.n, f.box, target);
    an::S4Shells ref;
    const double t_direct =
        time_median(1, [&] { ref = an::s4_shells(an::s4_modes_direct(f.p0.data(), w.data(), f.n, grid, q_max)); });
    for (double r : {1.25, 1.5, 2.0, 3.0})
      for (int hw : {3, 4, 6}) {
        an::S4Grid g(grid, q_max, {kPi / (r * q_max), hw});
        an::S4Shells sh;
        const double t = time_median(reps, [&] { sh = an::s4_shells(g.modes(f.p0.data(), w.data(), f.n)); });
        std::printf("%8.0f %6d %8.3f %7.2f %5d %5d %6zu %10.2f %10.0f %11.2e %11.2e\n", grid.mean_particles,
                    grid.per_side, g.spacing(), g.oversampling(), hw, g.points(), ref.q.size(), 1e3 * t,
                    1e3 * t_direct, max_rel_error(sh, ref), g.error_bound());
      }
  }
}

void bench_clusters(const Frames& f, int reps) {
  std::vector<double> d2(f.n);
  for (long i = 0; i < f.n; ++i)
    d2[i] = std::pow(f.pt[2 * i] - f.p0[2 * i], 2) + std::pow(f.pt[2 * i + 1] - f.p0[2 * i + 1], 2);
  // g_ab once per run (here of the t frame), then cutoffs typical of the
  // paper's fluid (first minima ~1.35 contact distances).
  const double t_g = time_median(3, [&] { an::pair_distribution(f.pt.data(), f.species.data(), f.n, f.box, 10, 0.05); });
  const an::NeighbourCutoffs cut{{2.7, 3.3, 3.9}};
  std::printf("\n# clusters per (origin, lag) on the t frame; cutoffs r11 r12 r22 = 2.7 3.3 3.9; g_ab (r<10, once "
              "per run): %.1f ms\n",
              1e3 * t_g);
  std::printf("%8s %8s %6s %8s %9s %9s %9s %8s %11s\n", "N", "a", "kind", "selected", "clusters", "largest",
              "spanning", "ms", "pairs_ms");
  an::NeighbourPairs nb;
  const double t_pairs = time_median(reps, [&] { nb = an::neighbour_pairs(f.pt.data(), f.species.data(), f.n, f.box, cut); });
  double total = t_pairs;
  for (double a : {0.6, 1.0})
    for (int fast = 0; fast < 2; ++fast) {
      const auto sel = fast ? an::fast_particles(d2.data(), f.n, a) : an::slow_particles(d2.data(), f.n, a);
      an::ClusterSet c;
      const double t = time_median(reps, [&] {
        const auto s = fast ? an::fast_particles(d2.data(), f.n, a) : an::slow_particles(d2.data(), f.n, a);
        c = an::find_clusters(nb, f.pt.data(), f.box, s.data());
        an::cluster_size_distribution(an::cluster_sizes(c), 5);
      });
      total += t;
      long largest = 0, spanning = 0;
      for (const auto& k : c.clusters) largest = std::max(largest, k.size), spanning += k.spans;
      std::printf("%8ld %8.2f %6s %8ld %9zu %9ld %9ld %8.2f %11.2f\n", f.n, a, fast ? "fast" : "slow",
                  std::accumulate(sel.begin(), sel.end(), 0L), c.clusters.size(), largest, spanning, 1e3 * t,
                  1e3 * t_pairs);
    }
  std::printf("# neighbour pairs (%zu) + slow and fast clusters with R_g for 2 cutoffs: %.2f ms per (origin, lag)\n",
              nb.pairs.size(), 1e3 * total);
}

} // namespace

int main(int argc, char** argv) {
  CLI::App app{"dynhet analysis kernel benchmark"};
  long n = 100000;
  double phi = 0.76, q_max = 1.0;
  int reps = 20;
  app.add_option("--n", n, "particles");
  app.add_option("--phi", phi, "packing fraction (sets the box)");
  app.add_option("--reps", reps, "repetitions per timing (median)");
  app.add_option("--q-max", q_max, "largest |q| of S4");
  CLI11_PARSE(app, argc, argv);
  const Frames f = make_frames(n, phi, 1);
  std::printf("# dynhet analysis kernels, one core; N=%ld, phi=%.2f, box=%.1f; medians of %d runs\n", n, phi, f.box,
              reps);
  bench_pass(f, reps);
  bench_s4(f, q_max, std::max(3, reps / 4));
  bench_clusters(f, std::max(3, reps / 4));
  return 0;
}
