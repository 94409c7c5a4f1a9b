// A process's last messages must be delivered before it exits.
//
// udpm (the default bus): lcm_publish is a sendto that has handed the
// datagram to the kernel when it returns; exiting loses nothing.
//
// tcpq (LCM 1.3.1's lcm/lcm_tcpq.c against the hub lcm.lcm.TCPService):
// lcm_publish returns once the bytes are in this process's socket send
// buffer, not once they have left it. They wait there (a) for up to the
// hub's delayed ACK (40 ms): the provider writes a message in five small
// send() calls on a socket without TCP_NODELAY, so Nagle's algorithm holds
// the last small writes back; and (b) for as long as the hub does not read
// us: it reads each client in a thread of its own and relays each message
// to every subscriber synchronously before it reads the next, so one slow
// subscriber holds every publisher back. A plain close (exit) still
// delivers what waits, except when bytes the hub relayed to us lie unread
// in our receive buffer (anything that came after our last lcm_handle):
// Linux then answers the close with a reset and drops whatever we had not
// yet sent. Measured: 1 or 2 of the 5 processes of a tiny run close so
// (the kernel's TCPAbortOnClose counter), all of them when another
// publisher shares the hub; a socket test lost its last bytes in 19 of 20
// such closes under Nagle, 0 of 20 with TCP_NODELAY; tiny runs of an
// earlier version (2ed0120) lost a node's last results in 2 of 5 runs (3 of
// 5 as first reported).
//
// So on tcpq a process ends its connection as TCP intends: it shuts down
// its sending side (the hub reads every byte before the end of the stream),
// then reads and discards what the hub still sends until the hub closes its
// side. TCPService closes only after it has read our end of stream, that is
// after it has read, and relayed to every subscriber, every message we
// published. Then nothing is unread and the close is clean. Bounded: a hub
// stalled by a stopped subscriber may never read us; after `timeout_s` the
// process goes anyway and says so.
#pragma once

#include <cerrno>
#include <chrono>
#include <cstring>
#include <string>

#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <lcm/lcm-cpp.hpp>

namespace dynhet {

inline bool is_tcpq_url(const std::string &url) { return url.rfind("tcpq://", 0) == 0; }

// LCM 1.3.1's tcpq provider says good() when it could not reach the hub,
// and a later handle() on the missing socket aborts (FD_SET of -1).
inline bool bus_unreachable(lcm::LCM &lcm, const std::string &url) {
  return !lcm.good() || (is_tcpq_url(url) && lcm.getFileno() < 0);
}

// The same provider closes its socket when the hub goes away (killed,
// restarted, its host down) and then reports file number -1, on which
// lcm_handle_timeout's select aborts the process ("bit out of range 0 -
// FD_SETSIZE on fd_set"). bus_lost says so; handle_timeout is
// LCM::handleTimeout that returns -1 then instead of aborting.
inline bool bus_lost(lcm::LCM &lcm) { return lcm.getFileno() < 0; }
inline int handle_timeout(lcm::LCM &lcm, int timeout_ms) {
  return bus_lost(lcm) ? -1 : lcm.handleTimeout(timeout_ms);
}
inline constexpr const char *kBusLost =
    "the LCM connection is gone (the tcpq hub closed it: stopped, killed or restarted)";

namespace detail {
// Reads and discards until the peer closes (true) or the deadline passes.
inline std::string drain_until_closed(int fd, double timeout_s) {
  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + std::chrono::duration<double>(timeout_s);
  char scratch[65536];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0)
      return "tcpq: the hub did not take our last messages within " + std::to_string(int(timeout_s)) +
             " s (a stalled subscriber?): they may be lost";
    pollfd p{fd, POLLIN, 0};
    const int r = ::poll(&p, 1, static_cast<int>(left));
    if (r < 0 && errno != EINTR) return std::string("tcpq: poll: ") + std::strerror(errno);
    if (r <= 0) continue;
    const ssize_t n = ::recv(fd, scratch, sizeof scratch, 0);
    if (n == 0) return ""; // the hub has read and relayed everything we sent, and closed
    if (n < 0 && errno != EINTR && errno != EAGAIN)
      return std::string("tcpq: the hub's connection failed: ") + std::strerror(errno);
  }
}
} // namespace detail

// Call after the last publish on `lcm`, once no other thread uses it; then
// only destroy it. Returns "" when everything published was delivered to
// the hub (or the bus needs no wait), else what went wrong.
inline std::string deliver_before_exit(lcm::LCM &lcm, const std::string &url, double timeout_s = 30) {
  if (!is_tcpq_url(url)) return "";
  const int fd = lcm.getFileno();
  if (fd < 0) return "tcpq: not connected to the hub: what was published last may be lost";
  const std::string why = ::shutdown(fd, SHUT_WR) == 0
                              ? detail::drain_until_closed(fd, timeout_s)
                              : std::string("tcpq: shutdown: ") + std::strerror(errno);
  // LCM's destroy unsubscribes every channel by sending on this socket, and
  // on an error reconnects to the hub to do it. Close the finished
  // connection and put one end of a local socket pair in its place (the
  // other end stays open until exit), so those last words go nowhere.
  int pair[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM, 0, pair) == 0) {
    ::dup2(pair[0], fd);
    ::close(pair[0]);
  }
  return why;
}

} // namespace dynhet
