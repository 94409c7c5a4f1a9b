// The recorder's journal (docs/checkpoints.md): every message it takes from
// the bus or a log, in order, appended to one file. The recorder's state is
// a function of those messages, so its part of a checkpoint cut is only a
// length of the journal and the CRC-32 of that prefix; resuming replays the
// prefix through the same handlers into a new run.h5 and goes on appending.
// Record: u32 channel length, channel, u32 data length, data.
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>

namespace dynhet {

class Journal {
public:
  Journal() = default;
  ~Journal();
  Journal(const Journal&) = delete;
  Journal& operator=(const Journal&) = delete;

  // A new, empty journal at `path` (an old one is replaced).
  void create(const std::string& path);
  // The journal at `path` cut back to its first `length` bytes, which must
  // have CRC-32 `crc`; each record of that prefix goes to `replay` (in
  // order) before the file is opened for appending. Throws
  // std::runtime_error naming the file if it is shorter or the CRC differs.
  void resume(const std::string& path, uint64_t length, uint32_t crc,
              const std::function<void(const std::string& channel, const uint8_t* data, uint32_t size)>& replay);

  void append(const std::string& channel, const void* data, uint32_t size);
  // Everything appended is on disk (fflush, fsync); throws if not.
  void sync();
  uint64_t length() const { return length_; }
  uint32_t crc() const { return crc_; }
  bool open() const { return file_ != nullptr; }

private:
  void write(const void* p, size_t n);
  std::string path_;
  std::FILE* file_ = nullptr;
  uint64_t length_ = 0;
  uint32_t crc_ = 0;
  bool failed_ = false; // a write failed (disk full): the journal can no longer back a cut
};

} // namespace dynhet
