#include "dynhet/state_archive.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <cerrno>
#include <cstdlib>
#include <algorithm>
#include <utility>

namespace dynhet {

extern const char* const kBuildId; // build_id.cpp, generated at build time

const std::string& build_id() {
  static const std::string id = kBuildId;
  return id;
}

uint64_t scene_hash(const std::string& s) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

uint32_t crc32_of(const uint8_t* p, size_t n) {
  uLong c = crc32(0L, Z_NULL, 0);
  while (n > 0) { // zlib takes uInt lengths
    const uInt k = static_cast<uInt>(std::min<size_t>(n, 1u << 30));
    c = crc32(c, p, k);
    p += k, n -= k;
  }
  return static_cast<uint32_t>(c);
}

namespace {

constexpr char kMagic[8] = {'D', 'Y', 'N', 'H', 'E', 'T', 'C', '1'};

std::string folder_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
}

void put_header(StateOut& out, PartHeader& h, uint64_t payload_size) {
  out.raw(kMagic, sizeof kMagic);
  out(h.process, h.run_id, h.cut, h.frame, h.scene_hash, h.build, h.crc, payload_size);
}

} // namespace

namespace {

// `pieces` one after the other into `path` atomically (write_file_atomic).
void write_pieces_atomic(const std::string& path, const std::vector<std::pair<const uint8_t*, size_t>>& pieces) {
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error(tmp + ": cannot create (" + std::strerror(errno) + ")");
  size_t total = 0, done = 0;
  for (const auto& piece : pieces) total += piece.second;
  for (const auto& [data, size] : pieces) {
    size_t at = 0;
    while (at < size) {
      const ssize_t w = ::write(fd, data + at, size - at);
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) {
        const std::string why = w < 0 ? std::strerror(errno) : "nothing written";
        ::close(fd);
        ::unlink(tmp.c_str());
        throw std::runtime_error(tmp + ": write failed after " + std::to_string(done + at) + " of " +
                                 std::to_string(total) + " bytes (" + why + ")");
      }
      at += static_cast<size_t>(w);
    }
    done += size;
  }
  // Tests only: a pause between the bytes and the rename, to kill a process
  // in the middle of writing its part (tests/kill_resume.sh).
  if (const char* d = std::getenv("DYNHET_TEST_PART_WRITE_DELAY")) ::usleep(static_cast<useconds_t>(std::atof(d) * 1e6));
  if (::fsync(fd) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd);
    ::unlink(tmp.c_str());
    throw std::runtime_error(tmp + ": fsync failed (" + why + ")");
  }
  ::close(fd);
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    ::unlink(tmp.c_str());
    throw std::runtime_error(path + ": rename failed (" + why + ")");
  }
  // The rename itself reaches the disk with the folder's entry.
  const int dir = ::open(folder_of(path).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

} // namespace

void write_file_atomic(const std::string& path, const std::vector<uint8_t>& bytes) {
  write_pieces_atomic(path, {{bytes.data(), bytes.size()}});
}

void write_part(const std::string& path, PartHeader h, const std::vector<uint8_t>& payload) {
  h.build = build_id();
  h.crc = crc32_of(payload.data(), payload.size());
  StateOut out;
  put_header(out, h, payload.size());
  // Header and payload straight from where they are (a sim part is 100 MB
  // and more: no copy of it into one buffer).
  write_pieces_atomic(path, {{out.bytes().data(), out.bytes().size()}, {payload.data(), payload.size()}});
}


namespace {

// A part open for reading: its size, and its header parsed from the first
// bytes (a few hundred: the header's strings are a process's name and the
// build id), the payload's length checked against the file's size.
struct OpenPart {
  int fd = -1;
  uint64_t size = 0, payload_at = 0, payload_size = 0;
  PartHeader h;
  OpenPart(const OpenPart&) = delete;
  OpenPart& operator=(const OpenPart&) = delete;
  explicit OpenPart(const std::string& path) {
    fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw BadPart(path + ": cannot be read");
    try {
      parse(path);
    } catch (...) { // a part refused: the destructor does not run for a constructor that threw
      ::close(fd);
      throw;
    }
  }
  // The file's size and its header.
  void parse(const std::string& path) {
    struct stat st {};
    if (::fstat(fd, &st) != 0 || st.st_size < 0) throw BadPart(path + ": cannot be read");
    size = static_cast<uint64_t>(st.st_size);
    for (uint64_t want = std::min<uint64_t>(size, 1 << 16);; want = size) {
      std::vector<uint8_t> b(static_cast<size_t>(want));
      read_at(path, 0, b.data(), b.size());
      if (b.size() < sizeof kMagic || std::memcmp(b.data(), kMagic, sizeof kMagic) != 0)
        throw BadPart(path + ": not a dynhet checkpoint part (no magic number)");
      try {
        StateIn in(b.data() + sizeof kMagic, b.size() - sizeof kMagic, path);
        in(h.process, h.run_id, h.cut, h.frame, h.scene_hash, h.build, h.crc, payload_size);
        payload_at = sizeof kMagic + in.offset();
        break;
      } catch (const BadPart&) {
        if (want == size) throw; // (a header longer than the first bytes, never written here: all of it)
      }
    }
    if (size - payload_at != payload_size)
      throw BadPart(path + ": truncated or padded: " + std::to_string(size - payload_at) + " bytes of state, the "
                    "header says " + std::to_string(payload_size));
  }
  ~OpenPart() {
    if (fd >= 0) ::close(fd);
  }
  void read_at(const std::string& path, uint64_t at, uint8_t* out, size_t n) const {
    while (n > 0) {
      const ssize_t r = ::pread(fd, out, n, static_cast<off_t>(at));
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) throw BadPart(path + ": cannot be read (it ends early)");
      out += r, at += static_cast<uint64_t>(r), n -= static_cast<size_t>(r);
    }
  }
  // The header's claims but the CRC, in the order read_part() checks them.
  void check(const std::string& path, const std::string& process, int64_t run_id, uint64_t scene) const {
    if (h.build != build_id())
      throw BadPart(path + ": written by another build (" + h.build + "; this is " + build_id() + ")");
    if (h.process != process) throw BadPart(path + ": the part of " + h.process + ", not of " + process);
    if (run_id != 0 && h.run_id != run_id)
      throw BadPart(path + ": of run " + std::to_string(h.run_id) + ", not " + std::to_string(run_id));
    if (h.scene_hash != scene) throw BadPart(path + ": of another scene");
  }
};

} // namespace

PartHeader read_part_header(const std::string& path) { return OpenPart(path).h; }

std::vector<uint8_t> read_part(const std::string& path, const std::string& process, int64_t run_id, uint64_t scene,
                               PartHeader* header) {
  const OpenPart f(path);
  std::vector<uint8_t> b(static_cast<size_t>(f.payload_size));
  f.read_at(path, f.payload_at, b.data(), b.size());
  if (crc32_of(b.data(), b.size()) != f.h.crc) throw BadPart(path + ": corrupt (its CRC-32 does not match)");
  f.check(path, process, run_id, scene);
  if (header) *header = f.h;
  return b;
}

void check_part(const std::string& path, const std::string& process, int64_t run_id, uint64_t scene,
                PartHeader* header) {
  const OpenPart f(path);
  // The payload through one small buffer: a sim part (100 MB and more) is
  // read back when its cut is marked whole, and a copy of it in memory
  // took longer than the read.
  std::vector<uint8_t> buf(std::min<uint64_t>(f.payload_size, 1 << 22));
  uLong c = crc32(0L, Z_NULL, 0);
  for (uint64_t at = 0; at < f.payload_size;) {
    const size_t n = static_cast<size_t>(std::min<uint64_t>(buf.size(), f.payload_size - at));
    f.read_at(path, f.payload_at + at, buf.data(), n);
    c = crc32(c, buf.data(), static_cast<uInt>(n));
    at += n;
  }
  if (static_cast<uint32_t>(c) != f.h.crc) throw BadPart(path + ": corrupt (its CRC-32 does not match)");
  f.check(path, process, run_id, scene);
  if (header) *header = f.h;
}

} // namespace dynhet
