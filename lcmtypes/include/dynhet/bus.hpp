// A process's side of the authenticated bus (dynhet/bus_auth.hpp):
// every message it publishes is tagged with the run's key, and every
// message it receives is checked before it is decoded.
#pragma once

#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <cstdlib>
#include <array>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "dynhet/bus_auth.hpp"

namespace dynhet {

class Bus {
public:
  // The key file (--key-file) or, explicitly, none (--unauthenticated):
  // exactly one of them. Throws std::runtime_error with a message for the
  // user (the program's name first) otherwise, and on a bad key file.
  // Without --key-file, $DYNHET_KEY_FILE names the key; --unauthenticated
  // wins over it. epoch (--bus-epoch): this launch's number (run_scene.sh
  // draws one per start and resume), "" for 0, or "any" to take every
  // launch's messages (a replay of a recorded log).
  static Bus from_options(const std::string& program, std::string key_file, bool unauthenticated,
                          const std::string& epoch = "") {
    if (key_file.empty() && !unauthenticated)
      if (const char* env = std::getenv("DYNHET_KEY_FILE"); env && *env) key_file = env;
    if (key_file.empty() && !unauthenticated)
      throw std::runtime_error(program + ": --key-file FILE is required (the run's key: run_scene.sh writes "
                                         "DIR/bus.key; or $DYNHET_KEY_FILE), or --unauthenticated to use an open "
                                         "bus on purpose");
    if (!key_file.empty() && unauthenticated)
      throw std::runtime_error(program + ": --key-file and --unauthenticated exclude each other");
    std::uint64_t e = 0;
    const bool any = epoch == "any";
    if (!epoch.empty() && !any) {
      std::size_t used = 0;
      try {
        e = std::stoull(epoch, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != epoch.size() || epoch[0] == '-')
        throw std::runtime_error(program + ": --bus-epoch is a non-negative integer or \"any\", not \"" + epoch + "\"");
    }
    Bus b;
    if (!key_file.empty()) {
      std::shared_ptr<const BusKey> key;
      try {
        key = BusKey::load(key_file);
      } catch (const std::exception& e) {
        throw std::runtime_error(program + ": " + e.what());
      }
      b.signer_ = std::make_shared<BusSigner>(key, e);
      b.verifier_ = std::make_shared<BusVerifier>(key, e, any);
      b.epoch_ = e, b.any_epoch_ = any;
    }
    return b;
  }
  static Bus open_bus() { return Bus{}; } // unauthenticated (tests, tools)
  explicit Bus(std::shared_ptr<const BusKey> key, std::uint64_t epoch = 0)
      : signer_(std::make_shared<BusSigner>(key, epoch)), verifier_(std::make_shared<BusVerifier>(key, epoch)) {}

  bool authenticated() const { return signer_ != nullptr; }
  std::uint64_t epoch() const { return epoch_; }
  bool any_epoch() const { return any_epoch_; }
  // Takes another launch's messages from now on (the recorder's journal
  // replay: each stretch under the epoch it was received with).
  void take_epoch(std::uint64_t epoch, bool any) const {
    if (verifier_) verifier_->set_epoch(epoch, any);
  }
  const char* describe() const { return authenticated() ? "authenticated (the run's key)" : "UNAUTHENTICATED"; }

  // Encodes m, tags it and publishes it; LCM's result (0: sent), -1 if m
  // does not encode.
  template <class M> int publish(lcm::LCM& lcm, const std::string& channel, const M& m) const {
    if (!signer_) return lcm.publish(channel, &m);
    const int n = m.getEncodedSize();
    if (n < 0) return -1;
    thread_local std::vector<std::uint8_t> buf;
    buf.resize(static_cast<std::size_t>(n) + kBusTagBytes);
    if (m.encode(buf.data(), 0, n) != n) return -1;
    // Numbered and sent in one step: a stream's messages leave in the order
    // of their numbers (receivers take state only forward), whichever
    // threads publish.
    std::lock_guard<std::mutex> lock(*publishing_);
    signer_->tag(channel, buf.data(), static_cast<std::size_t>(n));
    return lcm.publish(channel, buf.data(), static_cast<unsigned int>(buf.size()));
  }

  // Messages this process's receivers dropped, by reason (BusDrop), and
  // one more counted by the caller (a queue of its own full). Zeros on an
  // unauthenticated bus.
  std::array<std::int64_t, kBusDropReasons> drops() const {
    return verifier_ ? verifier_->drops() : std::array<std::int64_t, kBusDropReasons>{};
  }
  void count_drop(BusDrop d) const {
    if (verifier_) verifier_->count_drop(d);
  }

  // The LCM bytes of a received message: true, with their length in size;
  // false, with why, if it must be dropped (no tag, a wrong one, a replay).
  // On an unauthenticated bus every message is taken as it is.
  bool open(const std::string& channel, const void* data, std::size_t n, int& size, std::string& why) const {
    if (!verifier_) {
      size = static_cast<int>(n);
      return true;
    }
    std::size_t payload = 0;
    const BusVerifier::Verdict v = verifier_->verify(channel, data, n, payload);
    if (v != BusVerifier::Verdict::ok) {
      why = BusVerifier::what(v);
      return false;
    }
    size = static_cast<int>(payload);
    return true;
  }

private:
  Bus() = default;
  std::shared_ptr<BusSigner> signer_;
  std::shared_ptr<BusVerifier> verifier_;
  std::shared_ptr<std::mutex> publishing_ = std::make_shared<std::mutex>();
  std::uint64_t epoch_ = 0;
  bool any_epoch_ = false;
};

} // namespace dynhet
