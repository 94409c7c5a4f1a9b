// node_main (frame_node.hpp): an analysis node's process, its options, its
// receive thread and its loop, around the FrameNode the node makes.
#include "frame_node.hpp"

#include "dynhet/bus_cli.hpp"
#include "dynhet/flow_control.hpp"
#include "dynhet/lcm_exit.hpp"

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <thread>

#include <CLI/CLI.hpp>

namespace dynhet {

namespace {

std::atomic<int> g_node_signal{0};

bool read_text_file(const std::string& path, std::string& text) {
  std::ifstream in(path);
  if (!in) return false;
  std::stringstream buf;
  buf << in.rdbuf();
  text = buf.str();
  return true;
}
void on_node_signal(int sig) { g_node_signal = sig; }

// The receive thread: LCM's handle loop on the input bus, copying each
// message into the inbox and nothing else (no decoding, no checks: the
// compute thread does those), so that the socket is drained however long a
// frame takes to compute. It only calls handle(); the compute thread
// publishes (LCM 1.3.1's lcm.h: "All LCM functions are internally
// synchronized and thread-safe", and lcm_publish and lcm_handle may run in
// different threads). A replayed log waits for room in the inbox instead
// of dropping.
class Receiver {
public:
  // Each message's tag is checked here, before it takes room in the queue:
  // forgeries cannot crowd genuine frames out of it.
  Receiver(lcm::LCM& in, Inbox& inbox, bool replay, FrameNode& node)
      : in_(in), inbox_(inbox), replay_(replay), node_(node) {
    // LCM's own queues between its socket thread and handle(): deep, though
    // this thread empties them at once (checking a frame's tags takes ms,
    // and LCM drops what a full queue cannot take before any check).
    in_.subscribe(kChanRun, &Receiver::on_message, this)->setQueueCapacity(1 << 14);
    in_.subscribe(kChanFrame, &Receiver::on_message, this)->setQueueCapacity(100000);
    in_.subscribe(kChanSimStatus, &Receiver::on_message, this)->setQueueCapacity(1 << 14);
    in_.subscribe(kChanCheckpoint, &Receiver::on_message, this)->setQueueCapacity(1 << 14);
    thread_ = std::thread([this] { loop(); });
  }
  ~Receiver() { stop(); }
  // Stops the thread: the bus is then the caller's alone.
  void stop() {
    if (!thread_.joinable()) return;
    stop_ = true;
    inbox_.stop(); // wakes a push() waiting for room
    thread_.join();
  }

private:
  void loop() {
    auto last = FrameNode::Clock::now();
    while (!stop_) {
      const int r = handle_timeout(in_, 100);
      const auto now = FrameNode::Clock::now();
      inbox_.receive_turn(std::chrono::duration<double>(now - last).count());
      last = now;
      if (r < 0) { // a replayed log has ended (or the bus failed)
        inbox_.close();
        return;
      }
    }
  }
  void on_message(const lcm::ReceiveBuffer* rb, const std::string& ch) {
    const auto* p = static_cast<const uint8_t*>(rb->data);
    int size = 0;
    std::string why;
    if (!node_.bus().open(ch, rb->data, rb->data_size, size, why)) return node_.note_unauthenticated(ch, why);
    if (!inbox_.push(Inbox::Message{ch, std::vector<uint8_t>(p, p + size), rb->recv_utime}, ch == kChanFrame, replay_))
      node_.bus().count_drop(BusDrop::queue_full);
  }

  lcm::LCM& in_;
  Inbox& inbox_;
  bool replay_;
  FrameNode& node_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

} // namespace

int node_main(const std::string& program, const std::string& description, NodeFactory make_node, int argc,
              char** argv) {
  CLI::App app{description};
  std::string url, publish_url;
  int64_t run_id = 0;
  double wait_run = 300, sim_timeout = 60;
  app.add_option("--lcm-url", url, "LCM URL to read from (file://LOG?speed=0 replays a log)");
  app.add_option("--publish-url", publish_url, "LCM URL to publish on (default: the input bus)");
  app.add_option("--run-id", run_id, "only this run (default: the first one seen)");
  BusOptions bus_options;
  add_bus_options(app, bus_options);
  app.add_option("--wait-run", wait_run, "give up after this many seconds without run info");
  app.add_option("--sim-timeout", sim_timeout, "give up if the sim is silent this long (s) during a run");
  int64_t max_queue_mib = 1024;
  app.add_option("--max-queue-mib", max_queue_mib,
                 "at most this many MiB of messages wait between the receive thread and the computation (frames "
                 "also within a few times the sim's pacing window); beyond, they are dropped and counted")
      ->check(CLI::Range(int64_t{1}, int64_t{1} << 20))
      ->capture_default_str();
  double frame_delay = 0;
  app.add_option("--test-frame-delay", frame_delay,
                 "tests only: sleep this many seconds on every frame, a stand-in for heavy computation");
  std::string checkpoint_dir;
  int resume_cut = -1;
  app.add_option("--checkpoint-dir", checkpoint_dir,
                 "save this node's part of each checkpoint cut the sim asks for here (docs/checkpoints.md); "
                 "SIGTERM/SIGINT then stop the node after the next cut");
  app.add_option("--resume-cut", resume_cut, "resume from this cut of --checkpoint-dir");
  std::string analysis_path;
  app.add_option("--analysis", analysis_path,
                 "re-analysis: go by the recorded run's scene with the analysis tables and keys of this TOML in "
                 "place (cutoffs a, sub-box sizes, cage-relative, observables; dynhet/reanalysis.hpp)");
  CLI11_PARSE(app, argc, argv);
  std::string analysis_toml;
  if (!analysis_path.empty() && !read_text_file(analysis_path, analysis_toml)) {
    std::fprintf(stderr, "%s: cannot read %s\n", program.c_str(), analysis_path.c_str());
    return 2;
  }
  if (resume_cut >= 0 && checkpoint_dir.empty()) {
    std::fprintf(stderr, "%s: --resume-cut needs --checkpoint-dir\n", program.c_str());
    return 2;
  }

  const std::optional<Bus> bus = bus_or_say(program, bus_options);
  if (!bus) return 2;
  const std::string in_url = resolve_lcm_url(url);
  const bool replay = in_url.rfind("file://", 0) == 0;
  lcm::LCM in(in_url);
  std::unique_ptr<lcm::LCM> out_owned;
  if (!publish_url.empty() || replay) out_owned = std::make_unique<lcm::LCM>(resolve_lcm_url(publish_url));
  lcm::LCM& out = out_owned ? *out_owned : in;
  const std::string out_url = out_owned ? resolve_lcm_url(publish_url) : in_url;
  if (bus_unreachable(in, in_url) || bus_unreachable(out, out_url)) {
    std::fprintf(stderr, "%s: cannot open LCM (%s)\n", program.c_str(), in_url.c_str());
    return 3;
  }

  std::unique_ptr<FrameNode> node = make_node(out, run_id);
  node->set_bus(*bus);
  Inbox inbox(max_queue_mib << 20);
  inbox.set_bound(kQueueMin); // until the run info sizes it (frames come only after it)
  node->attach_inbox(&inbox);
  node->set_frame_delay(frame_delay);
  if (!analysis_path.empty()) node->set_reanalysis(analysis_toml, analysis_path);
  if (!checkpoint_dir.empty()) {
    node->set_checkpointing(checkpoint_dir, resume_cut);
    std::signal(SIGINT, on_node_signal);
    std::signal(SIGTERM, on_node_signal);
  }
  Receiver receiver(in, inbox, replay, *node); // stopped and joined before inbox, node and buses go

  std::fprintf(stderr, "%s: ready, reading %s (bus %s)\n", program.c_str(), in_url.c_str(), bus->describe());
  const auto start = FrameNode::Clock::now();
  int code = -1;
  while (code < 0 && !node->finished()) {
    if (const std::optional<Inbox::Message> m = inbox.pop(std::chrono::milliseconds(200))) {
      node->handle(*m);
    } else if (inbox.ended()) { // a replayed log has ended, every message of it handled
      if (!replay && bus_lost(in)) std::fprintf(stderr, "%s: %s\n", program.c_str(), kBusLost);
      node->input_ended();
      break;
    }
    if (const int sig = g_node_signal.exchange(0)) {
      if (!node->has_run()) { // no run yet: nothing to save, and no cut will come
        std::fprintf(stderr, "%s: signal %d before any run info: stopped, nothing to save\n", program.c_str(), sig);
        code = FrameNode::kInterrupted;
        break;
      }
      std::fprintf(stderr, "%s: signal %d: stopping after the sim's next checkpoint cut\n", program.c_str(), sig);
      node->signal_received(sig);
    }
    node->tick();
    if (!replay) node->check_sim_alive(sim_timeout);
    if (!node->has_run() && std::chrono::duration<double>(FrameNode::Clock::now() - start).count() > wait_run) {
      std::fprintf(stderr, "%s: no run info on %s within %g s\n", program.c_str(), in_url.c_str(), wait_run);
      code = 4;
    }
  }
  if (code < 0) code = node->exit_code();
  // The last results and status must reach the bus before the process ends
  // (tcpq: see dynhet/lcm_exit.hpp; udpm: nothing to wait for).
  receiver.stop();
  if (const std::string why = deliver_before_exit(out, out_url); !why.empty())
    std::fprintf(stderr, "%s: %s\n", program.c_str(), why.c_str());
  return code;
}

} // namespace dynhet
