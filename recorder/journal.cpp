#include "journal.hpp"

#include <unistd.h>
#include <zlib.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace dynhet {

Journal::~Journal() {
  if (file_) std::fclose(file_);
}

void Journal::create(const std::string& path) {
  path_ = path;
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) throw std::runtime_error(path + ": cannot create the journal (" + std::strerror(errno) + ")");
  length_ = 0;
  crc_ = static_cast<uint32_t>(crc32(0L, Z_NULL, 0));
}

void Journal::resume(const std::string& path, uint64_t length, uint32_t crc,
                     const std::function<void(const std::string&, const uint8_t*, uint32_t)>& replay) {
  path_ = path;
  std::FILE* in = std::fopen(path.c_str(), "rb");
  if (!in) throw std::runtime_error(path + ": cannot read the journal (" + std::strerror(errno) + ")");
  std::vector<uint8_t> prefix(length);
  const size_t got = length ? std::fread(prefix.data(), 1, length, in) : 0;
  std::fclose(in);
  if (got != length)
    throw std::runtime_error(path + ": the journal holds " + std::to_string(got) + " bytes, the cut needs " +
                             std::to_string(length));
  uLong c = crc32(0L, Z_NULL, 0);
  for (uint64_t at = 0; at < length;) {
    const uInt k = static_cast<uInt>(std::min<uint64_t>(length - at, 1u << 30));
    c = crc32(c, prefix.data() + at, k);
    at += k;
  }
  if (static_cast<uint32_t>(c) != crc) throw std::runtime_error(path + ": the journal's first " +
                                                                std::to_string(length) + " bytes are corrupt (CRC-32)");
  // The records, checked as they are read: the CRC says they are what was
  // written, and the lengths must still fit.
  for (uint64_t at = 0; at < length;) {
    uint32_t n = 0;
    if (length - at < 4) throw std::runtime_error(path + ": a record is cut short");
    std::memcpy(&n, &prefix[at], 4), at += 4;
    if (length - at < n) throw std::runtime_error(path + ": a record is cut short");
    const std::string channel(reinterpret_cast<const char*>(&prefix[at]), n);
    at += n;
    if (length - at < 4) throw std::runtime_error(path + ": a record is cut short");
    std::memcpy(&n, &prefix[at], 4), at += 4;
    if (length - at < n) throw std::runtime_error(path + ": a record is cut short");
    replay(channel, &prefix[at], n);
    at += n;
  }
  if (::truncate(path.c_str(), static_cast<off_t>(length)) != 0)
    throw std::runtime_error(path + ": cannot cut the journal back (" + std::strerror(errno) + ")");
  file_ = std::fopen(path.c_str(), "ab");
  if (!file_) throw std::runtime_error(path + ": cannot append to the journal (" + std::strerror(errno) + ")");
  length_ = length;
  crc_ = crc;
}

void Journal::write(const void* p, size_t n) {
  if (!file_ || failed_) return;
  if (std::fwrite(p, 1, n, file_) != n) {
    failed_ = true;
    return;
  }
  crc_ = static_cast<uint32_t>(crc32(crc_, static_cast<const Bytef*>(p), static_cast<uInt>(n)));
  length_ += n;
}

void Journal::append(const std::string& channel, const void* data, uint32_t size) {
  const uint32_t nc = static_cast<uint32_t>(channel.size());
  write(&nc, 4);
  write(channel.data(), nc);
  write(&size, 4);
  write(data, size);
}

void Journal::sync() {
  if (!file_) throw std::runtime_error("no journal");
  if (failed_) throw std::runtime_error(path_ + ": a write to the journal failed (disk full?)");
  if (std::fflush(file_) != 0 || ::fsync(fileno(file_)) != 0) {
    failed_ = true;
    throw std::runtime_error(path_ + ": the journal cannot be synced (" + std::strerror(errno) + ")");
  }
}

} // namespace dynhet
