// What every analysis node does around its physics: take the first run
// info, assemble frames from their chunks, know which origin and which
// (origin, lag) pairs each frame serves, hold each origin frame only until
// the last frame that needs it, publish the node status every second,
// notice the end of the run (the sim says done or failed, goes silent, or
// a replayed log ends), and run the LCM loop. A node derives from
// FrameNode and says what to do with the run, a frame and its results.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "dynhet/chunking.hpp"
#include "dynhet/frame_chunk_t.hpp"
#include "dynhet/lcm_url.hpp"
#include "dynhet/node_status_t.hpp"
#include "dynhet/run_info_t.hpp"
#include "dynhet/sim_status_t.hpp"

namespace dynhet {

class FrameNode {
public:
  // `name` is the node's name in its status ("overlap") and logs ("overlap_node").
  FrameNode(lcm::LCM& out, int64_t run_filter, std::string name);
  virtual ~FrameNode() = default;

  void on_run(const lcm::ReceiveBuffer*, const std::string&, const run_info_t* m);
  void on_chunk(const lcm::ReceiveBuffer*, const std::string&, const frame_chunk_t* m);
  void on_sim_status(const lcm::ReceiveBuffer*, const std::string&, const sim_status_t* m);

  bool finished() const { return finished_; }
  bool has_run() const { return info_ != nullptr; }
  int exit_code() const { return exit_code_; }
  // The sim publishes its status every second; silence longer than
  // `timeout` (not after a checkpointed interruption) means it died.
  void check_sim_alive(double timeout);
  // The input ended (log replayed to its end) before the sim said done.
  void input_ended();
  void tick(); // the node status, once a second

protected:
  struct Pair {
    int origin, lag;
    const std::vector<double>& pos0; // the origin frame
  };
  // The run has started: info() is set.
  virtual void start() = 0;
  // A frame: `origin` its origin index (-1 if none), `pairs` the (origin,
  // lag) pairs it ends whose origin frame is held (lost ones left out).
  virtual void frame(const Frame& f, int origin, const std::vector<Pair>& pairs) = 0;
  // No later frame needs origin k: let go of what was kept for it.
  virtual void drop_origin(int) {}
  virtual void publish_results(bool final) = 0;

  const run_info_t& info() const { return *info_; }
  // The origin frames held now: origin k -> positions at t0.
  const std::map<int, std::vector<double>>& held_origins() const { return origins_; }
  // Give up on the run (the results so far are published as final).
  void fail(const std::string& why) { finish(1, why); }
  const std::string& name() const { return name_; }
  int pairs_done() const { return pairs_done_; }
  bool wants(const std::string& observable) const;
  // The fields every result message shares: when, which run, which frame.
  template <class Msg> void stamp(Msg& m, bool final) const {
    m.utime = utime_now();
    m.run_id = info_->run_id;
    m.sim_time = last_time_;
    m.frame_index = last_frame_;
    m.is_final = final;
  }

  lcm::LCM& out_;

private:
  using Clock = std::chrono::steady_clock;
  void on_frame(const Frame& f);
  void publish_status();
  void finish(int code, const std::string& why);

  std::string name_;
  int64_t run_filter_;
  std::unique_ptr<run_info_t> info_;
  std::vector<int> origin_at_, last_use_;                 // per frame; per origin
  std::vector<std::vector<std::pair<int, int>>> pairs_at_; // per frame: (origin, lag)
  std::map<int, std::vector<double>> origins_;             // origin k -> positions at t0
  FrameAssembler assembler_;
  node_status_t status_{};
  Clock::time_point last_status_ = Clock::now(), last_sim_news_ = Clock::now();
  bool sim_interrupted_ = false, finished_ = false;
  int pairs_done_ = 0, last_frame_ = -1, exit_code_ = 0;
  double last_time_ = 0;
};

// A node's main(): flags (--lcm-url, --publish-url, --run-id, --wait-run,
// --sim-timeout), the buses, the subscriptions and the loop.
using NodeFactory = std::function<std::unique_ptr<FrameNode>(lcm::LCM& out, int64_t run_filter)>;
int run_node(int argc, char** argv, const std::string& program, const std::string& description,
             const NodeFactory& make);

} // namespace dynhet
