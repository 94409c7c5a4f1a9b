// P(dx, t) for the overlap node: the x-displacement histograms of every
// (origin, lag) pair's displacement pass, tallied per block of origins, and
// the displacement_t message at the lags the scene asks for (multiples of
// tau_alpha and fixed times, each the scheduled lag nearest in ln t).
#pragma once

#include <vector>

#include "dynhet/analysis/displacement.hpp"
#include "dynhet/analysis/displacement_distribution.hpp"
#include "dynhet/displacement_t.hpp"
#include "dynhet/run_info_t.hpp"
#include "dynhet/scene.hpp"

namespace dynhet {

class DisplacementResults {
public:
  // Sets of particles: all, then the small ones (species 0).
  static constexpr int kAll = 0, kSmall = 1, kSets = 2;

  DisplacementResults(const run_info_t& run, const Scene::Displacement& scene);
  // The histogram bins of the displacement pass.
  void configure(analysis::DisplacementSpec& spec) const;
  // One pass's histograms for (origin, lag).
  void add(int origin, int lag, const analysis::DisplacementResult& pass, long n_small);
  // The message at the lags nearest the targets, given the running tau_alpha.
  displacement_t message(double tau_alpha, double cutoff_a) const;
  template <class Ar> void state(Ar& ar) { ar(tally_); } // what a checkpoint keeps

private:
  const run_info_t& run_;
  Scene::Displacement scene_;
  analysis::DisplacementSpec spec_; // only the histogram fields are used
  analysis::DistributionFitSpec fit_;
  int blocks_;
  analysis::DisplacementTally tally_;
  std::vector<long> all_; // reused: small + large counts of one pass
};

} // namespace dynhet
