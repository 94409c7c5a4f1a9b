#include "dynhet/flow_control.hpp"

#include <cstdio>
#include <dirent.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <cstdlib>
#include <map>

#include <fstream>
#include <set>
#include <sstream>
#include <string>

namespace dynhet {

namespace {

// This process's sockets ("socket:[123]" links in /proc/self/fd): inode -> fd.
std::map<unsigned long, int> own_sockets() {
  std::map<unsigned long, int> sockets;
  DIR *d = opendir("/proc/self/fd");
  if (!d) return sockets;
  while (const dirent *e = readdir(d)) {
    char link[64] = {};
    const std::string path = std::string("/proc/self/fd/") + e->d_name;
    const ssize_t n = readlink(path.c_str(), link, sizeof link - 1);
    unsigned long inode = 0;
    if (n > 0 && std::sscanf(link, "socket:[%lu]", &inode) == 1) sockets[inode] = std::atoi(e->d_name);
  }
  closedir(d);
  return sockets;
}

std::set<unsigned long> own_socket_inodes() {
  std::set<unsigned long> inodes;
  for (const auto &[inode, fd] : own_sockets()) inodes.insert(inode);
  return inodes;
}

// The inodes listed in a /proc/net/udp table.
void add_udp_inodes(const char *table, std::set<unsigned long> &inodes) {
  std::ifstream in(table);
  std::string line;
  std::getline(in, line); // header
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string skip;
    unsigned long inode = 0;
    for (int i = 0; i < 9; ++i) s >> skip;
    if (s >> inode) inodes.insert(inode);
  }
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

int64_t grow_udp_receive_buffers(int64_t bytes) {
  std::set<unsigned long> udp;
  add_udp_inodes("/proc/net/udp", udp);
  add_udp_inodes("/proc/net/udp6", udp);
  const int want = static_cast<int>(std::min<int64_t>(bytes, INT_MAX / 2));
  int64_t smallest = -1;
  for (const auto &[inode, fd] : own_sockets()) {
    if (!udp.count(inode)) continue;
    int have = 0;
    socklen_t len = sizeof have;
    if (getsockopt(fd, SOL_SOCKET, SO_RCVBUF, &have, &len) != 0) continue;
    if (have / 2 < want) {
      setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &want, sizeof want);
      len = sizeof have;
      getsockopt(fd, SOL_SOCKET, SO_RCVBUF, &have, &len);
      if (have / 2 < want) {
        setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &want, sizeof want); // fails quietly without the capability
        len = sizeof have;
        getsockopt(fd, SOL_SOCKET, SO_RCVBUF, &have, &len);
      }
    }
    smallest = smallest < 0 ? have : std::min<int64_t>(smallest, have);
  }
  return smallest;
}

} // namespace dynhet
