#include "dynhet/state_archive.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <iterator>

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

void write_file_atomic(const std::string& path, const std::vector<uint8_t>& bytes) {
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error(tmp + ": cannot create (" + std::strerror(errno) + ")");
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t w = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      const std::string why = std::strerror(errno);
      ::close(fd);
      ::unlink(tmp.c_str());
      throw std::runtime_error(tmp + ": write failed after " + std::to_string(done) + " of " +
                               std::to_string(bytes.size()) + " bytes (" + why + ")");
    }
    done += static_cast<size_t>(w);
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

void write_part(const std::string& path, PartHeader h, const std::vector<uint8_t>& payload) {
  h.build = build_id();
  h.crc = crc32_of(payload.data(), payload.size());
  StateOut out;
  put_header(out, h, payload.size());
  std::vector<uint8_t> bytes;
  bytes.reserve(out.bytes().size() + payload.size());
  bytes = out.bytes();
  bytes.insert(bytes.end(), payload.begin(), payload.end());
  write_file_atomic(path, bytes);
}

namespace {

// The whole file in one read (a sim part is 200 bytes a particle: 0.8 GB
// at N = 4 x 10^6, which a stream read a byte at a time took seconds over).
std::vector<uint8_t> slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw BadPart(path + ": cannot be read");
  const std::streamoff size = in.tellg();
  if (size < 0) throw BadPart(path + ": cannot be read");
  std::vector<uint8_t> b(static_cast<size_t>(size));
  in.seekg(0);
  if (size > 0 && !in.read(reinterpret_cast<char*>(b.data()), size))
    throw BadPart(path + ": cannot be read");
  return b;
}

// The header, and where the payload starts.
PartHeader parse_header(const std::vector<uint8_t>& b, const std::string& path, size_t& payload_at,
                        uint64_t& payload_size) {
  if (b.size() < sizeof kMagic || std::memcmp(b.data(), kMagic, sizeof kMagic) != 0)
    throw BadPart(path + ": not a dynhet checkpoint part (no magic number)");
  StateIn in(b.data() + sizeof kMagic, b.size() - sizeof kMagic, path);
  PartHeader h;
  in(h.process, h.run_id, h.cut, h.frame, h.scene_hash, h.build, h.crc, payload_size);
  const size_t header_len = sizeof kMagic + in.offset();
  payload_at = header_len;
  if (b.size() - header_len != payload_size)
    throw BadPart(path + ": truncated or padded: " + std::to_string(b.size() - header_len) + " bytes of state, the "
                  "header says " + std::to_string(payload_size));
  return h;
}

} // namespace

PartHeader read_part_header(const std::string& path) {
  const std::vector<uint8_t> b = slurp(path);
  size_t at = 0;
  uint64_t n = 0;
  return parse_header(b, path, at, n);
}

std::vector<uint8_t> read_part(const std::string& path, const std::string& process, int64_t run_id, uint64_t scene,
                               PartHeader* header) {
  std::vector<uint8_t> b = slurp(path);
  size_t at = 0;
  uint64_t n = 0;
  const PartHeader h = parse_header(b, path, at, n);
  if (crc32_of(b.data() + at, n) != h.crc) throw BadPart(path + ": corrupt (its CRC-32 does not match)");
  if (h.build != build_id())
    throw BadPart(path + ": written by another build (" + h.build + "; this is " + build_id() + ")");
  if (h.process != process) throw BadPart(path + ": the part of " + h.process + ", not of " + process);
  if (run_id != 0 && h.run_id != run_id)
    throw BadPart(path + ": of run " + std::to_string(h.run_id) + ", not " + std::to_string(run_id));
  if (h.scene_hash != scene) throw BadPart(path + ": of another scene");
  if (header) *header = h;
  return std::vector<uint8_t>(b.begin() + static_cast<long>(at), b.end());
}

} // namespace dynhet
