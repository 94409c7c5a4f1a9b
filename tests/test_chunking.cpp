// Frames split into chunks and put back together; loss is counted.
#include <gtest/gtest.h>

#include "dynhet/chunking.hpp"

using namespace dynhet;

namespace {
std::vector<double> make_frame(int n, int f) {
  std::vector<double> xy(2 * n);
  for (int i = 0; i < 2 * n; ++i) xy[i] = f * 1000.0 + i * 0.5;
  return xy;
}
// Feeds frame f in chunks to the assembler, skipping chunk `skip`.
std::optional<Frame> feed(FrameAssembler& a, int n, int per, int f, int skip = -1) {
  const auto xy = make_frame(n, f);
  const auto ranges = chunk_ranges(n, per);
  std::optional<Frame> out;
  for (size_t c = 0; c < ranges.size(); ++c) {
    if (static_cast<int>(c) == skip) continue;
    ChunkHeader h{f, 0.25 * f, n, static_cast<int>(c), static_cast<int>(ranges.size()), ranges[c].first, ranges[c].count};
    if (auto fr = a.add(h, xy.data() + 2 * ranges[c].first)) out = fr;
  }
  return out;
}
} // namespace

TEST(Chunking, RangesCoverEveryParticleOnce) {
  const auto r = chunk_ranges(10001, 1000);
  ASSERT_EQ(r.size(), 11u);
  int next = 0;
  for (const auto& c : r) {
    EXPECT_EQ(c.first, next);
    EXPECT_LE(c.count, 1000);
    next += c.count;
  }
  EXPECT_EQ(next, 10001);
}

TEST(Chunking, ReassemblesExactly) {
  FrameAssembler a;
  const auto f = feed(a, 1001, 100, 0);
  ASSERT_TRUE(f.has_value());
  EXPECT_EQ(f->position, make_frame(1001, 0));
  EXPECT_EQ(f->time, 0.0);
  EXPECT_EQ(a.frames_whole(), 1);
  EXPECT_EQ(a.frames_lost(), 0);
}

TEST(Chunking, FrameWithALostChunkIsCountedLost) {
  FrameAssembler a; // reorder window 1
  EXPECT_TRUE(feed(a, 500, 100, 0).has_value());
  EXPECT_FALSE(feed(a, 500, 100, 1, /*skip=*/3).has_value());
  EXPECT_TRUE(feed(a, 500, 100, 2).has_value());
  EXPECT_EQ(a.frames_lost(), 0); // frame 1 could still complete
  EXPECT_TRUE(feed(a, 500, 100, 3).has_value());
  EXPECT_EQ(a.frames_lost(), 1); // now it cannot
  EXPECT_EQ(a.frames_whole(), 3);
  // A straggler of the lost frame changes nothing.
  EXPECT_FALSE(feed(a, 500, 100, 1).has_value());
  EXPECT_EQ(a.frames_whole(), 3);
  a.finish(6); // frames 4 and 5 never arrived at all
  EXPECT_EQ(a.frames_lost(), 3);
}

TEST(Chunking, DuplicatesAndMalformedChunksAreIgnored) {
  FrameAssembler a;
  const auto xy = make_frame(10, 0);
  ChunkHeader h{0, 0.0, 10, 0, 2, 0, 5};
  EXPECT_FALSE(a.add(h, xy.data()).has_value());
  EXPECT_FALSE(a.add(h, xy.data()).has_value()); // duplicate
  ChunkHeader bad{0, 0.0, 10, 1, 2, 8, 5};       // runs past the end
  EXPECT_FALSE(a.add(bad, xy.data()).has_value());
  EXPECT_EQ(a.chunks_malformed(), 1);
  ChunkHeader h2{0, 0.0, 10, 1, 2, 5, 5};
  auto f = a.add(h2, xy.data() + 10);
  ASSERT_TRUE(f.has_value());
  EXPECT_EQ(f->position, xy);
}

// A paced sim sends no later frame while a node still lacks a chunk of the
// last one out: once the sim says that frame is out, it is given up as
// lost (only a frame of which something arrived, only below what the sim
// has published), and the next frames assemble as before.
TEST(Chunking, FrameTheSimHasPublishedIsGivenUpWithoutLaterChunks) {
  FrameAssembler a;
  a.expect(100, 4, 30);
  ASSERT_TRUE(feed(a, 100, 30, 0).has_value());
  EXPECT_FALSE(feed(a, 100, 30, 1, 2).has_value()); // chunk 2 of frame 1 lost
  EXPECT_EQ(a.give_up_before(1), 0);               // the sim says only frame 0 is out
  EXPECT_EQ(a.frames_lost(), 0);
  EXPECT_EQ(a.give_up_before(4), 1);               // frame 1 is out: lost; 2 and 3 never started: untouched
  EXPECT_EQ(a.frames_whole(), 1);
  EXPECT_EQ(a.frames_lost(), 1);
  EXPECT_FALSE(feed(a, 100, 30, 1).has_value()); // its late chunks are ignored
  auto f2 = feed(a, 100, 30, 2);
  ASSERT_TRUE(f2.has_value());
  EXPECT_EQ(f2->position, make_frame(100, 2));
  EXPECT_EQ(a.frames_whole(), 2);
  EXPECT_EQ(a.frames_lost(), 1);
}
