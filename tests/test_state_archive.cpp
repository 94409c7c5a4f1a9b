// Checkpoint parts (dynhet/state_archive.hpp, dynhet/cut.hpp): values come
// back bit for bit, an accumulator restored from its part goes on exactly as
// the one that was never saved, and a part that is truncated, corrupt, or of
// another process, run or scene is refused with its file named; the newest
// usable whole cut is found and a damaged one is passed over.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <tuple>
#include <unistd.h>
#include <cstring>

#include "dynhet/analysis/chi4.hpp"
#include "dynhet/analysis/overlap.hpp"
#include "dynhet/cut.hpp"
#include "dynhet/state_archive.hpp"

namespace {

using dynhet::BadPart;
using dynhet::StateIn;
using dynhet::StateOut;
namespace fs = std::filesystem;

struct Tmp {
  fs::path dir = fs::temp_directory_path() / ("dynhet_archive_" + std::to_string(::getpid()) + "_" +
                                              ::testing::UnitTest::GetInstance()->current_test_info()->name());
  Tmp() { fs::create_directories(dir); }
  ~Tmp() { fs::remove_all(dir); }
};

struct Thing {
  explicit Thing(int n) : v(n, 0.0) {} // no default constructor: restored in place
  std::vector<double> v;
  std::string name;
  template <class Ar> void state(Ar& ar) { ar(v, name); }
};

TEST(StateArchive, ValuesComeBackBitForBit) {
  std::vector<double> d{1.0, -0.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                        std::nextafter(1.0, 2.0)};
  std::map<int, std::vector<double>> held{{3, {1, 2}}, {7, {}}};
  std::optional<std::array<double, 3>> cut = std::array<double, 3>{2.5, 3.5, 4.5};
  std::optional<int> none;
  std::vector<Thing> things{Thing(2), Thing(3)};
  things[1].v[2] = 0.1, things[1].name = "a0.6";
  uint64_t rng[4] = {1, 2, 3, ~0ull};
  StateOut out;
  out(d, held, cut, none, things, rng);

  std::vector<double> d2;
  std::map<int, std::vector<double>> held2{{99, {9}}};
  std::optional<std::array<double, 3>> cut2;
  std::optional<int> none2 = 5;
  std::vector<Thing> things2{Thing(0), Thing(0)};
  uint64_t rng2[4] = {};
  StateIn in(out.bytes().data(), out.bytes().size(), "test");
  in(d2, held2, cut2, none2, things2, rng2);
  EXPECT_TRUE(in.at_end());
  ASSERT_EQ(d2.size(), d.size());
  EXPECT_EQ(0, std::memcmp(d.data(), d2.data(), d.size() * sizeof(double))); // NaN and -0 too
  EXPECT_EQ(held2, held);
  ASSERT_TRUE(cut2.has_value());
  EXPECT_EQ(*cut2, *cut);
  EXPECT_FALSE(none2.has_value());
  EXPECT_EQ(things2[1].v, things[1].v);
  EXPECT_EQ(things2[1].name, "a0.6");
  EXPECT_EQ(0, std::memcmp(rng, rng2, sizeof rng));
}

TEST(StateArchive, ATruncatedOrHugeLengthIsRefusedNotAllocated) {
  std::vector<double> v(100, 1.0);
  StateOut out;
  out(v);
  std::vector<double> back;
  StateIn cut_short(out.bytes().data(), out.bytes().size() - 8, "part.bin");
  EXPECT_THROW(cut_short(back), BadPart);
  // A length field of 2^60 elements: refused before any allocation.
  std::vector<uint8_t> bytes = out.bytes();
  const uint64_t huge = uint64_t{1} << 60;
  std::memcpy(bytes.data(), &huge, 8);
  StateIn in(bytes.data(), bytes.size(), "part.bin");
  try {
    in(back);
    FAIL() << "a length beyond the state was taken";
  } catch (const BadPart& e) {
    EXPECT_NE(std::string(e.what()).find("part.bin"), std::string::npos);
  }
  // Accumulators made for the run must match the saved count.
  std::vector<Thing> two{Thing(1), Thing(1)}, three{Thing(1), Thing(1), Thing(1)};
  StateOut o2;
  o2(two);
  StateIn i2(o2.bytes().data(), o2.bytes().size(), "p");
  EXPECT_THROW(i2(three), BadPart);
}

// An accumulator saved half-way and restored into a fresh one goes on to
// the same result, bit for bit, as the one that was never saved.
TEST(StateArchive, RestoredAccumulatorsGoOnExactly) {
  const std::vector<double> lags{0.1, 0.3, 1.0, 3.0};
  const int origins = 6, boxes = 16;
  const dynhet::analysis::SubboxGrid grid{4, 20.0, 50.0};
  dynhet::analysis::OverlapAccumulator q(origins, lags, 1.0), q_restored(origins, lags, 1.0);
  dynhet::analysis::Chi4Accumulator c(origins, lags, grid, 1.0), c_restored(origins, lags, grid, 1.0);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<std::tuple<int, int, std::vector<double>>> pairs;
  for (int k = 0; k < origins; ++k)
    for (int j = 0; j < 4; ++j) {
      std::vector<double> qr(boxes);
      for (double& x : qr) x = u(rng);
      pairs.emplace_back(k, j, qr);
    }
  auto feed = [&](auto& qa, auto& ca, size_t from, size_t to) {
    for (size_t p = from; p < to; ++p) {
      const auto& [k, j, qr] = pairs[p];
      qa.add(k, j, qr.data(), boxes);
      double s1 = 0, s2 = 0;
      for (double x : qr) s1 += x, s2 += x * x;
      ca.add(k, j, s1, s2);
    }
  };
  const size_t half = pairs.size() / 2;
  feed(q, c, 0, half);
  StateOut out;
  out(q, c);
  StateIn in(out.bytes().data(), out.bytes().size(), "part");
  in(q_restored, c_restored);
  feed(q, c, half, pairs.size());
  feed(q_restored, c_restored, half, pairs.size());
  const auto a = q.result(), b = q_restored.result();
  EXPECT_EQ(0, std::memcmp(a.q.data(), b.q.data(), a.q.size() * sizeof(double)));
  EXPECT_EQ(std::memcmp(&a.tau_alpha, &b.tau_alpha, sizeof(double)), 0);
  const auto ca = c.result(), cb = c_restored.result();
  EXPECT_EQ(0, std::memcmp(ca.chi4.data(), cb.chi4.data(), ca.chi4.size() * sizeof(double)));
  EXPECT_EQ(std::memcmp(&ca.chi4_peak, &cb.chi4_peak, sizeof(double)), 0);
}

dynhet::PartHeader header(const std::string& process, int cut, int frame) {
  dynhet::PartHeader h;
  h.process = process, h.run_id = 42, h.cut = cut, h.frame = frame, h.scene_hash = dynhet::scene_hash("scene");
  return h;
}

TEST(StateArchive, APartIsRefusedWhenTruncatedCorruptOrAnothers) {
  Tmp t;
  const std::string path = (t.dir / "overlap.part").string();
  // (over 4 MiB: check_part reads the state in pieces of that size, and
  // read_part_header the first 64 KiB)
  std::vector<uint8_t> payload(5000000);
  for (size_t i = 0; i < payload.size(); ++i) payload[i] = static_cast<uint8_t>(i * 7);
  dynhet::write_part(path, header("overlap", 3, 17), payload);
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  dynhet::PartHeader h;
  EXPECT_EQ(dynhet::read_part(path, "overlap", 42, dynhet::scene_hash("scene"), &h), payload);
  EXPECT_EQ(h.cut, 3);
  EXPECT_EQ(h.frame, 17);
  dynhet::PartHeader hc;
  dynhet::check_part(path, "overlap", 42, dynhet::scene_hash("scene"), &hc);
  EXPECT_EQ(hc.crc, h.crc);
  EXPECT_EQ(dynhet::read_part_header(path).frame, 17);
  // read_part and check_part refuse alike, naming the file and why.
  auto refused = [&](const std::string& process, int64_t run, const std::string& scene, const std::string& why) {
    for (const bool check : {false, true}) {
      try {
        if (check) dynhet::check_part(path, process, run, dynhet::scene_hash(scene));
        else dynhet::read_part(path, process, run, dynhet::scene_hash(scene));
        ADD_FAILURE() << "not refused: " << why;
      } catch (const BadPart& e) {
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
      }
    }
  };
  refused("s4", 42, "scene", "not of s4");
  refused("overlap", 43, "scene", "not 43");
  refused("overlap", 42, "another scene", "of another scene");
  // One byte flipped in the state.
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(-10, std::ios::end);
    f.put('\x5a');
  }
  refused("overlap", 42, "scene", "corrupt");
  // Cut short: the header alone says so too.
  fs::resize_file(path, fs::file_size(path) - 100);
  refused("overlap", 42, "scene", "truncated");
  EXPECT_THROW(dynhet::read_part_header(path), BadPart);
}

TEST(Cuts, TheNewestWholeCutIsUsedAndADamagedOneIsPassedOver) {
  Tmp t;
  const std::string root = t.dir.string();
  const uint64_t scene = dynhet::scene_hash("scene");
  const std::vector<std::string> parts{"sim", "overlap", "recorder"};
  auto write_cut = [&](int cut, int frame, bool all) {
    fs::create_directories(dynhet::cut_dir(root, cut));
    fs::create_directories(root + "/frames");
    for (const auto& p : parts)
      if (all || p != "recorder")
        dynhet::write_part(dynhet::part_path(root, cut, p, frame), header(p, cut, frame), {1, 2, 3});
    dynhet::CutInfo c;
    c.cut = cut, c.frame = frame, c.run_id = 42, c.parts = parts, c.sim_time = 1.5 * cut;
    return dynhet::mark_cut_whole(root, c, scene);
  };
  EXPECT_TRUE(write_cut(0, 4, true).empty());
  EXPECT_TRUE(write_cut(1, 9, true).empty());
  const auto bad = write_cut(2, 12, false); // the recorder's part is missing: never whole
  ASSERT_EQ(bad.size(), 1u);
  EXPECT_EQ(bad[0].rfind("recorder: ", 0), 0u) << bad[0];
  EXPECT_FALSE(dynhet::read_cut_marker(root, 2).has_value());
  std::vector<std::string> refused;
  auto c = dynhet::latest_whole_cut(root, scene, refused);
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->cut, 1);
  EXPECT_EQ(c->frame, 9);
  EXPECT_DOUBLE_EQ(c->sim_time, 1.5);
  EXPECT_TRUE(refused.empty());
  // Cut 1's overlap part corrupted: cut 0, and cut 1 named as refused.
  {
    std::fstream f(dynhet::part_path(root, 1, "overlap", 9), std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(-1, std::ios::end);
    f.put('\x77');
  }
  c = dynhet::latest_whole_cut(root, scene, refused);
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->cut, 0);
  ASSERT_EQ(refused.size(), 1u);
  EXPECT_NE(refused[0].find("frames/overlap-10.part: corrupt"), std::string::npos) << refused[0];
  // Another scene's folder: nothing usable.
  refused.clear();
  EXPECT_FALSE(dynhet::latest_whole_cut(root, dynhet::scene_hash("other"), refused).has_value());
  EXPECT_EQ(refused.size(), 2u);
  // Pruning keeps the cuts from the one given on, and the frame parts from its boundary on.
  dynhet::prune_cuts(root, 1, 9);
  EXPECT_EQ(dynhet::list_cuts(root), (std::vector<int>{1, 2}));
  EXPECT_FALSE(fs::exists(dynhet::part_path(root, 0, "overlap", 4)));
  EXPECT_TRUE(fs::exists(dynhet::part_path(root, 1, "overlap", 9)));
  EXPECT_TRUE(fs::exists(dynhet::part_path(root, 2, "overlap", 12)));
}

} // namespace
