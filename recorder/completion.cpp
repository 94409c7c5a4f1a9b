#include "completion.hpp"

#include <algorithm>

#include "dynhet/observables.hpp"
#include "dynhet/scene.hpp"

namespace dynhet {

namespace {
// Observables whose result messages the recorder knows how to write: the
// declared ones and their cage-relative variants.
bool recordable(const std::string &observable) { return find_computed_observable(observable) != nullptr; }
} // namespace

std::string Completion::final_label(const std::string &observable, double cutoff_a) {
  const ObservableInfo *o = find_computed_observable(observable);
  return o && !o->per_cutoff ? observable : observable + " " + cutoff_label(cutoff_a);
}

Completion::Completion(const std::vector<std::string> &observables, const std::vector<double> &cutoffs)
    : observables_(observables) {
  for (const std::string &obs : observables)
    if (recordable(obs))
      for (double a : cutoffs) {
        const std::string f = final_label(obs, a);
        if (std::find(expected_finals_.begin(), expected_finals_.end(), f) == expected_finals_.end())
          expected_finals_.push_back(f);
      }
}

void Completion::sim_phase(const std::string &phase, const std::string &message) {
  // The first word on how the run ended stands against other ends; but a
  // status of a live phase after it means the sim goes on, and the "done"
  // or "failed" was not its own (anyone on the bus can publish one).
  const bool live = phase != "done" && phase != "failed" && phase != "interrupted";
  if (sim_ended() && !live) return;
  phase_ = phase;
  sim_message_ = message;
}

void Completion::node_state(const std::string &node, const std::string &state) { node_state_[node] = state; }

void Completion::node_frames(const std::string &node, int whole, int lost, int expected) {
  node_frames_[node] = {whole, lost, expected};
}

void Completion::frames(int lost, int expected) {
  frames_lost_ = lost;
  frames_expected_ = expected;
}

std::string Completion::state_of(const std::string &node) const {
  auto it = node_state_.find(node_of(node)); // the node serving this observable
  return it == node_state_.end() ? "never heard from" : it->second;
}

bool Completion::finals_complete(const std::string &observable) const {
  for (const std::string &f : expected_finals_)
    if ((f == observable || f.rfind(observable + " ", 0) == 0) && !finals_.count(f)) return false;
  return true;
}

bool Completion::settled() const {
  if (!sim_ended()) return false;
  for (const std::string &obs : observables_) {
    const std::string state = state_of(obs);
    if (state == "failed") continue;
    if (state != "done" || !finals_complete(obs)) return false;
  }
  return true;
}

std::vector<std::string> Completion::missing() const {
  std::vector<std::string> out;
  if (phase_ != "done")
    out.push_back("sim: " + phase_ + (sim_message_.empty() ? "" : " (" + sim_message_ + ")"));
  for (const std::string &obs : observables_) {
    if (!recordable(obs)) out.push_back(obs + ": this recorder has no writer for its results");
    const std::string state = state_of(obs);
    if (state != "done") out.push_back(obs + " node: " + state);
  }
  for (const std::string &f : expected_finals_)
    if (!finals_.count(f)) out.push_back(f + ": no final result");
  // Every result from every frame: a node that lost or never completed a
  // frame computed its results from fewer.
  for (const auto &[node, fr] : node_frames_)
    if (fr.lost > 0 || fr.whole < fr.expected)
      out.push_back(node + " node: " + std::to_string(fr.whole) + " of " + std::to_string(fr.expected) +
                    " frames whole, " + std::to_string(fr.lost) + " lost");
  if (frames_lost_ > 0)
    out.push_back("frames: " + std::to_string(frames_lost_) + " of " + std::to_string(frames_expected_) +
                  " lost by the recorder");
  return out;
}

} // namespace dynhet
