#include "dynhet/flow_control.hpp"

#include <cstdio>
#include <dirent.h>
#include <unistd.h>

#include <fstream>
#include <set>
#include <sstream>
#include <string>

namespace dynhet {

namespace {

// The inodes of this process's sockets ("socket:[123]" links in /proc/self/fd).
std::set<unsigned long> own_socket_inodes() {
  std::set<unsigned long> inodes;
  DIR *d = opendir("/proc/self/fd");
  if (!d) return inodes;
  while (const dirent *e = readdir(d)) {
    char link[64] = {};
    const std::string path = std::string("/proc/self/fd/") + e->d_name;
    const ssize_t n = readlink(path.c_str(), link, sizeof link - 1);
    unsigned long inode = 0;
    if (n > 0 && std::sscanf(link, "socket:[%lu]", &inode) == 1) inodes.insert(inode);
  }
  closedir(d);
  return inodes;
}

// Adds the drops of the sockets in `inodes` listed in `table`; false if it
// cannot be read. Columns: sl local rem st tx:rx tr:when retrnsmt uid
// timeout inode ref pointer drops.
bool add_drops(const char *table, const std::set<unsigned long> &inodes, int64_t &drops) {
  std::ifstream in(table);
  if (!in) return false;
  std::string line;
  std::getline(in, line); // header
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string sl, local, rem, st, queues, timer, retr, uid, timeout, ref, pointer;
    unsigned long inode = 0;
    int64_t d = 0;
    if (s >> sl >> local >> rem >> st >> queues >> timer >> retr >> uid >> timeout >> inode >> ref >>
            pointer >> d &&
        inodes.count(inode))
      drops += d;
  }
  return true;
}

} // namespace

int64_t udp_socket_drops() {
  const std::set<unsigned long> inodes = own_socket_inodes();
  int64_t drops = 0;
  const bool v4 = add_drops("/proc/net/udp", inodes, drops);
  const bool v6 = add_drops("/proc/net/udp6", inodes, drops);
  return v4 || v6 ? drops : -1;
}

} // namespace dynhet
