#include "completion.hpp"

#include <algorithm>
#include <cstdio>

namespace dynhet {

namespace {
// Observables whose result messages the recorder knows how to write.
bool recordable(const std::string &observable) { return observable == "overlap"; }
} // namespace

std::string cutoff_label(double cutoff_a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "a%g", cutoff_a);
  return buf;
}

Completion::Completion(const std::vector<std::string> &observables, const std::vector<double> &cutoffs)
    : observables_(observables) {
  const bool overlap = std::find(observables.begin(), observables.end(), "overlap") != observables.end();
  if (overlap)
    for (double a : cutoffs) cutoffs_.push_back(cutoff_label(a));
}

void Completion::sim_phase(const std::string &phase, const std::string &message) {
  if (sim_ended()) return; // the first word on how the run ended stands
  phase_ = phase;
  sim_message_ = message;
}

void Completion::node_state(const std::string &node, const std::string &state) { node_state_[node] = state; }

void Completion::frames(int lost, int expected) {
  frames_lost_ = lost;
  frames_expected_ = expected;
}

std::string Completion::state_of(const std::string &node) const {
  auto it = node_state_.find(node);
  return it == node_state_.end() ? "never heard from" : it->second;
}

bool Completion::finals_complete(const std::string &observable) const {
  if (observable != "overlap") return true;
  for (const std::string &c : cutoffs_)
    if (!finals_.count(c)) return false;
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
  for (const std::string &c : cutoffs_)
    if (!finals_.count(c)) out.push_back("overlap " + c + ": no final result");
  if (frames_lost_ > 0)
    out.push_back("frames: " + std::to_string(frames_lost_) + " of " + std::to_string(frames_expected_) +
                  " lost by the recorder");
  return out;
}

} // namespace dynhet
