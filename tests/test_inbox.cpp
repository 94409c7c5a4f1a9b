// The queue between a node's receive thread and its compute thread
// (analysis_nodes/inbox.hpp) and the bound it gets from the run
// (dynhet::queue_bound_bytes): order, byte bounds, what is dropped and
// counted, a replay that waits instead, shutdown.
#include <gtest/gtest.h>

#include <thread>

#include "dynhet/flow_control.hpp"
#include "inbox.hpp"

using dynhet::Inbox;
using namespace std::chrono_literals;

namespace {
Inbox::Message msg(const std::string &ch, size_t bytes, uint8_t tag = 0) {
  return Inbox::Message{ch, std::vector<uint8_t>(bytes, tag), 0};
}
constexpr int64_t kOverhead = 64; // Inbox's bookkeeping per message
} // namespace

TEST(Inbox, FirstInFirstOutAndBytesAccounted) {
  Inbox box(1 << 20);
  for (uint8_t i = 0; i < 5; ++i) ASSERT_TRUE(box.push(msg("C", 100, i), true, false));
  EXPECT_EQ(box.stats().queued_bytes, 5 * (100 + 1 + kOverhead));
  for (uint8_t i = 0; i < 5; ++i) {
    auto m = box.pop(10ms);
    ASSERT_TRUE(m);
    EXPECT_EQ(m->data[0], i);
  }
  EXPECT_EQ(box.stats().queued_bytes, 0);
  EXPECT_EQ(box.stats().peak_bytes, 5 * (100 + 1 + kOverhead));
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(box.pop(50ms)); // nothing: a timeout
  EXPECT_GE(std::chrono::steady_clock::now() - t0, 45ms);
  EXPECT_FALSE(box.ended());
}

// Chunks beyond the bound are dropped and counted; other messages (run
// info, sim status) still get in up to the hard cap.
TEST(Inbox, BulkBeyondTheBoundDroppedAndCounted) {
  const int64_t one = 1000 + 1 + kOverhead;
  Inbox box(10 * one);
  box.set_bound(3 * one);
  int taken = 0;
  for (int i = 0; i < 5; ++i) taken += box.push(msg("F", 1000), true, false);
  EXPECT_EQ(taken, 3);
  EXPECT_EQ(box.stats().dropped, 2);
  EXPECT_EQ(box.stats().dropped_bytes, 2 * one);
  EXPECT_EQ(box.stats().bound, 3 * one);
  for (int i = 0; i < 7; ++i) EXPECT_TRUE(box.push(msg("S", 1000), false, false)) << i;
  EXPECT_FALSE(box.push(msg("S", 1000), false, false)); // the hard cap
  EXPECT_EQ(box.stats().dropped, 3);
  box.pop(0ms);
  EXPECT_FALSE(box.push(msg("F", 1000), true, false)); // still above the bound
  EXPECT_TRUE(box.push(msg("S", 1000), false, false));
  // The bound never exceeds the hard cap; one message always fits an empty queue.
  box.set_bound(int64_t{1} << 40);
  EXPECT_EQ(box.stats().bound, 10 * one);
  while (box.pop(0ms)) {
  }
  EXPECT_TRUE(box.push(msg("F", 100000), true, false));
}

// A replay waits for room: every message arrives, in order, within the bound.
TEST(Inbox, WaitingProducerLosesNothing) {
  const int64_t one = 1000 + 1 + kOverhead;
  Inbox box(1 << 20);
  box.set_bound(4 * one);
  constexpr int kN = 2000;
  std::thread producer([&] {
    for (int i = 0; i < kN; ++i) box.push(msg("F", 1000, static_cast<uint8_t>(i)), true, true);
    box.close();
  });
  int got = 0;
  while (auto m = box.pop(1000ms)) {
    ASSERT_EQ(m->data[0], static_cast<uint8_t>(got));
    ++got;
    if (got % 100 == 0) std::this_thread::sleep_for(1ms); // a slow consumer
  }
  producer.join();
  EXPECT_EQ(got, kN);
  EXPECT_TRUE(box.ended());
  EXPECT_EQ(box.stats().dropped, 0);
  EXPECT_LE(box.stats().peak_bytes, 4 * one);
}

TEST(Inbox, StopWakesAWaitingProducer) {
  Inbox box(1 << 20);
  box.set_bound(1);
  ASSERT_TRUE(box.push(msg("F", 10), true, true)); // an empty queue takes one
  bool taken = true;
  std::thread producer([&] { taken = box.push(msg("F", 10), true, true); });
  std::this_thread::sleep_for(50ms);
  box.stop();
  producer.join();
  EXPECT_FALSE(taken);
  EXPECT_EQ(box.stats().dropped, 1);
}

TEST(Inbox, ClosedInputDrainsThenEnds) {
  Inbox box(1 << 20);
  box.push(msg("F", 10), true, false);
  box.close();
  EXPECT_FALSE(box.ended());
  EXPECT_TRUE(box.pop(0ms));
  EXPECT_FALSE(box.pop(1000ms)); // at once, not after the timeout
  EXPECT_TRUE(box.ended());
}

// The bound: a few times what pacing lets pile up (window + the frame in
// hand), at least 16 MiB, at most the hard cap.
TEST(FlowControl, QueueBoundFollowsThePacingWindow) {
  using namespace dynhet;
  EXPECT_EQ(pacing_window_frames(20000), (2 << 20) / (16 * 20000 + 64));
  EXPECT_EQ(pacing_window_frames(1000000), 1);
  const int64_t cap = int64_t{1} << 30;
  EXPECT_EQ(queue_bound_bytes(20000, 8192, cap), kQueueMin); // 4 x 7 frames of 320 KB < 16 MiB
  const int64_t frame = frame_wire_bytes(1000000, 8192);
  EXPECT_EQ(frame, 16000000 + 128 * 123);
  EXPECT_EQ(queue_bound_bytes(1000000, 8192, cap), kQueueSafety * 2 * frame); // about 128 MB
  EXPECT_EQ(queue_bound_bytes(10000000, 65000, cap), cap);
  // Whatever pacing lets pile up fits, with room to spare.
  for (int64_t n : {100, 20000, 200000, 1000000})
    EXPECT_GE(queue_bound_bytes(n, 8192, cap), 2 * (pacing_window_frames(n) + 1) * frame_wire_bytes(n, 8192))
        << n;
}

TEST(FlowControl, SocketDropsOfThisProcessAreReadable) {
  EXPECT_GE(dynhet::udp_socket_drops(), 0); // no UDP socket here: 0, and readable
}
