// A process's part of a checkpoint cut, as bytes: StateOut writes values,
// StateIn reads them back in the same order with every length checked, and
// write_part / read_part put them in a file with a header (what process,
// which run, which cut, which build, which scene) and a CRC-32, written to
// a temporary name, fsync'd and renamed, so that a part on disk is whole or
// absent. A class saves its state with one template that both archives
// call, so that saving and loading cannot drift apart:
//
//   template <class Ar> void state(Ar& ar) { ar(q_, var_); }
//
// Values: arithmetic types, std::string, std::vector, std::map, std::array,
// std::optional, and any class with such a state(Ar&) member.
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace dynhet {

// Raised for a part that cannot be used: truncated, corrupt, another
// build's, another run's or scene's. The message names the file.
struct BadPart : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class StateOut {
public:
  template <class... T> void operator()(T&... v) { (put(v), ...); }
  const std::vector<uint8_t>& bytes() const { return buf_; }
  void reserve(size_t n) { buf_.reserve(n); }
  void raw(const void* p, size_t n) {
    const auto* b = static_cast<const uint8_t*>(p);
    buf_.insert(buf_.end(), b, b + n);
  }

private:
  template <class T> void put(T& v) {
    if constexpr (std::is_arithmetic_v<T> || std::is_enum_v<T>) {
      raw(&v, sizeof v);
    } else {
      v.state(*this);
    }
  }
  void put(std::string& s) {
    uint64_t n = s.size();
    raw(&n, 8);
    raw(s.data(), n);
  }
  template <class T> void put(std::vector<T>& v) {
    uint64_t n = v.size();
    raw(&n, 8);
    if constexpr (std::is_arithmetic_v<T>) {
      if (n) raw(v.data(), n * sizeof(T));
    } else {
      for (auto& x : v) put(x);
    }
  }
  void put(std::vector<bool>&) = delete;
  template <class T, size_t N> void put(std::array<T, N>& a) {
    for (auto& x : a) put(x);
  }
  template <class T, size_t N> void put(T (&a)[N]) {
    for (auto& x : a) put(x);
  }
  template <class K, class V> void put(std::map<K, V>& m) {
    uint64_t n = m.size();
    raw(&n, 8);
    for (auto& [k, v] : m) {
      K key = k;
      put(key);
      put(v);
    }
  }
  template <class T> void put(std::optional<T>& o) {
    uint8_t has = o.has_value();
    raw(&has, 1);
    if (has) put(*o);
  }
  std::vector<uint8_t> buf_;
};

class StateIn {
public:
  // `what` names the source in errors (the file).
  StateIn(const uint8_t* p, size_t n, std::string what) : begin_(p), p_(p), end_(p + n), what_(std::move(what)) {}
  template <class... T> void operator()(T&... v) { (get(v), ...); }
  bool at_end() const { return p_ == end_; }
  size_t offset() const { return static_cast<size_t>(p_ - begin_); }
  const std::string& what() const { return what_; }
  void raw(void* out, size_t n) {
    if (static_cast<size_t>(end_ - p_) < n) throw BadPart(what_ + ": truncated (the state ends early)");
    std::memcpy(out, p_, n);
    p_ += n;
  }

private:
  uint64_t length(size_t element) {
    uint64_t n = 0;
    raw(&n, 8);
    if (element && n > static_cast<uint64_t>(end_ - p_) / element)
      throw BadPart(what_ + ": a length of " + std::to_string(n) + " beyond the end of the state");
    return n;
  }
  template <class T> void get(T& v) {
    if constexpr (std::is_arithmetic_v<T> || std::is_enum_v<T>) {
      raw(&v, sizeof v);
    } else {
      v.state(*this);
    }
  }
  void get(std::string& s) {
    s.resize(length(1));
    raw(s.data(), s.size());
  }
  template <class T> void get(std::vector<T>& v) {
    // Every element takes at least one byte: no length can allocate more
    // than the state holds. Objects without a default constructor (the
    // accumulators a node made for its run) must be there already.
    const uint64_t n = length(std::is_arithmetic_v<T> ? sizeof(T) : 1);
    if constexpr (std::is_default_constructible_v<T>) {
      v.resize(n);
    } else if (v.size() != n) {
      throw BadPart(what_ + ": " + std::to_string(n) + " accumulators saved, " + std::to_string(v.size()) +
                    " in this run");
    }
    if constexpr (std::is_arithmetic_v<T>) {
      if (!v.empty()) raw(v.data(), v.size() * sizeof(T));
    } else {
      for (auto& x : v) get(x);
    }
  }
  template <class T, size_t N> void get(std::array<T, N>& a) {
    for (auto& x : a) get(x);
  }
  template <class T, size_t N> void get(T (&a)[N]) {
    for (auto& x : a) get(x);
  }
  template <class K, class V> void get(std::map<K, V>& m) {
    m.clear();
    const uint64_t n = length(1);
    for (uint64_t i = 0; i < n; ++i) {
      K k{};
      get(k);
      get(m[k]);
    }
  }
  template <class T> void get(std::optional<T>& o) {
    uint8_t has = 0;
    raw(&has, 1);
    if (has) {
      o.emplace();
      get(*o);
    } else {
      o.reset();
    }
  }
  const uint8_t* begin_;
  const uint8_t* p_;
  const uint8_t* end_;
  std::string what_;
};

// What a part file says of itself, checked on reading.
struct PartHeader {
  std::string process;   // "sim", "overlap", ..., "recorder"
  int64_t run_id = 0;
  int32_t cut = -1;      // the cut's sequence number in the run
  int32_t frame = -1;    // the last frame folded in (-1: none)
  uint64_t scene_hash = 0;
  std::string build;     // build_id() of the writer
  uint32_t crc = 0;      // of the payload
};

// This build's identity: version, commit and a hash of uncommitted changes
// (generated at build time); a part from another build is refused.
const std::string& build_id();
// FNV-1a of the scene text: a part of another scene is refused.
uint64_t scene_hash(const std::string& scene_toml);
uint32_t crc32_of(const uint8_t* p, size_t n);

// Writes `path` atomically: path.tmp, fsync, rename, fsync of the folder.
// Throws std::runtime_error naming the file (a full disk among the causes);
// the temporary file is removed then.
void write_file_atomic(const std::string& path, const std::vector<uint8_t>& bytes);
// The header (crc filled in here) and payload in one file.
void write_part(const std::string& path, PartHeader h, const std::vector<uint8_t>& payload);
// Reads and checks a part: whole, CRC right, this build's, the expected
// process, run and scene (run_id 0: any). Throws BadPart naming the file.
std::vector<uint8_t> read_part(const std::string& path, const std::string& process, int64_t run_id,
                               uint64_t scene, PartHeader* header = nullptr);
// The same checks as read_part(), the payload not kept (a cut marked
// whole: every part read back).
void check_part(const std::string& path, const std::string& process, int64_t run_id, uint64_t scene,
                PartHeader* header = nullptr);
// The header only (no payload check beyond its length, from the file's
// size; the payload is not read): for listings.
PartHeader read_part_header(const std::string& path);

} // namespace dynhet
