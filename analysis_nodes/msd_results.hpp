// What the overlap node keeps per set of displacements (standard, or
// cage-relative) and computes of the MSD: the accumulators of one set
// (Measures), and the MSD's own part of every (origin, lag) pair and of
// its message (MsdResults): the fastest and slowest subsets, D with the
// waves' share, alpha_2(t) and F_s(q, t).
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

#include "dynhet/analysis/chi4.hpp"
#include "dynhet/analysis/overlap.hpp"
#include "dynhet/msd_t.hpp"
#include "dynhet/run_info_t.hpp"
#include "dynhet/scene.hpp"
#include "displacement_results.hpp"

namespace dynhet {

// One set of the node's accumulators: of the displacements as they are, or
// of the cage-relative ones.
struct Measures {
  bool cage_relative = false;
  std::vector<analysis::OverlapAccumulator> acc; // one per cutoff
  std::vector<double> msd_all, msd_small;  // per (origin, lag)
  std::vector<double> msd_extreme[4];      // per (origin, lag): fast all, slow all, fast small, slow small
  std::vector<double> flow_t, flow_l;      // per (origin, lag, mode): collective_modes
  std::vector<double> amp;                 // per (origin, mode): u_k . e at the last lag (t re, im, l re, im)
  std::vector<double> m4_all, m4_small;    // per (origin, lag): <|dr|^4> over the particles, for alpha_2
  std::vector<double> fs_all, fs_small;    // per (origin, lag, q): <J0(q |dr|)>
  std::unique_ptr<DisplacementResults> displacement;
  std::chrono::steady_clock::time_point last_displacement{};
  std::vector<analysis::Chi4Accumulator> chi4_acc; // [grid * n_cutoffs + cutoff], cutoffs ascending
  template <class Ar> void io(Ar& ar) {
    ar(acc, msd_all, msd_small, msd_extreme, flow_t, flow_l, amp, m4_all, m4_small, fs_all, fs_small, chi4_acc);
    if (displacement) ar(*displacement);
  }
  const char* says() const { return cage_relative ? " (cage-relative)" : ""; }
};

class MsdResults {
public:
  static constexpr int kFlowModes = 4; // |n| <= 4: waves of L / 4 and longer
  MsdResults(const run_info_t& run, const Scene::Msd& spec);
  // Sizes set s's MSD tables (NaN: not measured).
  void allocate(Measures& s) const;
  // One (origin k, lag j) pair of set s: d2 the |dr|^2 of the displacement
  // pass, msd_all its mean.
  void add(Measures& s, int k, int j, const double* pos0, const double* pos, const double* d2, double msd_all);
  // Set s's message (but its stamp); frozen: the waves' frozen shares.
  msd_t message(const Measures& s, std::vector<double>& frozen) const;
  // The final log line of D and the waves.
  void log_flows(const msd_t& m, const std::vector<double>& frozen, const char* says) const;

private:
  void self_part(Measures& s, size_t kj, const double* d2);
  void alpha2(const std::vector<double>& m4, const std::vector<double>& msd, std::vector<double>& a,
              std::vector<double>& err) const;
  void fs_mean(const std::vector<double>& table, std::vector<double>& mean, std::vector<double>& err) const;
  void origin_mean(const std::vector<double>& v, std::vector<double>& mean, std::vector<double>& err) const;
  std::vector<double> flow_part(const Measures& s, msd_t& m) const;

  const run_info_t& run_;
  Scene::Msd spec_;
  std::vector<std::uint8_t> species_;
  size_t n_modes_ = 0;
  std::vector<double> fs_q_;          // F_s's wave numbers
  std::vector<double> select_;        // the subsets' selection buffer
};

} // namespace dynhet
