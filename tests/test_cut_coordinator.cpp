// The sim's side of checkpoint cuts (sim_node/cut_coordinator.cpp) over a
// real LCM instance (memq://, in process): answers of the processes, parts
// on disk, WHOLE markers.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "cut_coordinator.hpp"
#include "dynhet/bus.hpp"
#include "dynhet/checkpoint_t.hpp"
#include "dynhet/cut.hpp"
#include "dynhet/lcm_url.hpp"
#include "dynhet/state_archive.hpp"

using namespace dynhet;

namespace {

constexpr int64_t kRun = 4242;
const std::string kScene = "[system]\nn_particles = 100\n";

struct Dir {
  std::string path;
  Dir() {
    char t[] = "/tmp/dynhet-cuts-XXXXXX";
    path = mkdtemp(t);
  }
  ~Dir() { std::filesystem::remove_all(path); }
};

// A node's part of the boundary after `frame`, as a node writes it.
void write_node_part(const std::string& dir, int cut, const std::string& who, int frame) {
  PartHeader h;
  h.process = who, h.run_id = kRun, h.cut = cut, h.frame = frame, h.scene_hash = scene_hash(kScene);
  const std::string path = part_path(dir, cut, who, frame);
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  write_part(path, h, std::vector<uint8_t>(64, 7));
}

void answer(lcm::LCM& lcm, const std::string& who, int cut, int frame, const std::string& state) {
  checkpoint_t a{};
  a.run_id = kRun, a.cut = cut, a.frame = frame, a.process = who, a.state = state;
  a.message = state == "failed" ? "frame 9 already folded in, past the cut's 3" : "";
  Bus::open_bus().publish(lcm, checkpoint_answer_channel(who), a);
}

bool whole(const std::string& dir, int cut) { return std::filesystem::exists(cut_dir(dir, cut) + "/WHOLE"); }

// A cut folder, an in-process bus and the sim's coordinator of the parts.
struct Cuts {
  Dir d;
  lcm::LCM lcm{"memq://"};
  CutCoordinator cuts;
  explicit Cuts(std::vector<std::string> parts)
      : cuts(lcm, Bus::open_bus(), d.path, kRun, kScene, std::move(parts)) {}
  int take(int frame) { return cuts.take(frame, 0.5 * frame, std::vector<uint8_t>(32, 1)); }
  // Writes a node's part as the node does; returns its path.
  std::string node_part(int cut, const std::string& who, int frame) {
    write_node_part(d.path, cut, who, frame);
    return part_path(d.path, cut, who, frame);
  }
};

} // namespace

// The sim asks again every second for a cut a slower process has not saved;
// a process already past the boundary may answer that repeat "failed". A
// process that said "saved" has its part on disk: its later "failed" must
// not end the cut (it did, and most cuts of a study's runs failed).
TEST(CutCoordinator, AFailedAfterSavedDoesNotEndTheCut) {
  Cuts f({"sim", "overlap", "s4"});
  ASSERT_TRUE(f.lcm.good());
  const int c = f.take(3);
  ASSERT_EQ(c, 0);
  write_node_part(f.d.path, c, "overlap", 3);
  answer(f.lcm, "overlap", c, 3, "saved");
  f.cuts.poll();
  answer(f.lcm, "overlap", c, 3, "failed"); // to the repeated request
  f.cuts.poll();
  EXPECT_EQ(f.cuts.newest_open(), 0) << "the cut is still open, waiting for s4";
  write_node_part(f.d.path, c, "s4", 3);
  answer(f.lcm, "s4", c, 3, "saved");
  EXPECT_TRUE(f.cuts.wait_whole(c, 5.0));
  EXPECT_EQ(f.cuts.last_whole(), 0);
  EXPECT_TRUE(whole(f.d.path, 0));
  // A process that never said "saved" still fails the cut.
  const int c2 = f.take(5);
  answer(f.lcm, "s4", c2, 5, "failed");
  EXPECT_FALSE(f.cuts.wait_whole(c2, 5.0));
  EXPECT_EQ(f.cuts.last_whole(), 0);
}

// A part written by another build is never read back, so no cut of the run
// can be whole: the coordinator says so once, drops the open cuts and takes
// no more (the sim waited the whole --cut-wait, 300 s, for the last one).
TEST(CutCoordinator, APartFromAnotherBuildTurnsCutsOffAtOnce) {
  Cuts f({"sim", "overlap"});
  ASSERT_TRUE(f.lcm.good());
  const int c = f.take(3);
  const std::string path = f.node_part(c, "overlap", 3);
  // The same part as another build writes it: its build id differs.
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const size_t at = bytes.find(build_id());
  ASSERT_NE(at, std::string::npos);
  char& last = bytes[at + build_id().size() - 1];
  last = last == 'x' ? 'y' : 'x';
  std::ofstream(path, std::ios::binary) << bytes;
  answer(f.lcm, "overlap", c, 3, "saved");
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(f.cuts.wait_whole(c, 30.0));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  EXPECT_NE(f.cuts.broken().find("overlap writes its parts from another build"), std::string::npos) << f.cuts.broken();
  EXPECT_EQ(f.cuts.newest_open(), -1);
  EXPECT_EQ(f.take(5), -1);
  EXPECT_FALSE(whole(f.d.path, 0));
}

// With repeated requests answered "saved", an older cut's last answer can
// come after a newer cut is whole. It must not become the restart point
// (that moved last_whole back, and the pruning then removed its folder).
TEST(CutCoordinator, AnOlderCutCompletedLateDoesNotMoveTheRestartPointBack) {
  Cuts f({"sim", "overlap"});
  ASSERT_TRUE(f.lcm.good());
  const int c5 = f.take(5);
  const int c6 = f.take(6);
  write_node_part(f.d.path, c5, "overlap", 5);
  write_node_part(f.d.path, c6, "overlap", 6);
  answer(f.lcm, "overlap", c6, 6, "saved"); // cut 5's answer was lost
  EXPECT_TRUE(f.cuts.wait_whole(c6, 5.0));
  EXPECT_EQ(f.cuts.last_whole(), c6);
  answer(f.lcm, "overlap", c5, 5, "saved"); // to the repeated request
  f.cuts.poll();
  f.cuts.poll();
  EXPECT_EQ(f.cuts.last_whole(), c6);
  EXPECT_FALSE(whole(f.d.path, c5));
  EXPECT_TRUE(whole(f.d.path, c6));
  EXPECT_EQ(f.cuts.newest_open(), -1);
}

// A part that is read back unusable (here: a byte of its state changed, so
// its CRC fails) while its process keeps answering "saved" fails the cut
// after kUnusableAnswers answers, instead of holding it open to the end.
TEST(CutCoordinator, APartThatStaysUnusableFailsTheCut) {
  Cuts f({"sim", "overlap"});
  ASSERT_TRUE(f.lcm.good());
  const int c = f.take(3);
  const std::string path = f.node_part(c, "overlap", 3);
  {
    std::fstream io(path, std::ios::in | std::ios::out | std::ios::binary);
    io.seekp(-5, std::ios::end);
    io.put('\x55');
  }
  for (int k = 0; k < CutCoordinator::kUnusableAnswers - 1; ++k) {
    answer(f.lcm, "overlap", c, 3, "saved");
    f.cuts.poll();
    EXPECT_EQ(f.cuts.newest_open(), c) << "answer " << k + 1 << ": still open";
  }
  answer(f.lcm, "overlap", c, 3, "saved");
  f.cuts.poll();
  f.cuts.poll();
  EXPECT_EQ(f.cuts.newest_open(), -1);
  EXPECT_EQ(f.cuts.last_whole(), -1);
  EXPECT_FALSE(whole(f.d.path, c));
  EXPECT_TRUE(f.cuts.broken().empty()) << "one bad part fails its cut, not every cut";
}
