// Keys, tags and their checks for the authenticated bus (bus_auth.hpp).
#include "dynhet/bus_auth.hpp"
#include "dynhet/lcm_url.hpp"

#include <sodium.h>

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <stdexcept>
#include <sys/stat.h>
#include <unistd.h>

namespace dynhet {
namespace {

constexpr unsigned char kMagic[4] = {'D', 'H', 'T', '2'};
constexpr std::size_t kHead = 4 + 8 + 8 + 8; // magic, epoch, sender, sequence
constexpr char kDomain[] = "dynhet bus tag v1"; // with its terminating zero

void init_sodium() {
  static const int ok = sodium_init(); // thread-safe, idempotent
  if (ok < 0) throw std::runtime_error("libsodium failed to initialise");
}

void put_u64(unsigned char* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<unsigned char>(v >> (8 * i));
}
std::uint64_t get_u64(const unsigned char* p) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= std::uint64_t{p[i]} << (8 * i);
  return v;
}

// The tag of (channel, head = magic | epoch | sender | sequence, payload).
void compute_tag(const BusKey& key, const std::string& channel, const unsigned char* head, const void* payload,
                 std::size_t n, unsigned char* tag) {
  crypto_generichash_state st;
  crypto_generichash_init(&st, key.data(), BusKey::kBytes, 32);
  crypto_generichash_update(&st, reinterpret_cast<const unsigned char*>(kDomain), sizeof kDomain);
  unsigned char len[8];
  put_u64(len, channel.size());
  crypto_generichash_update(&st, len, sizeof len);
  crypto_generichash_update(&st, reinterpret_cast<const unsigned char*>(channel.data()), channel.size());
  crypto_generichash_update(&st, head, kHead);
  crypto_generichash_update(&st, static_cast<const unsigned char*>(payload), n);
  crypto_generichash_final(&st, tag, 32);
  sodium_memzero(&st, sizeof st);
}

std::string errno_text() { return std::strerror(errno); }

} // namespace

std::size_t lcm_bytes_of(const void* data, std::size_t n) {
  const auto* b = static_cast<const unsigned char*>(data);
  return n >= kBusTagBytes && std::memcmp(b + n - kBusTagBytes, kMagic, 4) == 0 ? n - kBusTagBytes : n;
}

std::optional<std::uint64_t> bus_epoch_of(const void* data, std::size_t n) {
  const auto* b = static_cast<const unsigned char*>(data);
  if (lcm_bytes_of(data, n) == n) return std::nullopt;
  return get_u64(b + n - kBusTagBytes + 4);
}

bool carries_state(const std::string& channel) {
  auto in = [&](const char* family) { // the family's own channel, or one of its sources' (FAMILY_...)
    const std::size_t n = std::strlen(family);
    return channel.compare(0, n, family) == 0 && (channel.size() == n || channel[n] == '_');
  };
  return channel == kChanRun || channel == kChanSimStatus || in(kChanNodeStatus) || in(kChanCheckpoint);
}

const char* bus_drop_name(BusDrop d) {
  switch (d) {
  case BusDrop::untagged: return "untagged";
  case BusDrop::bad_tag: return "bad_tag";
  case BusDrop::other_launch: return "other_launch";
  case BusDrop::replayed: return "replayed";
  case BusDrop::stale: return "stale";
  case BusDrop::lost: return "lost";
  case BusDrop::queue_full: return "queue_full";
  }
  return "?";
}

BusKey::~BusKey() { sodium_memzero(key_.data(), key_.size()); }

std::shared_ptr<const BusKey> BusKey::load(const std::string& path) {
  init_sodium();
  const std::string what = "key file " + path + ": ";
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) throw std::runtime_error(what + "cannot be opened (" + errno_text() + ")");
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat s {};
  if (::fstat(fd, &s) != 0) throw std::runtime_error(what + "cannot be read (" + errno_text() + ")");
  if (!S_ISREG(s.st_mode)) throw std::runtime_error(what + "not a regular file");
  if (s.st_mode & (S_IRWXG | S_IRWXO))
    throw std::runtime_error(what + "readable or writable by others (mode " +
                             std::to_string((s.st_mode >> 6) & 7) + std::to_string((s.st_mode >> 3) & 7) +
                             std::to_string(s.st_mode & 7) + "): the key must be its owner's alone (chmod 600)");
  if (s.st_size == 0) throw std::runtime_error(what + "empty");
  if (s.st_size != static_cast<off_t>(kBytes))
    throw std::runtime_error(what + std::to_string(s.st_size) + " bytes, not " + std::to_string(kBytes) +
                             " (a key is 32 random bytes: run_scene.sh writes one)");
  std::array<unsigned char, kBytes> bytes{};
  std::size_t got = 0;
  while (got < kBytes) {
    const ssize_t r = ::read(fd, bytes.data() + got, kBytes - got);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) throw std::runtime_error(what + "cannot be read (" + (r < 0 ? errno_text() : "short") + ")");
    got += static_cast<std::size_t>(r);
  }
  auto key = std::make_shared<const BusKey>(bytes);
  sodium_memzero(bytes.data(), bytes.size());
  return key;
}

void BusKey::create(const std::string& path) {
  init_sodium();
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0600);
  if (fd < 0) throw std::runtime_error("key file " + path + ": cannot be created (" + errno_text() + ")");
  unsigned char bytes[kBytes];
  randombytes_buf(bytes, kBytes);
  const bool ok = ::fchmod(fd, 0600) == 0 && ::write(fd, bytes, kBytes) == static_cast<ssize_t>(kBytes) &&
                  ::fsync(fd) == 0;
  sodium_memzero(bytes, kBytes);
  const std::string err = errno_text();
  ::close(fd);
  if (!ok) {
    ::unlink(path.c_str());
    throw std::runtime_error("key file " + path + ": cannot be written (" + err + ")");
  }
}

BusSigner::BusSigner(std::shared_ptr<const BusKey> key, std::uint64_t epoch) : key_(std::move(key)), epoch_(epoch) {
  if (!key_) throw std::invalid_argument("BusSigner: no key");
  init_sodium();
  randombytes_buf(&sender_, sizeof sender_);
}

void BusSigner::tag(const std::string& channel, std::uint8_t* message, std::size_t n) {
  std::uint64_t seq;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    seq = ++sequence_[channel];
  }
  unsigned char* head = message + n;
  std::memcpy(head, kMagic, 4);
  put_u64(head + 4, epoch_);
  put_u64(head + 12, sender_);
  put_u64(head + 20, seq);
  compute_tag(*key_, channel, head, message, n, head + kHead);
}

BusVerifier::BusVerifier(std::shared_ptr<const BusKey> key, std::uint64_t epoch, bool any_epoch)
    : key_(std::move(key)), epoch_(epoch), any_epoch_(any_epoch) {
  if (!key_) throw std::invalid_argument("BusVerifier: no key");
  init_sodium();
}

void BusVerifier::set_epoch(std::uint64_t epoch, bool any_epoch) {
  std::lock_guard<std::mutex> lock(mutex_);
  epoch_ = epoch, any_epoch_ = any_epoch;
}

const char* BusVerifier::what(Verdict v) {
  switch (v) {
  case Verdict::ok: return "authentic";
  case Verdict::untagged: return "unauthenticated: no tag of this bus";
  case Verdict::bad_tag: return "unauthenticated: its tag does not match (not signed with this run's key)";
  case Verdict::other_epoch:
    return "unauthenticated: of another launch of the run (a message of an earlier segment, replayed)";
  case Verdict::replayed: return "unauthenticated: a replay (this sender's sequence number was seen before)";
  case Verdict::stale:
    return "unauthenticated: a replay of older state (its sender's later state on this channel was already taken)";
  }
  return "?";
}

BusVerifier::Verdict BusVerifier::verify(const std::string& channel, const void* data, std::size_t n,
                                         std::size_t& payload) {
  payload = 0;
  if (n < kBusTagBytes) return counted(Verdict::untagged);
  const auto* bytes = static_cast<const unsigned char*>(data);
  const std::size_t at = n - kBusTagBytes;
  const unsigned char* head = bytes + at;
  if (std::memcmp(head, kMagic, 4) != 0) return counted(Verdict::untagged);
  unsigned char tag[32];
  compute_tag(*key_, channel, head, bytes, at, tag);
  if (crypto_verify_32(tag, head + kHead) != 0) return counted(Verdict::bad_tag); // constant time
  bool other_epoch;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    other_epoch = !any_epoch_ && get_u64(head + 4) != epoch_;
  }
  if (other_epoch) return counted(Verdict::other_epoch);
  const Verdict v = take(get_u64(head + 12), channel, get_u64(head + 20));
  if (v != Verdict::ok) return counted(v);
  payload = at;
  return Verdict::ok;
}

BusVerifier::Verdict BusVerifier::counted(Verdict v) {
  static constexpr BusDrop kReason[] = {BusDrop::lost, BusDrop::untagged, BusDrop::bad_tag, BusDrop::other_launch,
                                        BusDrop::replayed, BusDrop::stale}; // by Verdict (ok: unused)
  count_drop(kReason[static_cast<int>(v)]);
  return v;
}

void BusVerifier::count_drop(BusDrop d) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++drops_[static_cast<int>(d)];
}

std::array<std::int64_t, kBusDropReasons> BusVerifier::drops() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return drops_;
}

// Takes `seq` of the stream (sender, channel) once: a number above the top
// moves the window (the numbers skipped are holes: lost, until one comes);
// below it, a number in the window not yet taken fills a hole, except on a
// channel that carries state, where only a number above the top is taken.
BusVerifier::Verdict BusVerifier::take(std::uint64_t sender, const std::string& channel, std::uint64_t seq) {
  if (seq == 0) return Verdict::replayed; // sequences count from 1
  std::string stream(8, '\0');
  std::memcpy(stream.data(), &sender, 8);
  stream += channel;
  std::lock_guard<std::mutex> lock(mutex_);
  Window& w = windows_[stream];
  const bool first = w.first == 0;
  if (first) w.first = seq;
  auto bit = [&](std::uint64_t s) -> std::pair<std::uint64_t&, std::uint64_t> {
    return {w.seen[(s % kWindow) / 64], std::uint64_t{1} << (s % 64)};
  };
  auto& lost = drops_[static_cast<int>(BusDrop::lost)];
  if (seq > w.top) {
    // The first message heard of a stream may follow others sent before
    // this receiver listened: those are not holes.
    if (!first) lost += static_cast<std::int64_t>(seq - w.top - 1);
    // Forget what leaves the window: the slots of top+1 .. seq.
    const std::uint64_t steps = seq - w.top;
    if (steps >= kWindow) w.seen.fill(0);
    else
      for (std::uint64_t s = w.top + 1; s <= seq; ++s) {
        auto [word, mask] = bit(s);
        word &= ~mask;
      }
    w.top = seq;
    auto [word, mask] = bit(seq);
    word |= mask;
    return Verdict::ok;
  }
  if (carries_state(channel)) return Verdict::stale;
  if (w.top - seq >= kWindow) return Verdict::replayed; // too old to tell: dropped
  auto [word, mask] = bit(seq);
  if (word & mask) return Verdict::replayed;
  word |= mask;
  if (seq > w.first && lost > 0) --lost; // a hole filled: that message was late, not lost
  return Verdict::ok;
}

} // namespace dynhet
