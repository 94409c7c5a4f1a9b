// sim_node's flow control (below): frames wait for the nodes it paces on.
#pragma once

#include <chrono>
#include <cstdio>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "dynhet/flow_control.hpp"
#include "dynhet/bus.hpp"
#include "dynhet/lcm_exit.hpp"
#include "dynhet/lcm_guard.hpp"
#include "dynhet/lcm_url.hpp"
#include "dynhet/node_status_t.hpp"

namespace dynhet {

// Flow control: the sim does not publish frame f until every node it paces
// on has reassembled frame f - window (from their node status, which they
// publish after every frame), so that a slow or stopped node finds at most
// `window` frames waiting in its socket buffer (half of the 4 MiB
// run_scene.sh asks for, pacing_window_frames) and loses none.
// When the scene keeps the frames, the recorder is paced on too (it
// publishes its own status, node "recorder", after every kept frame). A
// node that failed or finished is not waited for; one silent for kGiveUp
// seconds (the recorder: kGiveUpRecorder) is dropped from the pacing with a
// warning (its losses are then its own, and counted).
//
// The pacer listens from the sim's start, before compression and
// equilibration (poll() drains it meanwhile): the bus then knows every
// number each node has used in this launch, and a node's status from
// equilibration replayed in production is dropped as stale, not taken as
// a first copy.
class Pacer {
public:
  Pacer(lcm::LCM& lcm, Bus bus, int64_t run_id, std::vector<std::string> nodes, long n_particles)
      : lcm_(lcm), bus_(std::move(bus)), run_id_(run_id) {
    for (auto& n : nodes) nodes_[n] = Node{};
    window_ = pacing_window_frames(n_particles);
    // Each node's own channel (DYNHET_NODE_STATUS_<node>; node names hold
    // no regex characters).
    for (auto& [name, n] : nodes_) {
      subs_.push_back(lcm_.subscribe(node_status_channel(name), &Pacer::on_status, this));
      subs_.back()->setQueueCapacity(1 << 14); // statuses pile up while the sim computes between polls
    }
  }
  // Handles every status queued (while the sim compresses, equilibrates or
  // computes a frame: nothing may pile up to where LCM drops it).
  void poll() {
    if (nodes_.empty()) return;
    while (handle_timeout(lcm_, 0) > 0) {
    }
  }
  // Production starts: a node's silence is counted from here.
  void start_production() { start_ = Clock::now(); }
  ~Pacer() {
    for (lcm::Subscription* s : subs_) lcm_.unsubscribe(s);
  }
  long window() const { return window_; }
  long unauthenticated() const { return unauthenticated_; } // node statuses dropped by the bus
  // Waits until frame f may go out; `idle` is called every ~20 ms meanwhile.
  template <class Idle> void before_frame(int f, Idle&& idle) {
    if (nodes_.empty()) return;
    for (;;) {
      if (handle_timeout(lcm_, 0) < 0 && bus_lost(lcm_)) throw std::runtime_error(kBusLost);
      const auto now = Clock::now();
      bool wait = false;
      for (auto& [name, n] : nodes_) {
        if (n.gone) continue;
        if (n.state == "failed" || n.state == "done") continue;
        if (n.whole >= f - window_ && n.seen) continue;
        const double silent = std::chrono::duration<double>(now - (n.seen ? n.last : start_)).count();
        if (silent > (name == kRecorderNode ? kGiveUpRecorder : kGiveUp)) {
          std::fprintf(stderr, "\nsim_node: node %s silent for %.0f s at frame %d: no longer waited for\n",
                       name.c_str(), silent, f);
          n.gone = true;
          continue;
        }
        wait = true;
        // Said once per node: when it is behind, or silent for longer than
        // its status interval (1 s) allows (stopped, or not started).
        if (!n.waited_for && (n.seen || silent > 2.0)) {
          std::fprintf(stderr, "\nsim_node: waiting for slow nodes (flow control, window %ld frames): %s at frame %d%s\n",
                       window_, name.c_str(), f, n.seen ? "" : " (no status from it yet)");
          n.waited_for = true;
        }
      }
      if (!wait) return;
      idle();
      handle_timeout(lcm_, 20);
    }
  }

private:
  using Clock = std::chrono::steady_clock;
  // A node's compute thread, which publishes its status, can be busy for
  // minutes on one frame at large N (S4 over many pairs); the recorder's
  // loop publishes every second, so a recorder silent for 30 s is stopped
  // or dead (killed: the sim then goes on without it after 30 s, not 300).
  static constexpr double kGiveUp = 300.0, kGiveUpRecorder = 30.0;
  struct Node {
    int whole = -1;
    std::string state;
    bool seen = false, gone = false, waited_for = false;
    Clock::time_point last;
  };
  void on_status(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    node_status_t m;
    std::string why;
    int size = 0;
    if (!bus_.open(channel, rb->data, rb->data_size, size, why)) { // never paced by it
      ++unauthenticated_;
      return;
    }
    if (!guard::safe_decode(rb->data, size, m, why)) return;
    if (m.run_id != run_id_ || channel != node_status_channel(m.node)) return; // not this node's own
    auto it = nodes_.find(m.node);
    if (it == nodes_.end()) return;
    Node& n = it->second;
    n.whole = std::max(n.whole, m.frames_whole + m.frames_lost - 1); // the last frame index it is past
    n.state = m.state;
    n.seen = true;
    n.last = Clock::now();
  }
  lcm::LCM& lcm_;
  Bus bus_;
  int64_t run_id_;
  std::map<std::string, Node> nodes_;
  long window_ = 1;
  long unauthenticated_ = 0;
  std::vector<lcm::Subscription*> subs_;
  Clock::time_point start_ = Clock::now();
};


} // namespace dynhet
