// Free space on the file system that holds a file: the recorder and the
// sim's checkpoint check it before writing, so that a full disk is named
// (ENOSPC) and never leaves a half-written HDF5 file.
#pragma once

#include <sys/statvfs.h>

#include <cstdint>
#include <string>

namespace dynhet {

// Bytes free for an unprivileged writer on the file system holding `path`
// (-1 if unknown).
inline int64_t free_bytes(const std::string& path) {
  const auto slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "." : slash == 0 ? "/" : path.substr(0, slash);
  struct statvfs v {};
  if (statvfs(dir.c_str(), &v) != 0) return -1;
  return static_cast<int64_t>(v.f_bavail) * static_cast<int64_t>(v.f_frsize);
}

} // namespace dynhet
