// An authenticated bus: only the processes that hold a run's key
// can put messages into it.
//
// LCM has no authentication of its own, and every process on the host (or,
// with --bus lan, on the LAN) can publish on a run's channels with its run
// id, which travels in clear. So each run has a secret, 32 random bytes in a
// file only its owner can read (run_scene.sh creates DIR/bus.key), and every
// message carries a tag after its LCM bytes:
//
//   LCM bytes | "DHT2" | epoch (8 bytes) | sender (8) | sequence (8) | tag (32)
//
// tag = keyed BLAKE2b-256 (libsodium's crypto_generichash) over a domain
// string, the channel's name, the epoch, the sender, the sequence number
// and the LCM bytes, which hold the run id (every dynhet message carries
// it). The epoch is one launch of the run's processes (run_scene.sh draws
// one at each start and resume, --bus-epoch): a receiver takes only its own
// launch's, so a message recorded in an earlier segment of the run cannot
// be replayed into a later one. The sender is 8 random bytes drawn when a
// process starts; its sequence counts that sender's messages on each
// channel from 1 (a stream: one sender, one channel). A receiver checks the
// tag before it decodes anything (in constant time) and drops a message
// with no tag, a wrong tag, another epoch, or a sequence number of its
// stream it has already taken (a window of the last 1024 per stream).
//
// State only moves forward: on a channel that carries state (run info, sim
// and node statuses, checkpoint requests and answers: carries_state) a
// message is taken only if its number is above the last one taken on its
// stream, whatever the window holds, so a genuine message replayed later
// (one this receiver never got: its queue or socket dropped it) cannot
// take a process's state back. A stream's numbers have no holes, so a hole
// is a genuine message lost before the check (a full LCM queue, a full
// socket buffer): counted as lost, never silent.
//
// What it does not stop: processes started by hand without --bus-epoch
// share epoch 0, and one restarted alone draws a new sender that a receiver
// started after it cannot tell from a first copy. Replays (replay.sh) take
// every epoch of the log, which replay.sh checked first.
//
// Tools that only watch (lcm-spy, lcm-logger) see the LCM bytes first and
// ignore the tail.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

namespace dynhet {

class BusKey {
public:
  static constexpr std::size_t kBytes = 32;
  // Reads the key file: a regular file of exactly 32 bytes that neither its
  // group nor others may read or write. Throws std::runtime_error naming
  // the file and what is wrong with it (missing, empty, wrong size, mode).
  static std::shared_ptr<const BusKey> load(const std::string& path);
  // A new random key in path (created, never overwritten; mode 0600;
  // flushed to disk). Throws if path exists or cannot be written.
  static void create(const std::string& path);
  // From bytes (tests).
  explicit BusKey(const std::array<unsigned char, kBytes>& bytes) : key_(bytes) {}
  ~BusKey();
  BusKey(const BusKey&) = delete;
  BusKey& operator=(const BusKey&) = delete;
  const unsigned char* data() const { return key_.data(); }

private:
  std::array<unsigned char, kBytes> key_{};
};

constexpr std::size_t kBusTagBytes = 4 + 8 + 8 + 8 + 32; // what a tag adds to a message

// Whether a channel carries state that must only move forward (run info,
// the sim's and the nodes' statuses, checkpoint requests and answers).
bool carries_state(const std::string& channel);

// Why messages were dropped, counted by every receiver (its status and
// run.h5 carry them in this order, under these names).
enum class BusDrop : int {
  untagged,     // no tag of this bus
  bad_tag,      // a tag not made with the run's key (forged, altered, re-channelled)
  other_launch, // another launch's epoch
  replayed,     // a number of its stream already taken
  stale,        // state older than the last taken from its stream
  lost,         // a hole in a stream: a genuine message that never reached the check
  queue_full,   // authentic, but the receiver's own queue had no room (analysis nodes)
};
constexpr int kBusDropReasons = 7;
const char* bus_drop_name(BusDrop d); // "untagged", "bad_tag", ...

// Reading a message's tail without checking its tag: only for tools that
// look at a log (which nodes a replay needs) or at the bus (tests); what
// takes part in a run checks with BusVerifier.
// The LCM bytes of a message that may carry a tag (all of it if none).
std::size_t lcm_bytes_of(const void* data, std::size_t n);
// The launch epoch a tagged message says it is of; none if untagged.
std::optional<std::uint64_t> bus_epoch_of(const void* data, std::size_t n);

// Tags messages for one process (one sender); thread-safe.
class BusSigner {
public:
  // epoch: this launch's (bus_auth.hpp), carried in every tag.
  BusSigner(std::shared_ptr<const BusKey> key, std::uint64_t epoch);
  // Writes the tag of message[0, n) (the LCM encoding) at message + n:
  // message must hold n + kBusTagBytes bytes.
  void tag(const std::string& channel, std::uint8_t* message, std::size_t n);
  std::uint64_t sender() const { return sender_; }

private:
  std::shared_ptr<const BusKey> key_;
  std::uint64_t epoch_, sender_;
  std::mutex mutex_;
  std::unordered_map<std::string, std::uint64_t> sequence_; // per channel
};

// Checks the tags of messages received on one process's subscriptions;
// thread-safe.
class BusVerifier {
public:
  enum class Verdict { ok, untagged, bad_tag, other_epoch, replayed, stale };
  // epoch: the only one taken; any_epoch: every epoch (a replay of a
  // recorded log, checked as a whole first).
  BusVerifier(std::shared_ptr<const BusKey> key, std::uint64_t epoch, bool any_epoch = false);
  // ok: the message is genuine and new; its LCM bytes are the first
  // `payload` bytes. Anything else: drop it (what() says why).
  Verdict verify(const std::string& channel, const void* data, std::size_t n, std::size_t& payload);
  static const char* what(Verdict v);
  // Which launch's messages are taken from now on (the recorder replaying
  // its journal takes each stretch with the epoch it was received under).
  void set_epoch(std::uint64_t epoch, bool any_epoch);
  static constexpr std::uint64_t kWindow = 1024;
  // Every message dropped so far, by reason (lost: holes in the streams
  // not filled since; queue_full is the caller's to count: count_drop).
  std::array<std::int64_t, kBusDropReasons> drops() const;
  void count_drop(BusDrop d);

private:
  struct Window {
    std::uint64_t top = 0;                      // highest sequence taken
    std::uint64_t first = 0;                    // the first heard (numbers below it are no holes)
    std::array<std::uint64_t, kWindow / 64> seen{}; // bit (s % kWindow): s taken, for s in (top - kWindow, top]
  };
  Verdict take(std::uint64_t sender, const std::string& channel, std::uint64_t sequence);
  Verdict counted(Verdict v);
  std::shared_ptr<const BusKey> key_;
  std::uint64_t epoch_;
  bool any_epoch_;
  mutable std::mutex mutex_;
  std::unordered_map<std::string, Window> windows_; // by stream: sender's 8 bytes, then the channel
  std::array<std::int64_t, kBusDropReasons> drops_{};
};

} // namespace dynhet
