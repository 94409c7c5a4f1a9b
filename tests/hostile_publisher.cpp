// A hostile publisher on dynhet's channels, for tests/hostile.sh: for
// `seconds` it sends, in rounds, every class of bad message a process on
// the bus could send to the run `run_id`:
//   - random bytes after each type's valid fingerprint, on its channel;
//   - arrays declaring a negative or a huge length (2^31 - 1) in a short
//     message;
//   - run info of this run with frame indices out of range;
//   - chunks of this run whose first particle is near 2^31 (int overflow),
//     that declare N = 2^30, frames of 1 particle, 2^24 chunks per frame,
//     or NaN positions;
//   - messages of another run (run info, chunks, a "done" status).
// Every one of them must be dropped (and counted) by every receiver; the
// run's results must equal a clean run's bit for bit. With --forge-done it
// also sends a well-formed "done" status of this run, saying INT32_MAX or -7
// frames are out (a forgery no check can tell from the sim's), which must
// not end a node before its frames nor make it give up frames.
//
// With --relay it sends nothing of its own: it republishes every result and
// node status of the run, byte for byte, on another source's channel (the
// other cutoff's, a0.6 <-> a1, the tiny scene's; another node's): genuine
// messages whose channel disagrees with their own cutoff or node, which the
// recorder and the sim must drop (channels carry one source each).
//
// The bus is authenticated (bus.hpp): without --key-file this publisher is
// an attacker that knows the run id but not the run's key, and every
// message it sends must be dropped as unauthenticated before any check of
// its content. With --key-file KEY it holds the key (a process of the run
// gone wrong): its messages pass the bus and meet the checks of their
// content, as above.
//
// With --tamper (no key) it forges from the run's own traffic: every
// message of the run it hears it sends back three ways on the same
// channel: byte for byte (a replay), without its tag (a well-formed
// message of this run, as an attacker who knows the run id writes one),
// and with one byte of its content changed under the genuine tag. All
// three must be dropped and counted, and the sim must not be paced by the
// forged node statuses. --tamper --replay-only sends the byte-for-byte
// copies alone (each must be dropped as a replay). --tamper --hold keeps
// every message of the run's first launch and sends them all again once
// the run has been resumed (a later launch, another epoch): each must be
// dropped as a message of another launch.
//
// With --replay-state (no key) it sends the run's own state messages
// again, byte for byte, at the moments they could move the run backwards:
// every state message of compression and equilibration (run info, sim and
// node statuses) once production starts; each node's earlier statuses when
// it is halfway through its frames; each node's earlier statuses once it
// says "done", and the sim's (with its run info) once it says "done". Each
// copy must be dropped as stale by every receiver (whatever its replay
// window holds), the run must complete, its results equal a clean run's.
//
// Without a key it also sends, every round, well-formed statuses of every
// node and the recorder of this run saying they are far ahead (a million
// frames whole): the sim must not take them.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "dynhet/bus_auth.hpp"
#include "dynhet/checkpoint_t.hpp"
#include "dynhet/chi4_t.hpp"
#include "dynhet/clusters_t.hpp"
#include "dynhet/bond_breaking_t.hpp"
#include "dynhet/displacement_t.hpp"
#include "dynhet/frame_chunk_t.hpp"
#include "dynhet/msd_t.hpp"
#include "dynhet/node_status_t.hpp"
#include "dynhet/overlap_t.hpp"
#include "dynhet/run_info_t.hpp"
#include "dynhet/s4_t.hpp"
#include "dynhet/sim_status_t.hpp"

namespace {

// --key-file: everything sent is tagged with the run's key (an insider).
std::unique_ptr<dynhet::BusSigner> g_signer;

void send(lcm::LCM& lcm, const std::string& ch, const void* data, unsigned n) {
  if (!g_signer) {
    lcm.publish(ch, data, n);
    return;
  }
  std::vector<uint8_t> b(static_cast<const uint8_t*>(data), static_cast<const uint8_t*>(data) + n);
  b.resize(n + dynhet::kBusTagBytes);
  g_signer->tag(ch, b.data(), n);
  lcm.publish(ch, b.data(), static_cast<unsigned>(b.size()));
}
template <class M> void send(lcm::LCM& lcm, const std::string& ch, const M* m) {
  const int n = m->getEncodedSize();
  std::vector<uint8_t> b(n);
  m->encode(b.data(), 0, n);
  send(lcm, ch, b.data(), static_cast<unsigned>(n));
}

// Big-endian writer for hand-made encodings.
struct Bytes {
  std::vector<uint8_t> b;
  void i64(int64_t v) {
    for (int s = 56; s >= 0; s -= 8) b.push_back(static_cast<uint8_t>(uint64_t(v) >> s));
  }
  void i32(int32_t v) {
    for (int s = 24; s >= 0; s -= 8) b.push_back(static_cast<uint8_t>(uint32_t(v) >> s));
  }
  void f64(double v) {
    int64_t u;
    std::memcpy(&u, &v, 8);
    i64(u);
  }
};

template <class T> void random_after_fingerprint(lcm::LCM& lcm, const char* ch, std::mt19937_64& gen) {
  Bytes m;
  m.i64(T::getHash());
  const int n = static_cast<int>(gen() % 400);
  for (int i = 0; i < n; ++i) m.b.push_back(static_cast<uint8_t>(gen()));
  send(lcm, ch, m.b.data(), static_cast<unsigned>(m.b.size()));
}

// A frame chunk header of run `run`, then n_values as declared and `have`
// positions actually present.
void chunk(lcm::LCM& lcm, int64_t run, int frame, int n_particles, int index, int count_chunks, int first,
           int count, int32_t n_values, int have, double value) {
  Bytes m;
  m.i64(dynhet::frame_chunk_t::getHash());
  m.i64(0);
  m.i64(run);
  m.i32(frame);
  m.f64(1.0);
  m.i32(n_particles);
  m.i32(index);
  m.i32(count_chunks);
  m.i32(first);
  m.i32(count);
  m.i32(n_values);
  for (int i = 0; i < have; ++i) m.f64(value);
  send(lcm, "DYNHET_FRAME", m.b.data(), static_cast<unsigned>(m.b.size()));
}

dynhet::run_info_t bad_run_info(int64_t run) {
  dynhet::run_info_t m{};
  m.run_id = run;
  m.n_particles = 300;
  m.box_length = 30;
  m.packing_fraction = 0.6;
  m.restitution = 0.9;
  m.radius[0] = 1, m.radius[1] = 1.43, m.mass[0] = 1, m.mass[1] = 2.04;
  m.n_small = 150;
  m.n_frames = 3;
  m.frame_time = {0, 1, 2};
  m.n_origins = 1;
  m.origin_frame = {1000000}; // out of range
  m.n_lags = 2;
  m.lag_time = {1, 2};
  m.n_pairs = 2;
  m.pair_frame = {1, 2000000}; // out of range
  m.n_cutoffs = 1;
  m.cutoff_a = {0.6};
  m.n_observables = 1;
  m.observables = {"overlap"};
  m.overlap_subbox_particles = 30;
  m.n_chi4_sizes = 0;
  m.chunk_particles = 128;
  return m;
}

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

// The channel of another source of the same family: the other cutoff of
// the tiny scene, or the next node; "" if none.
std::string other_source(const std::string& ch) {
  auto ends = [&](const std::string& tail) {
    return ch.size() > tail.size() && ch.compare(ch.size() - tail.size(), tail.size(), tail) == 0;
  };
  auto swap_tail = [&](size_t n, const std::string& tail) { return ch.substr(0, ch.size() - n) + tail; };
  if (ends("_a0.6")) return swap_tail(4, "a1");
  if (ends("_a1")) return swap_tail(2, "a0.6");
  if (ends("_overlap")) return swap_tail(7, "clusters");
  if (ends("_clusters")) return swap_tail(8, "s4");
  if (ends("_s4")) return swap_tail(2, "overlap");
  return "";
}

// Republishes each message once (its own copies come back over the bus:
// a payload already relayed is not relayed again).
class Relay {
public:
  explicit Relay(lcm::LCM& lcm) : lcm_(lcm) {
    for (const char* family : {"DYNHET_OVERLAP_.*", "DYNHET_CHI4_.*", "DYNHET_S4_.*", "DYNHET_CLUSTERS_.*",
                               "DYNHET_NODE_STATUS_.*"})
      lcm_.subscribe(family, &Relay::on_message, this)->setQueueCapacity(10000);
  }
  long relayed() const { return relayed_; }

private:
  void on_message(const lcm::ReceiveBuffer* rb, const std::string& ch) {
    // Once the recorder has said it is done, copies would only count as
    // relayed without a recorder to drop them: stop.
    if (ch == "DYNHET_NODE_STATUS_recorder") {
      dynhet::node_status_t m;
      if (m.decode(rb->data, 0, static_cast<int>(rb->data_size)) > 0 && (m.state == "done" || m.state == "failed"))
        recorder_done_ = true;
      return;
    }
    if (recorder_done_) return;
    const std::string to = other_source(ch);
    if (to.empty()) return;
    const auto* p = static_cast<const char*>(rb->data);
    if (!seen_.insert(std::string(p, rb->data_size)).second) return;
    lcm_.publish(to, rb->data, rb->data_size);
    ++relayed_;
  }
  lcm::LCM& lcm_;
  std::set<std::string> seen_;
  long relayed_ = 0;
  bool recorder_done_ = false;
};

// Sends every message of the run back three ways (--tamper): a replay, the
// content without its tag, the content changed under the genuine tag.
class Tamper {
public:
  // hold: keep the run's messages and send them all again, byte for byte,
  // once a later launch of the run (a resume: another epoch) has its sim out.
  Tamper(lcm::LCM& lcm, bool replay_only, bool hold) : lcm_(lcm), replay_only_(replay_only), hold_(hold) {
    lcm_.subscribe("DYNHET_.*", &Tamper::on_message, this)->setQueueCapacity(100000);
  }
  long forged() const { return forged_; }

private:
  void on_message(const lcm::ReceiveBuffer* rb, const std::string& ch) {
    const auto* p = static_cast<const uint8_t*>(rb->data);
    const std::string bytes(reinterpret_cast<const char*>(p), rb->data_size);
    if (!seen_.insert(bytes).second) return; // its own copies, back over the bus
    const size_t n = rb->data_size;
    const std::optional<uint64_t> epoch = dynhet::bus_epoch_of(p, n);
    if (!epoch || n < dynhet::kBusTagBytes + 8) return; // tagged, with a fingerprint to leave alone
    if (hold_) {
      if (!first_epoch_) first_epoch_ = epoch;
      if (*epoch == *first_epoch_) {
        held_.emplace_back(ch, bytes);
      } else if (!held_.empty() && ch == "DYNHET_RUN") {
        // The run resumed and its new sim is out (every process of the new
        // launch listens by then): the first launch's messages, all again.
        std::fprintf(stderr, "hostile_publisher: %s of another launch heard: sending the %zu messages of the first again\n",
                     ch.c_str(), held_.size());
        for (const auto& [c, b] : held_) lcm_.publish(c, b.data(), static_cast<unsigned>(b.size()));
        forged_ += static_cast<long>(held_.size());
        held_.clear();
      }
      return;
    }
    if (ch == "DYNHET_NODE_STATUS_recorder") {
      dynhet::node_status_t m;
      if (m.decode(p, 0, static_cast<int>(n - dynhet::kBusTagBytes)) > 0 && (m.state == "done" || m.state == "failed"))
        recorder_done_ = true;
    }
    if (recorder_done_) return;
    std::string replay = bytes, untagged = bytes.substr(0, n - dynhet::kBusTagBytes);
    std::string changed = bytes;
    changed[8 + (n - dynhet::kBusTagBytes - 8) / 2] ^= 0x01; // in the content, past the fingerprint
    for (const std::string* f : {&replay, &untagged, &changed}) {
      if (replay_only_ && f != &replay) continue;
      seen_.insert(*f);
      lcm_.publish(ch, f->data(), static_cast<unsigned>(f->size()));
      ++forged_;
    }
  }
  lcm::LCM& lcm_;
  bool replay_only_, hold_;
  std::optional<uint64_t> first_epoch_;
  std::vector<std::pair<std::string, std::string>> held_;
  std::set<std::string> seen_;
  long forged_ = 0;
  bool recorder_done_ = false;
};

// Sends the run's state messages again (--replay-state; see the top).
class StateReplay {
public:
  explicit StateReplay(lcm::LCM& lcm) : lcm_(lcm) {
    lcm_.subscribe("DYNHET_.*", &StateReplay::on_message, this)->setQueueCapacity(100000);
  }
  long forged() const { return forged_; }
  void report() const {
    std::printf("hostile_publisher: replayed %ld state messages (%ld of equilibration in production, %ld halfway, "
                "%ld after a done, %ld of them the recorder's own after its done)\n",
                forged_, equilibration_, halfway_, after_done_, recorder_after_done_);
  }

private:
  void on_message(const lcm::ReceiveBuffer* rb, const std::string& ch) {
    const auto* p = static_cast<const uint8_t*>(rb->data);
    const size_t n = rb->data_size;
    if (!dynhet::carries_state(ch) || !dynhet::bus_epoch_of(p, n)) return;
    const std::string bytes(reinterpret_cast<const char*>(p), n);
    if (!seen_.insert(bytes).second) return; // its own copies, back over the bus
    const int lcm_bytes = static_cast<int>(n - dynhet::kBusTagBytes);
    if (ch == "DYNHET_SIM_STATUS") {
      dynhet::sim_status_t m;
      if (m.decode(p, 0, lcm_bytes) <= 0) return;
      if (m.phase == "production" && !production_) {
        production_ = true;
        equilibration_ += replay_all(); // everything before production, now
      }
      if (m.phase == "done" && !sim_done_) {
        sim_done_ = true;
        after_done_ += replay("DYNHET_SIM_STATUS") + replay("DYNHET_RUN");
      }
    } else if (ch.rfind("DYNHET_NODE_STATUS_", 0) == 0) {
      dynhet::node_status_t m;
      if (m.decode(p, 0, lcm_bytes) <= 0) return;
      if (m.frames_expected > 0 && 2 * m.frames_whole >= m.frames_expected && halfway_done_.insert(ch).second)
        halfway_ += replay(ch);
      if (m.state == "done" && done_.insert(ch).second) {
        const long k = replay(ch);
        after_done_ += k;
        if (m.node == "recorder") recorder_after_done_ += k; // sent when no one is left to hear them
      }
    }
    held_[ch].push_back(bytes);
  }
  long replay(const std::string& ch) { // every message held of ch, in order
    long k = 0;
    for (const std::string& b : held_[ch]) {
      lcm_.publish(ch, b.data(), static_cast<unsigned>(b.size()));
      ++k;
    }
    forged_ += k;
    return k;
  }
  long replay_all() {
    long k = 0;
    for (const auto& [ch, list] : held_) k += replay(ch);
    return k;
  }
  lcm::LCM& lcm_;
  std::map<std::string, std::vector<std::string>> held_;
  std::set<std::string> seen_, halfway_done_, done_;
  bool production_ = false, sim_done_ = false;
  long forged_ = 0, equilibration_ = 0, halfway_ = 0, after_done_ = 0, recorder_after_done_ = 0;
};

} // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: hostile_publisher URL RUN_ID SECONDS [--forge-done | --relay | --tamper] "
                         "[--key-file KEY]\n");
    return 2;
  }
  lcm::LCM lcm(argv[1]);
  if (!lcm.good()) return 3;
  const int64_t run = std::stoll(argv[2]);
  const double seconds = std::stod(argv[3]);
  bool forge_done = false, relay = false, tamper = false, replay_only = false, hold = false, replay_state = false;
  std::string key_file;
  for (int i = 4; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--forge-done") forge_done = true;
    else if (a == "--relay") relay = true;
    else if (a == "--tamper") tamper = true;
    else if (a == "--replay-only") replay_only = true;
    else if (a == "--hold") hold = true;
    else if (a == "--replay-state") replay_state = true;
    else if (a == "--key-file" && i + 1 < argc) key_file = argv[++i];
    else {
      std::fprintf(stderr, "hostile_publisher: unknown argument %s\n", a.c_str());
      return 2;
    }
  }
  if (!key_file.empty()) {
    // An insider holds the key and reads the launch's epoch off the run's
    // own traffic (it travels in clear): wait for the first tagged message.
    struct Epoch {
      std::optional<uint64_t> e;
      void on(const lcm::ReceiveBuffer* rb, const std::string&) {
        const auto* p = static_cast<const uint8_t*>(rb->data);
        const size_t n = rb->data_size;
        if (!e) e = dynhet::bus_epoch_of(p, n);
      }
    } epoch;
    lcm::Subscription* sub = lcm.subscribe("DYNHET_.*", &Epoch::on, &epoch);
    const auto t0 = std::chrono::steady_clock::now();
    while (!epoch.e && std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < seconds)
      lcm.handleTimeout(100);
    lcm.unsubscribe(sub);
    if (!epoch.e) {
      std::fprintf(stderr, "hostile_publisher: no tagged message of the run heard\n");
      return 1;
    }
    g_signer = std::make_unique<dynhet::BusSigner>(dynhet::BusKey::load(key_file), *epoch.e);
  }
  if (replay_state) {
    std::signal(SIGTERM, on_signal);
    std::signal(SIGINT, on_signal);
    StateReplay r(lcm);
    const auto t0 = std::chrono::steady_clock::now();
    while (!g_stop && std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < seconds)
      lcm.handleTimeout(100);
    r.report();
    return 0;
  }
  if (relay || tamper) {
    std::signal(SIGTERM, on_signal);
    std::signal(SIGINT, on_signal);
    const auto t0 = std::chrono::steady_clock::now();
    std::unique_ptr<Relay> r;
    std::unique_ptr<Tamper> t;
    if (relay) r = std::make_unique<Relay>(lcm);
    else t = std::make_unique<Tamper>(lcm, replay_only, hold);
    while (!g_stop && std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < seconds)
      lcm.handleTimeout(100);
    if (r) std::printf("hostile_publisher: relayed %ld messages to another source's channel\n", r->relayed());
    else std::printf("hostile_publisher: forged %ld messages from the run's own\n", t->forged());
    return 0;
  }
  std::mt19937_64 gen(12345);
  const auto t0 = std::chrono::steady_clock::now();
  long rounds = 0;
  const double nan = std::nan("");
  while (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < seconds) {
    random_after_fingerprint<dynhet::run_info_t>(lcm, "DYNHET_RUN", gen);
    random_after_fingerprint<dynhet::frame_chunk_t>(lcm, "DYNHET_FRAME", gen);
    random_after_fingerprint<dynhet::sim_status_t>(lcm, "DYNHET_SIM_STATUS", gen);
    random_after_fingerprint<dynhet::node_status_t>(lcm, "DYNHET_NODE_STATUS_overlap", gen);
    random_after_fingerprint<dynhet::overlap_t>(lcm, "DYNHET_OVERLAP_a0.6", gen);
    random_after_fingerprint<dynhet::chi4_t>(lcm, "DYNHET_CHI4_a0.6", gen);
    random_after_fingerprint<dynhet::msd_t>(lcm, "DYNHET_MSD", gen);
    random_after_fingerprint<dynhet::s4_t>(lcm, "DYNHET_S4_a1", gen);
    random_after_fingerprint<dynhet::clusters_t>(lcm, "DYNHET_CLUSTERS_a1", gen);
    random_after_fingerprint<dynhet::displacement_t>(lcm, "DYNHET_DISPLACEMENT", gen);
    random_after_fingerprint<dynhet::overlap_t>(lcm, "DYNHET_OVERLAP_CR_a0.6", gen);
    random_after_fingerprint<dynhet::msd_t>(lcm, "DYNHET_MSD_CR", gen);
    random_after_fingerprint<dynhet::bond_breaking_t>(lcm, "DYNHET_BOND_BREAKING", gen);
    random_after_fingerprint<dynhet::checkpoint_t>(lcm, "DYNHET_CHECKPOINT", gen);
    random_after_fingerprint<dynhet::checkpoint_t>(lcm, "DYNHET_CHECKPOINT_overlap", gen);
    // Checkpoint cuts of this run: forged requests (a huge cut number, a
    // frame far ahead, NaN time, a process name that is a path, a state
    // nobody knows) and forged "saved" answers of every node and the
    // recorder: no cut may become whole without its parts on disk, none may
    // block the real cuts, and the results must not change.
    dynhet::checkpoint_t ck{};
    ck.run_id = run;
    ck.process = "sim", ck.state = "save", ck.cut = 999999 - static_cast<int>(rounds % 7), ck.frame = 0;
    send(lcm, "DYNHET_CHECKPOINT", &ck);
    ck.cut = static_cast<int>(rounds % 5), ck.frame = 55; // an early number, a late frame
    send(lcm, "DYNHET_CHECKPOINT", &ck);
    ck.sim_time = nan;
    send(lcm, "DYNHET_CHECKPOINT", &ck);
    ck.sim_time = 1, ck.process = "../../etc", ck.state = "saved";
    send(lcm, "DYNHET_CHECKPOINT_overlap", &ck);
    ck.process = "sim", ck.state = "explode";
    send(lcm, "DYNHET_CHECKPOINT", &ck);
    for (const char* p : {"overlap", "s4", "clusters", "recorder"}) {
      ck.process = p, ck.state = "saved", ck.frame = static_cast<int>(rounds % 56);
      for (int c = 0; c < 3; ++c) {
        ck.cut = c;
        send(lcm, std::string("DYNHET_CHECKPOINT_") + p, &ck);
      }
    }
    // Declared lengths the message cannot hold: negative, and 2^31 - 1.
    chunk(lcm, run, 0, 300, 0, 3, 0, 128, -5, 0, 0.0);
    chunk(lcm, run, 0, 300, 0, 3, 0, 128, 0x7fffffff, 4, 0.0);
    // Chunk headers against the run: int overflow, N = 2^30, 1-particle
    // frames, 2^24 chunks, NaN positions.
    chunk(lcm, run, 1, 300, 0, 3, 0x7fffff00, 128, 256, 256, 1.0);
    chunk(lcm, run, 1, 1 << 30, 0, 1, 0, 2, 4, 4, 1.0);
    chunk(lcm, run, 2, 1, 0, 1, 0, 1, 2, 2, 1.0);
    chunk(lcm, run, 3, 300, 5, 1 << 24, 640, 2, 4, 4, 1.0);
    chunk(lcm, run, 4, 300, 0, 3, 0, 128, 256, 256, nan);
    // Run info of this run with indices out of range.
    dynhet::run_info_t bad = bad_run_info(run);
    send(lcm, "DYNHET_RUN", &bad);
    // Another run: its run info, a chunk and a "done".
    dynhet::run_info_t other = bad_run_info(run + 1);
    other.origin_frame = {0};
    other.pair_frame = {1, 2};
    send(lcm, "DYNHET_RUN", &other);
    chunk(lcm, run + 1, 0, 300, 0, 3, 0, 128, 256, 256, 1.0);
    dynhet::sim_status_t done{};
    done.run_id = run + 1;
    done.phase = "done";
    send(lcm, "DYNHET_SIM_STATUS", &done);
    if (forge_done) {
      // This run's "done", saying every frame (or a negative count) is out:
      // nodes must neither end early nor give up frames still coming.
      done.run_id = run;
      done.frames_published = rounds % 2 ? INT32_MAX : -7;
      send(lcm, "DYNHET_SIM_STATUS", &done);
    }
    if (!g_signer) // statuses of this run, far ahead: no key, so they must not pace the sim
      for (const char* p : {"overlap", "s4", "clusters", "recorder"}) {
        dynhet::node_status_t st{};
        st.run_id = run;
        st.node = p;
        st.state = "running";
        st.frames_expected = 56;
        st.frames_whole = 1000000;
        send(lcm, std::string("DYNHET_NODE_STATUS_") + p, &st);
      }
    ++rounds;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::printf("hostile_publisher: %ld rounds of %d bad messages\n", rounds, forge_done ? 38 : 37);
  return 0;
}
