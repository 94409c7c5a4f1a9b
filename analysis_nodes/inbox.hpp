// Between a node's receive thread and its compute thread: the messages as
// they came off the bus (channel and raw bytes), in arrival order, bounded
// in bytes. The receive thread only copies messages in, so the socket is
// drained promptly however long the compute thread spends on one frame
// (S4 at N = 10^6 takes about a second); the compute thread takes them out
// and runs the node's handlers (checks, reassembly, physics) unchanged.
// No LCM here.
//
// Two bounds: frame chunks ("bulk") are taken while the queued bytes stay
// within bound() (set from the run's N: dynhet::queue_bound_bytes, a few
// times what the sim's pacing lets pile up), every other message within
// the hard cap. A message not taken is dropped and counted: the node then
// names the cause of the frames it lost ("queue full"). A replayed log
// waits for room instead (push with wait), and loses nothing.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace dynhet {

class Inbox {
public:
  struct Message {
    std::string channel;
    std::vector<uint8_t> data;
    int64_t recv_utime = 0;
  };
  struct Stats {
    int64_t bound = 0, hard_cap = 0; // bytes
    int64_t queued_bytes = 0, peak_bytes = 0;
    int64_t dropped = 0, dropped_bytes = 0; // messages not taken (queue full)
    double longest_receive_gap = 0;         // s between two turns of the receive loop
  };

  explicit Inbox(int64_t hard_cap);

  // Receive side. Queues `m` if there is room (see above); else drops and
  // counts it, or with `wait` waits for room. Returns whether it was taken.
  bool push(Message m, bool bulk, bool wait);
  // The input has ended (a replayed log): pop() returns nothing once drained.
  void close();
  // One turn of the receive loop took `seconds` (the longest is kept: a
  // turn of seconds means the process was stopped or starved).
  void receive_turn(double seconds);

  // Compute side. The next message, waiting up to `timeout`; nothing on a
  // timeout, or once closed and drained (ended()).
  std::optional<Message> pop(std::chrono::milliseconds timeout);
  bool ended() const;
  // Bytes of frame chunks allowed from now on (at most the hard cap).
  void set_bound(int64_t bytes);

  // Shutting down: a waiting push() returns (dropping), and every later one.
  void stop();
  Stats stats() const;

private:
  // What a message costs: its bytes, its channel and the bookkeeping.
  static int64_t cost(const Message &m) {
    return static_cast<int64_t>(m.data.size() + m.channel.size()) + 64;
  }
  bool fits(int64_t c, bool bulk) const {
    return q_.empty() || s_.queued_bytes + c <= (bulk ? s_.bound : s_.hard_cap);
  }

  mutable std::mutex mu_;
  std::condition_variable not_empty_, not_full_;
  std::deque<Message> q_;
  Stats s_;
  bool closed_ = false, stopped_ = false;
};

} // namespace dynhet
