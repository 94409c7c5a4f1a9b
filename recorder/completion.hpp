// What a run still owes the recorder before its file is complete: the
// sim's last phase, each named observable's node state and final results,
// and (when the trajectory is kept) the frames. Plain bookkeeping: no LCM,
// no HDF5.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

#include "dynhet/lcm_url.hpp" // cutoff_label

namespace dynhet {

class Completion {
public:
  Completion() = default;
  // The observables the run names and the cutoffs (one final result of
  // each observable per cutoff).
  Completion(const std::vector<std::string> &observables, const std::vector<double> &cutoffs);

  void sim_phase(const std::string &phase, const std::string &message);
  void node_state(const std::string &node, const std::string &state);
  // A node's frame counts from its last status: a node that did not
  // reassemble every frame the sim published makes the file incomplete.
  void node_frames(const std::string &node, int whole, int lost, int expected);
  // A final result of `observable` ("overlap", or "overlap_cr" for the
  // cage-relative results) for one cutoff; one of an observable that is not
  // per cutoff (msd, ...) stands for every cutoff (cutoff ignored).
  void final_result(const std::string &observable, double cutoff_a) { finals_.insert(final_label(observable, cutoff_a)); }
  // "overlap a0.6", or "msd" for an observable that is not per cutoff.
  static std::string final_label(const std::string &observable, double cutoff_a);
  void frames(int lost, int expected);

  // The sim has said done or failed.
  bool sim_ended() const { return phase_ == "done" || phase_ == "failed"; }
  // Nothing more is coming: the sim ended and every node needed has said
  // done (with all its final results) or failed.
  bool settled() const;
  // What is missing for a complete file, one line each; empty if complete.
  std::vector<std::string> missing() const;

  const std::string &phase() const { return phase_; }

private:
  std::vector<std::string> observables_;
  std::vector<std::string> expected_finals_; // "overlap a0.6", ...
  std::string phase_ = "unknown", sim_message_;
  std::map<std::string, std::string> node_state_;
  struct Frames {
    int whole = 0, lost = 0, expected = 0;
  };
  std::map<std::string, Frames> node_frames_;
  std::set<std::string> finals_;
  int frames_lost_ = 0, frames_expected_ = 0;

  bool finals_complete(const std::string &observable) const;
  std::string state_of(const std::string &node) const;
};

} // namespace dynhet
