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
//   [--sections pass,s4,clusters] (or s4_node: s4_node's cost per pair only)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <memory>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "dynhet/analysis/bonds.hpp"
#include "dynhet/analysis/cage.hpp"
#include "dynhet/analysis/clusters.hpp"
#include "dynhet/analysis/displacement.hpp"
#include "dynhet/analysis/displacement_distribution.hpp"
#include "dynhet/analysis/overlap.hpp"
#include "dynhet/analysis/s4.hpp"
#include "dynhet/model.hpp"

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
    return (1 - fx) * ((1 - fy) * g(ix, iy) + fy * g(ix, iy + 1)) +
           fx * ((1 - fy) * g(ix + 1, iy) + fy * g(ix + 1, iy + 1));
  }
};

Frames make_frames(long n, double phi, unsigned seed) {
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g(0, 1);
  const double r2 = dynhet::kPaperRadiusRatio;
  Frames f{n, std::sqrt(n * kPi * (1 + r2 * r2) / 2 / phi), std::vector<double>(2 * n),
           std::vector<double>(2 * n), std::vector<std::uint8_t>(n)};
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

// CPU time of this thread, so that other processes sharing the two cores
// do not count; they still share caches and memory bandwidth.
double cpu_seconds() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// CPU time of reps calls, in seconds: the fastest (the kernel's cost) and
// the median.
struct Timing {
  double min, median;
};
template <class F> Timing time_calls(int reps, F&& f) {
  std::vector<double> t;
  for (int r = 0; r < reps; ++r) {
    const double t0 = cpu_seconds();
    f();
    t.push_back(cpu_seconds() - t0);
  }
  std::sort(t.begin(), t.end());
  return {t.front(), t[t.size() / 2]};
}

// One configuration of the one-pass kernel: its grids, cutoffs, origin index.
struct PassCase {
  std::string label;
  an::DisplacementSpec spec;
  std::unique_ptr<an::OriginIndex> origin;
  double index_s;
  std::vector<double> t, t_d2; // per call, seconds
  double q = 0;
};

PassCase make_case(const Frames& f, const std::vector<int>& targets, bool nested,
                   const std::vector<double>& cutoffs) {
  PassCase c;
  c.spec.grids = an::nested_subbox_grids(f.n, f.box, targets);
  if (!nested)
    for (size_t g = 0; g < targets.size(); ++g)
      c.spec.grids[g] = an::make_subbox_grid(f.n, f.box, targets[g]);
  for (const auto& g : c.spec.grids) {
    const int nb = static_cast<int>(std::lround(g.mean_particles));
    c.label += (c.label.empty() ? "" : ",") + (nb == f.n ? std::string("all") : std::to_string(nb));
  }
  c.spec.cutoffs = cutoffs;
  c.spec.hist_lo = -10, c.spec.hist_width = 0.05, c.spec.hist_bins = 400;
  c.index_s = time_calls(5, [&] { an::OriginIndex o(f.p0.data(), f.n, c.spec); }).min;
  c.origin = std::make_unique<an::OriginIndex>(f.p0.data(), f.n, c.spec);
  return c;
}

Timing summary(std::vector<double> t) {
  std::sort(t.begin(), t.end());
  return {t.front(), t[t.size() / 2]};
}

void bench_extremes(const Frames& f, const std::vector<double>& d2, const an::DisplacementResult& r, int reps);

void bench_pass(const Frames& f, int reps) {
  std::printf("\n# one pass per (origin, lag): Q_r and chi4 on every grid for every cutoff, MSD all/small, "
              "P(dx) histogram\n");
  std::printf("# a grid whose side divides a finer grid's is summed from it: 'indexed' grids cost one\n"
              "# counter increment per particle each; the cases are timed in turn, round after round\n");
  std::printf("%8s %-36s %7s %7s %9s %9s %9s %9s %7s\n", "N", "sub-box N (actual)", "indexed", "cutoffs",
              "index_ms", "ns/p_min", "ns/p_med", "+d2_min", "Q(0.6)");
  const std::vector<std::pair<std::vector<int>, bool>> sets{
      {{100}, false},
      {{25, 100, 400, 1600, 6400, int(f.n)}, false},
      {{25, 100, 400, 1600, 6400, int(f.n)}, true},
      {{25, 50, 100, 200, 400, 800, 1600, 6400, int(f.n)}, false}};
  std::vector<PassCase> cases;
  for (const auto& set : sets)
    for (const std::vector<double>& cutoffs :
         {std::vector<double>{0.6}, std::vector<double>{0.6, 1.0}, std::vector<double>{0.6, 1.0, 1.4, 1.8}})
      cases.push_back(make_case(f, set.first, set.second, cutoffs));
  std::vector<double> d2(f.n);
  an::DisplacementResult r;
  for (int rep = 0; rep < reps; ++rep)
    for (PassCase& c : cases) {
      c.t.push_back(time_calls(1, [&] {
                      an::displacement_pass(f.p0.data(), f.pt.data(), f.species.data(), f.n, *c.origin,
                                            c.spec, r);
                    }).min);
      c.t_d2.push_back(time_calls(1, [&] {
                         an::displacement_pass(f.p0.data(), f.pt.data(), f.species.data(), f.n, *c.origin,
                                               c.spec, r, d2.data());
                       }).min);
      c.q = r.q[0];
    }
  for (const PassCase& c : cases) {
    const Timing t = summary(c.t), t2 = summary(c.t_d2);
    std::printf("%8ld %-36s %7d %7zu %9.2f %9.2f %9.2f %9.2f %7.3f\n", f.n, c.label.c_str(),
                c.origin->indexed_grids(), c.spec.cutoffs.size(), 1e3 * c.index_s, 1e9 * t.min / f.n,
                1e9 * t.median / f.n, 1e9 * t2.min / f.n, c.q);
  }
  bench_extremes(f, d2, r, reps);
}

// What the MSD's fastest/slowest subsets and P(dx, t) add per (origin,
// lag) pair on top of the pass, as the overlap node does them.
void bench_extremes(const Frames& f, const std::vector<double>& d2, const an::DisplacementResult& r, int reps) {
  std::printf("\n# added per (origin, lag): fastest/slowest 10%% of all and 20%% of small (exact: sampled bands + nth_element), "
              "P(dx) tally\n");
  std::printf("%8s %-52s %9s %9s %12s\n", "N", "what", "ns/p_min", "ns/p_med", "max_rel_err");
  // Reference: a full sort of each set.
  auto sorted_means = [&](int which, double fraction) {
    std::vector<double> v;
    for (long i = 0; i < f.n; ++i)
      if (which < 0 || f.species[i] == which) v.push_back(d2[i]);
    std::sort(v.begin(), v.end());
    const long k = std::max(1L, std::lround(fraction * v.size()));
    return an::ExtremeMsd{std::accumulate(v.end() - k, v.end(), 0.0) / k,
                          std::accumulate(v.begin(), v.begin() + k, 0.0) / k, k};
  };
  const an::ExtremeMsd ref[2] = {sorted_means(-1, 0.1), sorted_means(0, 0.2)};
  an::ExtremeMsd got[2];
  auto rel = [](double a, double b) { return std::abs(a - b) / std::abs(b); };
  auto row = [&](const char* what, const Timing& t, bool check) {
    double e = 0;
    for (int s = 0; s < 2 && check; ++s) e = std::max({e, rel(got[s].fast, ref[s].fast), rel(got[s].slow, ref[s].slow)});
    std::printf("%8ld %-52s %9.2f %9.2f %12.1e\n", f.n, what, 1e9 * t.min / f.n, 1e9 * t.median / f.n, e);
  };
  const Timing fresh = time_calls(reps, [&] {
    got[0] = an::msd_extremes(d2.data(), f.species.data(), f.n, 0.1, -1);
    got[1] = an::msd_extremes(d2.data(), f.species.data(), f.n, 0.2, 0);
  });
  row("extremes, new buffer per call", fresh, true);
  std::vector<double> buffer;
  const Timing reused = time_calls(reps, [&] {
    got[0] = an::msd_extremes(d2.data(), f.species.data(), f.n, 0.1, -1, buffer);
    got[1] = an::msd_extremes(d2.data(), f.species.data(), f.n, 0.2, 0, buffer);
  });
  row("extremes, reused buffer", reused, true);
  const Timing one_pass = time_calls(reps, [&] {
    const an::ExtremeMsdAllSmall e = an::msd_extremes_all_small(d2.data(), f.species.data(), f.n, 0.1, 0.2, buffer);
    got[0] = e.all, got[1] = e.small;
  });
  row("extremes, all + small in one pass (overlap node)", one_pass, true);
  std::printf("# whole-set fallbacks in the last call: all %d, small %d\n", got[0].full_selections,
              got[1].full_selections);
  // P(dx): the pass histograms every pair anyway; the node adds them to a
  // tally per (block, lag, set): 2 x bins additions per pair.
  const int bins = static_cast<int>(r.hist[0].size());
  an::DisplacementTally tally(20, 1, 2, bins);
  std::vector<long> all(bins);
  const Timing t_tally = time_calls(reps, [&] {
    for (int b = 0; b < bins; ++b) all[b] = r.hist[0][b] + r.hist[1][b];
    tally.add(0, 0, 0, all.data(), f.n);
    tally.add(0, 0, 1, r.hist[0].data(), r.n_small);
  });
  row("P(dx) tally of one pair (400 bins, 2 sets)", t_tally, false);
  // The flow part of D: the 24 longest waves of the displacement field.
  const Timing t_modes = time_calls(reps, [&] {
    const an::WaveModes w = an::collective_modes(f.p0.data(), f.pt.data(), f.n, f.box, 4, r.msd_all);
    if (w.transverse.size() != 24) std::abort();
  });
  row("collective modes |n| <= 4 (24 waves, D's flow part)", t_modes, false);
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
  std::printf("%8s %5s %8s %6s %4s %5s %6s %9s %9s %10s %11s %11s\n", "sub-N", "m", "spacing", "R", "hw", "M",
              "shells", "grid_min", "grid_med", "direct_ms", "max_relerr", "est_bound");
  for (int target : {int(f.n), 6400, 400}) {
    const an::SubboxGrid grid = an::make_subbox_grid(f.n, f.box, target);
    an::S4Shells ref;
    const double t_direct = time_calls(1, [&] {
                              ref =
                                  an::s4_shells(an::s4_modes_direct(f.p0.data(), w.data(), f.n, grid, q_max));
                            }).min;
    for (double r : {1.25, 1.5, 2.0, 3.0})
      for (int hw : {4, 6}) {
        an::S4Grid g(grid, q_max, {kPi / (r * q_max), hw});
        an::S4Shells sh;
        const Timing t = time_calls(reps, [&] { sh = an::s4_shells(g.modes(f.p0.data(), w.data(), f.n)); });
        std::printf("%8.0f %5d %8.3f %6.2f %4d %5d %6zu %9.2f %9.2f %10.0f %11.2e %11.2e\n",
                    grid.mean_particles, grid.per_side, g.spacing(), g.oversampling(), hw, g.points(),
                    ref.q.size(), 1e3 * t.min, 1e3 * t.median, 1e3 * t_direct, max_rel_error(sh, ref),
                    g.error_bound());
      }
  }
}

// What s4_node spends per (origin, lag) pair with the default [s4]
// parameters: S4 on every grid of the default chi4 sizes (nested) and the
// whole box, each against its direct sum, for one cutoff (a = 0.6) and for
// two (0.6 and 1.0) as the node does them: d2 once per pair, then per cutoff
// the weights and the transforms on the same grids (plans and buffers).
void bench_s4_node(const Frames& f, double q_max, int reps) {
  std::vector<double> d2(f.n), w;
  for (long i = 0; i < f.n; ++i)
    d2[i] = std::pow(f.pt[2 * i] - f.p0[2 * i], 2) + std::pow(f.pt[2 * i + 1] - f.p0[2 * i + 1], 2);
  std::vector<an::SubboxGrid> grids = an::nested_subbox_grids(f.n, f.box, {25, 100, 400, 1600, 6400});
  grids.push_back(an::SubboxGrid{1, f.box, double(f.n)});
  std::vector<std::unique_ptr<an::S4Grid>> fft;
  for (const auto& g : grids) fft.push_back(std::make_unique<an::S4Grid>(g, q_max));
  for (const std::vector<double>& cutoffs : {std::vector<double>{0.6}, std::vector<double>{0.6, 1.0}}) {
    double err = 0;
    for (double a : cutoffs) {
      an::overlap_weights(d2.data(), f.n, a, w);
      for (size_t g = 0; g < grids.size(); ++g) {
        const an::S4Shells ref = an::s4_shells(an::s4_modes_direct(f.p0.data(), w.data(), f.n, grids[g], q_max));
        err = std::max(err, max_rel_error(an::s4_shells(fft[g]->modes(f.p0.data(), w.data(), f.n)), ref));
      }
    }
    const Timing t = time_calls(reps, [&] {
      for (double a : cutoffs) {
        an::overlap_weights(d2.data(), f.n, a, w);
        for (auto& g : fft) an::s4_shells(g->modes(f.p0.data(), w.data(), f.n));
      }
    });
    std::printf("# s4_node per pair, %zu grids (default chi4 sizes + whole box, R = 2, hw 4), %zu cutoff%s "
                "(a = %g%s): %.1f ms (min; median %.1f), max rel error %.1e\n",
                grids.size(), cutoffs.size(), cutoffs.size() > 1 ? "s" : "", cutoffs[0],
                cutoffs.size() > 1 ? ", 1" : "", 1e3 * t.min, 1e3 * t.median, err);
  }
}

// Clusters as clusters_node does them: g_ab and the neighbour graph once per
// origin frame (t0), then per (origin, lag) and cutoff the slow and fast
// selections, their clusters with R_g at t (eq. 10) and the tallies.
void bench_clusters(const Frames& f, int reps) {
  std::vector<double> d2(f.n);
  for (long i = 0; i < f.n; ++i)
    d2[i] = std::pow(f.pt[2 * i] - f.p0[2 * i], 2) + std::pow(f.pt[2 * i + 1] - f.p0[2 * i + 1], 2);
  // Cutoffs typical of the paper's fluid (first minima ~1.35 contact distances).
  const an::NeighbourCutoffs cut{{2.7, 3.3, 3.9}};
  const Timing t_g = time_calls(3, [&] { an::pair_distribution(f.p0.data(), f.species.data(), f.n, f.box, 8, 0.05); });
  an::NeighbourFinder finder(cut);
  an::NeighbourGraph graph;
  const Timing t_graph = time_calls(reps, [&] { graph.build(finder.find(f.p0.data(), f.species.data(), f.n, f.box)); });
  std::printf("\n# clusters per (origin, lag), neighbours at t0 (r11 r12 r22 = 2.7 3.3 3.9), R_g at t; "
              "per origin frame: g_ab (r < 8) %.1f ms, neighbour graph (%zu pairs) %.1f ms (min)\n",
              1e3 * t_g.min, graph.to.size() / 2, 1e3 * t_graph.min);
  std::printf("%8s %6s %6s %9s %9s %9s %9s %8s %8s\n", "N", "a", "kind", "selected", "clusters", "largest",
              "spanning", "ms_min", "ms_med");
  an::ClusterFinder clusters;
  an::ClusterTally tally(f.n, 5, 10);
  Timing one = {0, 0}, both = {0, 0};
  for (double a : {0.6, 1.0})
    for (int fast = 0; fast < 2; ++fast) {
      const an::ClusterSet* c = nullptr;
      long selected = 0;
      const Timing t = time_calls(reps, [&] {
        const auto s = fast ? an::fast_particles(d2.data(), f.n, a) : an::slow_particles(d2.data(), f.n, a);
        c = &clusters.find(graph, f.p0.data(), f.pt.data(), f.box, s.data());
        tally.add(*c);
        selected = std::accumulate(s.begin(), s.end(), 0L);
      });
      if (a == 0.6) one.min += t.min, one.median += t.median;
      both.min += t.min, both.median += t.median;
      long largest = 0, spanning = 0;
      for (const auto& k : c->clusters) largest = std::max(largest, k.size), spanning += k.spans;
      std::printf("%8ld %6.2f %6s %9ld %9zu %9ld %9ld %8.2f %8.2f\n", f.n, a, fast ? "fast" : "slow", selected,
                  c->clusters.size(), largest, spanning, 1e3 * t.min, 1e3 * t.median);
    }
  std::printf("# total per (origin, lag), slow and fast clusters with R_g and tallies: 1 cutoff %.2f ms, "
              "2 cutoffs %.2f ms (min; median %.2f, %.2f); plus per origin frame %.1f ms\n",
              1e3 * one.min, 1e3 * both.min, 1e3 * one.median, 1e3 * both.median, 1e3 * (t_g.min + t_graph.min));
}

} // namespace

// Cages: the Voronoi neighbours of an origin frame (once per
// origin) and the cage-relative displacements of one (origin, lag) pair.
void bench_cage(const Frames& f, int reps) {
  std::printf("\n# cages: Voronoi neighbours of one frame (CGAL periodic Delaunay), cage-relative displacements "
              "of one (origin, lag)\n");
  std::printf("%8s %-52s %9s %9s %12s\n", "N", "what", "ms_min", "ms_med", "mean_nb");
  an::Neighbours v;
  const Timing tv = time_calls(reps, [&] { v = an::voronoi_neighbours(f.p0.data(), f.n, f.box); });
  const double mean_nb = double(v.list.size()) / f.n;
  std::printf("%8ld %-52s %9.2f %9.2f %12.3f\n", f.n, "voronoi_neighbours", 1e3 * tv.min, 1e3 * tv.median, mean_nb);
  std::vector<double> dr(2 * f.n), cr(2 * f.n);
  for (long i = 0; i < 2 * f.n; ++i) dr[i] = f.pt[i] - f.p0[i];
  const Timing tc = time_calls(reps, [&] { an::cage_relative(dr.data(), v, cr.data()); });
  std::printf("%8ld %-52s %9.2f %9.2f %12.3f\n", f.n, "cage_relative (one origin, lag)", 1e3 * tc.min, 1e3 * tc.median,
              mean_nb);

  // The overlap node's pass of one set per (origin, lag), as it does it:
  // six nested grids and one cutoff with |dr|^2, the fastest/slowest
  // subsets; the cage-relative set adds dr, dr^CR and pos0 + dr^CR first.
  an::DisplacementSpec spec;
  spec.grids = an::nested_subbox_grids(f.n, f.box, {25, 100, 400, 1600, 6400, int(f.n)});
  spec.cutoffs = {0.6};
  spec.hist_lo = -10, spec.hist_width = 0.05, spec.hist_bins = 400;
  const an::OriginIndex origin(f.p0.data(), f.n, spec);
  an::DisplacementResult r;
  std::vector<double> d2(f.n), buffer, pos_cr(2 * f.n);
  auto standard = [&](const double* pos) {
    an::displacement_pass(f.p0.data(), pos, f.species.data(), f.n, origin, spec, r, d2.data());
    an::msd_extremes_all_small(d2.data(), f.species.data(), f.n, 0.1, 0.2, buffer);
  };
  auto cage = [&] { // as the overlap node: cage_relative_positions, then the same
    an::cage_relative_positions(f.p0.data(), f.pt.data(), v, dr, pos_cr.data());
    standard(pos_cr.data());
  };
  std::vector<double> ts, tcr; // alternated, round after round
  for (int rep = 0; rep < 4 * reps; ++rep) {
    ts.push_back(time_calls(1, [&] { standard(f.pt.data()); }).min);
    tcr.push_back(time_calls(1, cage).min);
  }
  const Timing a = summary(ts), b = summary(tcr);
  std::printf("%8ld %-52s %9.2f %9.2f %12s\n", f.n, "standard pass of one set (6 grids, a=0.6, subsets)", 1e3 * a.min,
              1e3 * a.median, "");
  const Timing s_cr = time_calls(4 * reps, [&] { standard(pos_cr.data()); });
  std::printf("%8ld %-52s %9.2f %9.2f %12s\n", f.n, "the same pass on pos0 + dr^CR", 1e3 * s_cr.min,
              1e3 * s_cr.median, "");
  std::printf("%8ld %-52s %9.2f %9.2f %12.2f\n", f.n, "cage-relative pass (dr^CR + the same)  [ratio: median]",
              1e3 * b.min, 1e3 * b.median, b.median / a.median);
  // All the overlap node does per set and pair with the default scene's
  // observables: also Q_r on the overlap grid, the waves |n| <= 4 and
  // F_s at three q.
  const an::SubboxGrid qgrid = an::make_subbox_grid(f.n, f.box, 64);
  std::vector<double> q_r;
  const double qs[3] = {M_PI, 2 * M_PI / 2.43, 2 * M_PI / 2.86};
  double sink = 0;
  auto whole = [&](const double* pos) {
    an::overlap_subboxes(f.p0.data(), pos, f.n, qgrid, spec.cutoffs, q_r);
    standard(pos);
    const an::WaveModes w = an::collective_modes(f.p0.data(), pos, f.n, f.box, 4, r.msd_all);
    sink += w.transverse[0];
    for (long i = 0; i < f.n; ++i) {
      const double rr = std::sqrt(d2[i]);
      for (double q : qs) sink += ::j0(q * rr);
    }
  };
  ts.clear(), tcr.clear();
  for (int rep = 0; rep < reps; ++rep) {
    ts.push_back(time_calls(1, [&] { whole(f.pt.data()); }).min);
    tcr.push_back(time_calls(1, [&] {
                    an::cage_relative_positions(f.p0.data(), f.pt.data(), v, dr, pos_cr.data());
                    whole(pos_cr.data());
                  }).min);
  }
  const Timing wa = summary(ts), wb = summary(tcr);
  std::printf("%8ld %-52s %9.2f %9.2f %12s\n", f.n, "the node's whole set (+Q_r, waves |n|<=4, F_s 3 q)", 1e3 * wa.min,
              1e3 * wa.median, "");
  std::printf("%8ld %-52s %9.2f %9.2f %12.2f\n", f.n, "its cage-relative set  [ratio: median]", 1e3 * wb.min,
              1e3 * wb.median, wb.median / wa.median);
  // F_s at three q (2 pi / sigma_ab), as the overlap node adds it per set.
  double fs = 0;
  const Timing tf = time_calls(reps, [&] {
    fs = 0;
    for (long i = 0; i < f.n; ++i) {
      const double rr = std::sqrt(d2[i]);
      for (double q : qs) fs += ::j0(q * rr);
    }
  });
  std::printf("%8ld %-52s %9.2f %9.2f %12.3g\n", f.n, "F_s at 3 q (glibc j0), one set [mean F_s]", 1e3 * tf.min,
              1e3 * tf.median, fs / (3.0 * f.n) + 0 * sink);
  // Bond breaking: the bonds of an origin (a1 = 1.1), which are intact at t (a2 = 1.5).
  an::BondSet bonds;
  const Timing tb = time_calls(reps, [&] {
    bonds = an::make_bonds(f.p0.data(), f.species.data(), f.n, f.box, {2.0, 2.86}, 1.1, 1.5);
  });
  std::printf("%8ld %-52s %9.2f %9.2f %12.3f\n", f.n, "make_bonds (one origin) [bonds per particle]", 1e3 * tb.min,
              1e3 * tb.median, double(bonds.pairs.pairs.size()) / f.n);
  std::vector<std::uint8_t> intact(bonds.pairs.pairs.size());
  long n_intact = 0;
  const Timing ti = time_calls(reps, [&] { n_intact = an::bonds_intact(bonds, f.species.data(), dr.data(), intact.data()); });
  std::printf("%8ld %-52s %9.2f %9.2f %12.3f\n", f.n, "bonds_intact (one origin, lag) [C_B]", 1e3 * ti.min,
              1e3 * ti.median, double(n_intact) / std::max<size_t>(1, intact.size()));
}

int main(int argc, char** argv) {
  CLI::App app{"dynhet analysis kernel benchmark"};
  long n = 100000;
  double phi = 0.76, q_max = 1.0;
  int reps = 20;
  std::string sections = "pass,s4,clusters,cage";
  app.add_option("--n", n, "particles");
  app.add_option("--phi", phi, "packing fraction (sets the box)");
  app.add_option("--reps", reps, "repetitions per timing (median)");
  app.add_option("--q-max", q_max, "largest |q| of S4");
  app.add_option("--sections", sections, "which tables: pass,s4,clusters,cage (s4: the spacing table and s4_node's "
                                         "cost; s4_node: the latter only)");
  CLI11_PARSE(app, argc, argv);
  const Frames f = make_frames(n, phi, 1);
  std::printf("# dynhet analysis kernels, one core (thread CPU time); N=%ld, phi=%.2f, box=%.1f; min and "
              "median of %d runs\n",
              n, phi, f.box, reps);
  auto wanted = [&](const std::string& s) { return ("," + sections + ",").find("," + s + ",") != std::string::npos; };
  if (wanted("pass")) bench_pass(f, reps);
  if (wanted("s4")) bench_s4(f, q_max, std::max(3, reps / 4));
  if (wanted("s4") || wanted("s4_node")) bench_s4_node(f, q_max, std::max(3, reps / 4));
  if (wanted("clusters")) bench_clusters(f, std::max(3, reps / 4));
  if (wanted("cage")) bench_cage(f, std::max(3, reps / 4));
  return 0;
}
