// The sim's side of a checkpoint cut (dynhet/cut.hpp, docs/checkpoints.md),
// in the spirit of Chandy and Lamport's marker: at a synchronised time
// between frames k and k + 1 (or on a signal, anywhere between them) the
// sim asks on DYNHET_CHECKPOINT that every process save its part with
// frame k folded in, then saves its own while they save theirs. Frames and
// the request leave one socket in order, so each node sees
// the request before frame k + 1. Each process answers on
// DYNHET_CHECKPOINT_<process>; the recorder answers last (it saves once
// every node has said so, so its results hold every node's up to frame k).
// When every process has answered "saved", the sim reads every part back
// from disk (an answer proves nothing: any process on the bus can publish
// one) and writes the cut's WHOLE marker: from then on the cut is the
// run's restart point, and the cuts before the previous whole one go.
// Requests are repeated every second until the cut is whole or a newer one
// replaces it (a lost datagram costs a second, not the cut).
#pragma once

#include <chrono>
#include <functional>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "dynhet/bus.hpp"

namespace dynhet {

class CutCoordinator {
public:
  // `parts`: the processes whose parts make a cut whole, the sim ("sim")
  // included. Cut numbers continue after the folder's highest.
  CutCoordinator(lcm::LCM& lcm, Bus bus, std::string dir, int64_t run_id, std::string scene_text,
                 std::vector<std::string> parts);
  ~CutCoordinator();

  // Asks every other process for its part of a cut after frame `frame` at
  // simulation time t, then writes the sim's part (its payload). Returns the
  // cut's number. Throws if the sim's part cannot be written (a full disk):
  // that cut is dropped, and the previous cut stays the restart point.
  // `stop`: the sim stops after this cut (a signal): the request says so
  // ("stop"), and every process that has had a signal stops after saving it.
  // Returns -1 (and takes nothing) once cuts are off (broken()).
  int take(int frame, double t, const std::vector<uint8_t>& sim_payload, bool stop = false);
  // Why no cut of this run can be whole, or "": a process writes its parts
  // from another build (its part's header says which), and a part from
  // another build is never read back. Said once; the open cuts are dropped
  // and no more are taken, so nothing waits for them.
  const std::string& broken() const { return broken_; }
  // Handles the answers that have come (no wait) and repeats requests that
  // are a second old; marks cuts whole.
  void poll();
  // Polls until cut `cut` is whole, `timeout` seconds have passed or
  // abort() says so.
  bool wait_whole(int cut, double timeout, const std::function<bool()>& abort = {});
  int last_whole() const { return last_whole_; }
  long unauthenticated() const { return unauthenticated_; } // answers dropped by the bus
  int newest_open() const; // -1: none
  static constexpr size_t kMaxOpen = 60; // the nodes keep 64
  // A process whose part of a cut is read back unusable after this many of
  // its "saved" answers (a forged one may come first) fails the cut.
  static constexpr int kUnusableAnswers = 3;
  // Wall-clock seconds since the last cut was taken (or since the start).
  double seconds_since_take() const;

private:
  using Clock = std::chrono::steady_clock;
  struct Pending {
    int frame;
    double time;
    bool stop = false;
    std::set<std::string> saved;         // answered "saved"
    std::map<std::string, int> unusable; // how often a process's answered part was read back unusable (named the first time)
    bool failed = false;                 // given up (a part that stays unusable)
    Clock::time_point asked;
  };

  void on_answer(const lcm::ReceiveBuffer* rb, const std::string& channel);
  void request(int cut, const Pending& p);
  bool complete(int cut, Pending& p); // false: not whole (yet)

  lcm::LCM& lcm_;
  Bus bus_;
  std::string dir_;
  int64_t run_id_;
  std::string scene_;
  uint64_t scene_hash_;
  std::vector<std::string> parts_;
  int next_cut_ = 0, last_whole_ = -1, previous_whole_ = -1;
  int last_whole_frame_ = -1, previous_whole_frame_ = -1;
  std::map<int, Pending> pending_;
  lcm::Subscription* sub_ = nullptr;
  long unauthenticated_ = 0;
  std::string broken_;
  Clock::time_point last_take_ = Clock::now();
};

} // namespace dynhet
