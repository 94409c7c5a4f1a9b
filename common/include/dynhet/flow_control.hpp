// Flow control, shared by the sim (which paces its frames on the status of
// the nodes and, when the scene keeps frames, of the recorder) and by the
// receivers (which size their in-memory queues on the same window). No LCM.
#pragma once

#include <algorithm>
#include <cstdint>

namespace dynhet {

// The node name the recorder publishes its own status under (only when it
// keeps the frames): the sim paces on it, and the recorder does not count
// it as an analysis node.
inline constexpr const char *kRecorderNode = "recorder";

// Bytes of one frame on the wire: 16 N of positions and a header per chunk.
inline int64_t frame_wire_bytes(int64_t n_particles, int64_t chunk_particles) {
  const int64_t chunks = chunk_particles > 0 ? (n_particles + chunk_particles - 1) / chunk_particles : 1;
  return 16 * n_particles + 128 * std::max<int64_t>(1, chunks);
}

// How many frames the sim lets a paced receiver fall behind: 2 MiB worth
// (half the socket buffer run_scene.sh asks for), at least one frame.
inline int64_t pacing_window_frames(int64_t n_particles) {
  return std::max<int64_t>(1, (int64_t{2} << 20) / (16 * n_particles + 64));
}

// The bytes of frame chunks a node's queue (receive thread -> compute
// thread) may hold: kQueueSafety times what pacing lets pile up (the window
// and the frame in hand), at least kQueueMin, at most `hard_cap`. Beyond it
// chunks are dropped and counted ("queue full").
inline constexpr int64_t kQueueSafety = 4;
inline constexpr int64_t kQueueMin = int64_t{16} << 20;
inline int64_t queue_bound_bytes(int64_t n_particles, int64_t chunk_particles, int64_t hard_cap) {
  const int64_t paced =
      (pacing_window_frames(n_particles) + 1) * frame_wire_bytes(n_particles, chunk_particles);
  return std::min(hard_cap, std::max(kQueueMin, kQueueSafety * paced));
}

// Datagrams the kernel dropped at this process's UDP sockets (their
// receive buffers overflowed), from /proc/net/udp{,6} (this network
// namespace) and /proc/self/fd; -1 if that cannot be read. Counts every
// datagram on the sockets' port, of any channel.
int64_t udp_socket_drops();

// Grows the receive buffer of each of this process's UDP sockets (LCM's
// udpm socket: LCM asks for recv_buf_size, which the kernel caps at
// net.core.rmem_max) to hold at least `bytes`, so that a receiver can hold
// a whole frame while it is off the CPU: SO_RCVBUF, then SO_RCVBUFFORCE
// (root, or CAP_NET_ADMIN) past rmem_max. Never shrinks one. Returns the
// smallest buffer now in place (the kernel's figure, which counts its own
// overhead: about twice what was asked), or -1 if there is no UDP socket.
int64_t grow_udp_receive_buffers(int64_t bytes);

// What a receiver of frames asks for: a whole frame and 1 MiB, at least
// 4 MiB, at most 512 MiB.
inline int64_t frame_receive_buffer_bytes(int64_t n_particles, int64_t chunk_particles) {
  return std::clamp<int64_t>(frame_wire_bytes(n_particles, chunk_particles) + (int64_t{1} << 20),
                             int64_t{4} << 20, int64_t{512} << 20);
}

} // namespace dynhet
