// Engine benchmark: events per second and ns per collision against N and
// phi, memory per particle, and the energy drift of elastic runs, as a
// table. Usage: bench_engine [--n 10000,100000] [--phi 0.6,0.78] [--coll 50]
//   [--eps 1.0] [--driven] [--pairs neighbours|any] [--reach 1] [--kick-search list|cells] [--cache DIR]
//   [--tile-from 10000]
// With --tile-from B, a system of N = k^2 B particles starts from the
// compressed B-particle state tiled k x k (velocities redrawn), instead of
// compressing N particles from scratch (which takes hours at N = 10^6).
// With --cache DIR, prepared states (compressed or tiled) are kept in DIR
// and read by the next run, of this build or of another: both start from
// the same state.
// Rates are per second of this thread's CPU time, so that another process on
// the machine does not change them (wall time is printed too).
#include <chrono>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "checkpoint.hpp"
#include "dynhet/engine/engine.hpp"
#include "dynhet/model.hpp"
#include "dynhet/stats.hpp"

namespace {

double seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The state of b particles in a box of side l tiled k x k into a box of side
// `box` (= k l up to roundoff; positions are scaled to it). Particle ids
// keep the species rule: the first half of the ids are small.
dynhet::engine::State tile_state(const dynhet::engine::State& s, long b, double l, int k, double box) {
  const long n = b * k * k, small_b = b - b / 2, small_n = n - n / 2;
  dynhet::engine::State t;
  t.x.resize(n), t.y.resize(n), t.vx.resize(n), t.vy.resize(n), t.last_collision.assign(n, -1e300);
  t.image_x.assign(n, 0), t.image_y.assign(n, 0), t.collision_count.assign(n, 0);
  const double f = box / (k * l);
  for (int ty = 0; ty < k; ++ty)
    for (int tx = 0; tx < k; ++tx) {
      const long tile = ty * k + tx;
      for (long i = 0; i < b; ++i) {
        const long id = i < small_b ? tile * small_b + i : small_n + tile * (b - small_b) + (i - small_b);
        t.x[id] = (s.x[i] + tx * l) * f;
        t.y[id] = (s.y[i] + ty * l) * f;
        t.vx[id] = s.vx[i];
        t.vy[id] = s.vy[i];
      }
    }
  for (int r = 0; r < 4; ++r) t.rng[r] = s.rng[r];
  t.kick_in = s.kick_in;
  return t;
}

// A prepared (compressed or tiled) state kept in the cache directory, so
// that the next run, of this build or another, starts from the same state.
void write_cached(const std::string& path, const std::string& dir, const dynhet::engine::State& s) {
  std::filesystem::create_directories(dir);
  dynhet::Checkpoint c;
  c.state = s;
  dynhet::write_checkpoint(path, c);
}

double cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

} // namespace

int main(int argc, char** argv) {
  CLI::App app{"dynhet engine benchmark"};
  std::vector<long> ns{10000, 100000};
  std::vector<double> phis{0.60, 0.70, 0.78, 0.805};
  double coll_per_particle = 50, eps = 1.0, sync = 50.0;
  bool driven = false, fingerprint = false;
  double skin = dynhet::engine::Params{}.skin;
  std::string cache, pairs = "neighbours", kick_search = "list";
  double reach = dynhet::engine::Params{}.kick_reach;
  long tile_from = 0;
  app.add_option("--n", ns, "particle numbers")->delimiter(',');
  app.add_option("--phi", phis, "packing fractions")->delimiter(',');
  app.add_option("--coll", coll_per_particle, "collisions per particle to time");
  app.add_option("--eps", eps, "restitution");
  app.add_flag("--driven", driven, "kicks at the Enskog frequency");
  app.add_option("--pairs", pairs, "kick pairs: neighbours (within --reach) or any two particles")
      ->check(CLI::IsMember({"neighbours", "any"}));
  app.add_option("--reach", reach, "largest surface gap of a neighbour kick pair, small radii");
  app.add_option("--kick-search", kick_search,
                 "neighbour pairs: the partner drawn from the kick list (list) or searched in the 3 x 3 cells "
                 "(cells, the earlier engine's)")
      ->check(CLI::IsMember({"list", "cells"}));
  app.add_option("--sync", sync, "time between synchronisations (memory re-sorting)");
  app.add_option("--cache", cache,
                 "keep compressed states here (HDF5 checkpoints) and start from them next time");
  app.add_option("--tile-from", tile_from,
                 "start N = k^2 B from the compressed state of B particles tiled k x k");
  app.add_option("--skin", skin, "neighbour-list skin in small radii (0: automatic, from phi)");
  app.add_flag("--fingerprint", fingerprint,
               "after each row, print a hash of the final positions and the event counts: a change "
               "that must not alter the trajectory keeps them");
  CLI11_PARSE(app, argc, argv);

  std::printf("# dynhet engine, one core; eps=%g, %s; timed over %g collisions per particle, "
              "synchronised every %g; rates per CPU second\n", eps,
              driven ? ("driven, kick pairs: " + (pairs == "any" ? pairs : pairs + " within " + std::to_string(reach) +
                                                                   " (partner from the " + kick_search + ")"))
                           .c_str()
                     : "undriven",
              coll_per_particle, sync);
  // sync_s: CPU seconds of the timed span spent in its synchronisations;
  // c+k/s_loop: collisions plus kicks per CPU second of the rest, the event
  // loop alone (a run synchronises once per run.checkpoint_interval, about
  // 87 collisions per particle at phi = 0.78, where --coll sets how many
  // collisions per particle the timed span's last synchronisation weighs on).
  std::printf("%9s %6s %9s %10s %10s %10s %10s %10s %10s %9s %9s %5s %8s %11s %8s %8s %8s %11s\n", "N", "phi", "prep_s",
              "coll/s", "kicks/s", "c+k/s", "rebuild/s", "stale/s", "events/s", "ns/coll", "B/part", "nbrs", "wall_s",
              "dE/E", "T_mean", "T_sd", "sync_s", "c+k/s_loop");
  for (long n : ns)
    for (double phi : phis) {
      dynhet::engine::Params p = dynhet::engine::paper_params(n, phi, eps, driven);
      p.seed = 1;
      p.skin = skin;
      p.kick_pairs = pairs == "any" ? dynhet::engine::KickPairs::any : dynhet::engine::KickPairs::neighbours;
      p.kick_reach = reach;
      p.kick_search_cells = kick_search == "cells";
      dynhet::engine::Engine e(p);
      auto t0 = std::chrono::steady_clock::now();
      const std::string cached =
          cache.empty() ? "" : cache + "/state_n" + std::to_string(n) + "_phi" + std::to_string(phi) +
                                  (driven ? "_driven_eps" + std::to_string(eps) : "") + ".h5";
      double prep = -1; // -1: read from the cache
      try {
        const long k = tile_from > 0 ? std::lround(std::sqrt(double(n) / tile_from)) : 0;
        if (!cached.empty() && std::filesystem::exists(cached)) {
          e.restore(dynhet::read_checkpoint(cached).state);
        } else if (k > 1 && k * k * tile_from == n) {
          dynhet::engine::Params pb = p;
          pb.n_particles = tile_from;
          dynhet::engine::Engine base(pb);
          base.prepare();
          base.synchronize();
          const double lb = dynhet::make_model(tile_from, phi, p.radius_ratio).box_length;
          const double ln = dynhet::make_model(n, phi, p.radius_ratio).box_length;
          e.restore(tile_state(base.state(), tile_from, lb, static_cast<int>(k), ln));
          e.thermalize(1.0);
          e.synchronize(); // predictions for the new velocities
          if (const double ov = e.max_overlap(); ov > 1e-9)
            throw std::runtime_error("tiled state overlaps by " + std::to_string(ov));
          prep = seconds(t0);
          if (!cached.empty()) write_cached(cached, cache, e.state()); // another build then starts from it too
        } else {
          e.prepare();
          prep = seconds(t0);
          if (!cached.empty()) {
            e.synchronize();
            write_cached(cached, cache, e.state());
          }
        }
      } catch (const std::exception& ex) {
        std::printf("%9ld %6.3f  failed: %s\n", n, phi, ex.what());
        continue;
      }
      const double e0 = e.kinetic_energy_per_particle();
      // Short warm-up to learn the collision rate, then the timed run.
      e.run_until(1.0);
      const double rate = e.counters().collisions / 1.0; // per unit time, whole system
      const auto c0 = e.counters();
      const double t_run = coll_per_particle * n / std::max(rate, 1.0);
      t0 = std::chrono::steady_clock::now();
      const double cpu0 = cpu_seconds();
      // Synchronise (and re-sort particles in memory) every `sync` time
      // units, as sim_node does at run.checkpoint_interval.
      dynhet::BlockAverage temp; // granular temperature T = KE per particle, sampled
      double t2 = 0, sync_cpu = 0;
      for (double t = e.time(), end = e.time() + t_run; t < end;) {
        for (double stop = std::min(end, t + sync); t < stop;) {
          t = std::min(stop, t + 1.0);
          e.run_until(t);
          const double T = e.kinetic_energy_per_particle();
          temp.add(T);
          t2 += T * T;
        }
        const double s0 = cpu_seconds();
        e.synchronize();
        sync_cpu += cpu_seconds() - s0;
      }
      const double t_sd = std::sqrt(std::max(0.0, t2 / temp.count() - temp.mean() * temp.mean()));
      const double wall = seconds(t0), cpu = cpu_seconds() - cpu0;
      const double bytes = double(e.memory_bytes()) / n; // the engine's arrays, after the run (they grow)
      const auto c1 = e.counters();
      const double coll = double(c1.collisions - c0.collisions), kicks = double(c1.kicks - c0.kicks);
      const double cross = double(c1.rebuilds - c0.rebuilds), stale = double(c1.stale - c0.stale);
      std::printf("%9ld %6.3f %9.2f %10.3g %10.3g %10.3g %10.3g %10.3g %10.3g %9.1f %9.0f %5.2f %8.1f %11.2e %8.4f %8.4f %8.3f %11.3g\n",
                  n, phi, prep, coll / cpu, kicks / cpu, (coll + kicks) / cpu, cross / cpu, stale / cpu, (coll + kicks + cross + stale) / cpu,
                  1e9 * cpu / coll, bytes, e.mean_neighbours(), wall,
                  eps == 1.0 && !driven ? e.kinetic_energy_per_particle() / e0 - 1 : NAN, temp.mean(), t_sd, sync_cpu,
                  (coll + kicks) / std::max(cpu - sync_cpu, 1e-9));
      if (fingerprint) {
        std::vector<double> xy;
        e.unwrapped_positions(xy);
        uint64_t h = 1469598103934665603ull; // FNV-1a over the bytes
        for (const double v : xy) {
          uint64_t b;
          std::memcpy(&b, &v, sizeof b);
          for (int k = 0; k < 8; ++k) h = (h ^ ((b >> (8 * k)) & 0xff)) * 1099511628211ull;
        }
        std::printf("#   fingerprint %016llx after %lld collisions, %lld kicks at t = %.17g\n",
                    static_cast<unsigned long long>(h), static_cast<long long>(c1.collisions),
                    static_cast<long long>(c1.kicks), e.time());
      }
      std::fflush(stdout);
    }
  return 0;
}
