// What every analysis node shares, in the LCM layer above the kernels: it
// takes the run info of the first run seen (or of --run-id), reassembles
// frames from chunks, knows from the schedule which frame is which origin
// and which (origin, lag) pairs it completes, holds each origin frame
// (16 N bytes) only until the last pair the node uses has been seen,
// watches the sim (done, failed, interrupted, silent, or a replayed log
// that ends) and publishes the node status after every frame and every
// second. Two threads (node_main): a receive thread runs LCM's handle loop
// and only copies each message into a bounded Inbox; the compute thread
// (everything here) takes them out and handles them. A node derives
// from FrameNode and says which lags it uses, what to do with an origin
// frame and with a pair, and how to publish its results; node_main<Node>()
// is its main().
//
// (Two branches took this layer out of overlap_node independently; this is
// their union: the per-origin and per-pair hooks, uses_lag and node_main of
// one, held_origins() and wants() of the other.)
#pragma once

#include <optional>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "dynhet/bus.hpp"
#include "dynhet/checkpoint_t.hpp"
#include "dynhet/chunking.hpp"
#include "dynhet/frame_chunk_t.hpp"
#include "dynhet/state_archive.hpp"
#include "dynhet/lcm_url.hpp"
#include "dynhet/node_status_t.hpp"
#include "dynhet/run_info_t.hpp"
#include "dynhet/sim_status_t.hpp"
#include "inbox.hpp"

namespace dynhet {

// The mean time between the run's origins (0 with fewer than two): the
// jackknife blocks of origins span the longest lag an estimate uses
// (analysis::origin_block). run_info_problem has checked the indices.
inline double origin_spacing(const run_info_t& m) {
  if (m.n_origins < 2) return 0;
  const double first = m.frame_time[m.origin_frame.front()], last = m.frame_time[m.origin_frame.back()];
  return (last - first) / (m.n_origins - 1);
}

class FrameNode {
public:
  using Clock = std::chrono::steady_clock;

  // `name` is the node's name in its status ("overlap") and logs ("overlap_node").
  FrameNode(lcm::LCM& out, int64_t run_filter, std::string name);
  virtual ~FrameNode() = default;

  bool finished() const { return finished_; }
  // The bus's side of this node: its key (or none, --unauthenticated).
  void set_bus(Bus bus) { bus_ = std::move(bus); }
  const Bus& bus() const { return bus_; }
  // A message the receive thread dropped before it reached the queue (no
  // tag, a wrong one, a replay: bus.hpp): counted, said (the first ten,
  // then every thousandth), never queued. Thread-safe.
  void note_unauthenticated(const std::string& channel, const std::string& why);
  bool has_run() const { return info_ != nullptr; }
  int exit_code() const { return exit_code_; }
  // The sim publishes its status every second; silence longer than
  // `timeout` (not after a checkpointed interruption) means it died.
  void check_sim_alive(double timeout);
  // The input ended (log replayed to its end) before the sim said done.
  void input_ended();
  // The queue from the receive thread: its bound is set from the run's N,
  // and what it dropped or saw (a stalled receive loop) names the cause of
  // lost frames.
  void attach_inbox(Inbox* inbox) { inbox_ = inbox; }
  // A re-analysis (dynhet/reanalysis.hpp): the run info, once checked,
  // goes with the analysis of this TOML text (`origin` names its file) in
  // place of the recorded one. Changes to what decided the frames fail the
  // node before it computes anything.
  void set_reanalysis(std::string analysis_toml, std::string origin) {
    reanalysis_ = std::move(analysis_toml), reanalysis_origin_ = std::move(origin);
  }
  // Tests: sleep this long on every frame, a stand-in for heavy physics.
  void set_frame_delay(double seconds) { frame_delay_ = seconds; }
  // One message from the inbox, to its raw handler by channel.
  void handle(const Inbox::Message& m);
  void tick(); // node status once a second

  // The handlers take raw buffers: each message is checked (encoding,
  // then contents) before use, and a bad one is dropped and counted
  // (messages_rejected in the node status), never fatal.
  void on_run_raw(const lcm::ReceiveBuffer* rb, const std::string& ch);
  void on_chunk_raw(const lcm::ReceiveBuffer* rb, const std::string& ch);
  void on_sim_status_raw(const lcm::ReceiveBuffer* rb, const std::string& ch);
  void on_checkpoint_raw(const lcm::ReceiveBuffer* rb, const std::string& ch);
  void reject(const std::string& channel, const std::string& why);

  // Checkpoint cuts (dynhet/cut.hpp, docs/checkpoints.md): parts are saved
  // under `dir` when the sim asks; resume_cut >= 0 loads this node's part
  // of that cut once the run info is here.
  void set_checkpointing(const std::string& dir, int resume_cut) { cut_dir_ = dir, resume_cut_ = resume_cut; }
  bool checkpointing() const { return !cut_dir_.empty(); }
  // SIGTERM or SIGINT: save the next cut the sim asks for, then stop
  // (resumable); the sim's "interrupted" also stops it.
  void signal_received(int sig) {
    signal_ = sig;
    signalled_at_ = Clock::now();
  }
  // A node signalled alone (the sim not) stops after this long without the
  // sim's "stop" cut.
  static constexpr double kSignalWait = 300;
  // Exit status of a node that stopped with its state saved in a cut (or
  // whose sim stopped so), to be resumed.
  static constexpr int kInterrupted = 2;

protected:
  // The run has started: set up. Throwing fails the node with the message
  // (no results are published then).
  virtual void start(const run_info_t& m) = 0;
  // Whether the node evaluates lag j (asked after start()); origins are held
  // only until their last used lag.
  virtual bool uses_lag(int) const { return true; }
  // Origin frame k has arrived (before the pairs the same frame ends); it
  // is held (held_origins()) until on_origin_dropped(k).
  virtual void on_origin(int /*k*/, const std::vector<double>& /*pos0*/) {}
  virtual void on_origin_dropped(int /*k*/) {}
  // One (origin k, lag j) pair: origin positions and the frame at t0 + lag
  // (pairs whose origin frame was lost are left out).
  virtual void on_pair(int k, int j, const std::vector<double>& pos0, const Frame& f) = 0;
  // After a frame that completed at least one pair, and at the end (final).
  virtual void publish_results(bool final) = 0;
  // The node's own state in a checkpoint part (after the base's): every
  // accumulator, so that a resumed node goes on bit for bit. load_state
  // comes after start(), with held_origins() restored: rebuild there what
  // derives from them.
  virtual void save_state(StateOut& out) = 0;
  virtual void load_state(StateIn& in) = 0;

  // The fields every result message shares: when, which run, which frame.
  template <class Msg> void stamp(Msg& m, bool final) const {
    m.utime = utime_now();
    m.run_id = info_->run_id;
    m.sim_time = last_time_;
    m.frame_index = last_frame_;
    m.is_final = final;
  }
  const run_info_t& info() const { return *info_; }
  // The origin frames held now: origin k -> positions at t0.
  const std::map<int, std::vector<double>>& held_origins() const { return origins_; }
  // Whether the run's scene asks for `observable`.
  bool wants(const std::string& observable) const;
  // Publishes m on the output bus, tagged with the run's key (bus.hpp).
  template <class M> int publish(const std::string& channel, const M& m) { return bus_.publish(out_, channel, m); }
  int pairs_done() const { return pairs_done_; }
  const std::string& name() const { return name_; }

private:
  void on_run(const run_info_t& m);
  void on_chunk(const frame_chunk_t& m);
  void on_sim_status(const sim_status_t& m);
  void on_frame(const Frame& f);
  void maybe_done();
  std::string loss_cause() const;
  void watch_inbox();
  Inbox* inbox_ = nullptr;
  int64_t inbox_dropped_seen_ = 0;
  double longest_handler_ = 0; // s: the longest one message (a frame's physics) took here
  double frame_delay_ = 0;
  static constexpr double kDoneGrace = 10.0; // s of silence after "done" before frames count as lost
  // s without a chunk after which a frame the sim says it has published,
  // still incomplete here, is lost (FrameAssembler::give_up_before)
  static constexpr double kChunkGrace = 2.0;
  void publish_status();
  void finish(int code, const std::string& why);
  void drain_unauthenticated(); // the receive thread's count into the status (compute thread)
  std::atomic<int64_t> unauthenticated_new_{0}, unauthenticated_said_{0};

  // Checkpoint cuts.
  void on_checkpoint(const checkpoint_t& m);
  // Saves the pending cut if this node is at its frame boundary: frame
  // `frame` folded in and nothing later (next_chunk_frame: the frame of a
  // chunk about to be added, -1 none).
  void try_cut(int next_chunk_frame = -1);
  struct Boundary { // the cuts asked for at one frame boundary
    std::vector<int> cuts;
    bool stop = false; // one of them is the sim's last before it stops
  };
  void save_cut(int frame, const Boundary& b);
  void answer_cut(int cut, int frame, const std::string& state, int64_t bytes, double seconds,
                  const std::string& message);
  void load_cut();
  void stop_resumable(const std::string& why);
  std::string sim_stopped_why() const;
  template <class Ar> void base_state(Ar& ar) {
    ar(origins_, last_frame_, last_time_, pairs_done_, assembler_, status_.messages_rejected, status_.chunks_rejected,
       status_.last_rejection, status_.messages_unauthenticated);
  }
  std::string reanalysis_, reanalysis_origin_;
  std::string cut_dir_;
  int resume_cut_ = -1, signal_ = 0;
  Clock::time_point signalled_at_;
  std::map<int, Boundary> pending_cuts_; // asked for, not yet saved: frame -> cuts
  int saved_frame_ = -2;                  // the boundary of the last part saved (-2: none)
  int first_pending_frame() const;           // the earliest frame a pending cut is after (INT32_MAX: none)
  // The boundaries saved (the 64 latest): the sim asks again every second
  // for a cut a slower process has not saved yet, and the answer to a
  // boundary this node is past stays "saved".
  struct SavedPart {
    int64_t bytes = 0;
    double seconds = 0;
  };
  std::map<int, SavedPart> saved_parts_; // frame -> its part

  lcm::LCM& out_;
  Bus bus_ = Bus::open_bus();
  int64_t run_filter_;
  std::string name_;
  std::unique_ptr<run_info_t> info_;
  std::vector<int> origin_at_, last_use_;                 // per frame; per origin
  std::vector<std::vector<std::pair<int, int>>> pairs_at_; // per frame: the used (origin, lag)
  std::map<int, std::vector<double>> origins_;             // origin k -> positions at t0
  FrameAssembler assembler_;
  node_status_t status_{};
  Clock::time_point last_status_ = Clock::now(), last_sim_news_ = Clock::now(), last_chunk_ = Clock::now();
  bool sim_interrupted_ = false, started_ = false, finished_ = false;
  std::optional<Clock::time_point> done_said_; // when a "done" of this run came, if one did
  int pairs_done_ = 0, last_frame_ = -1, exit_code_ = 0;
  double last_time_ = 0;
};

// A node's main(): flags (--lcm-url, --publish-url, --run-id, --wait-run,
// --sim-timeout, --max-queue-mib), the buses (file://LOG?speed=0 replays a
// log and then publishes on --publish-url), the receive thread and the
// compute loop.
// make_node(out, run_id) builds the node.
using NodeFactory = std::unique_ptr<FrameNode> (*)(lcm::LCM& out, int64_t run_id);
int node_main(const std::string& program, const std::string& description, NodeFactory make_node, int argc,
              char** argv);
template <class Node> int node_main(const std::string& program, const std::string& description, int argc, char** argv) {
  return node_main(
      program, description,
      [](lcm::LCM& out, int64_t run_id) -> std::unique_ptr<FrameNode> { return std::make_unique<Node>(out, run_id); },
      argc, argv);
}

} // namespace dynhet
