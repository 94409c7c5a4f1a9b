// Re-analysis scenes (dynhet/reanalysis.hpp): the analysis keys of a file
// replace the recorded ones, what decided the frames is refused by name,
// and the original settings give back the recorded text byte for byte.
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "dynhet/reanalysis.hpp"
#include "dynhet/scene.hpp"

using dynhet::parse_scene_text;
using dynhet::reanalysis_scene_text;
using dynhet::SceneError;

namespace {

const std::string kRecorded = R"(# recorded
[system]
n_particles = 300
packing_fraction = 0.6
seed = 7

[schedule]
origins = 4
origin_spacing = 1.0
lag_min = 0.05
lag_max = 10.0
lags_per_decade = 5

[observables]
compute = ["overlap", "chi4"]
cutoff_a = [0.6, 1.0]
keep_frames = true

[chi4]
subbox_particles = [10, 40, 300]
)";

std::string error_of(const std::string& analysis) {
  try {
    reanalysis_scene_text(kRecorded, analysis, "analysis.toml");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

} // namespace

TEST(Reanalysis, OriginalSettingsGiveTheRecordedTextBack) {
  EXPECT_EQ(reanalysis_scene_text(kRecorded, "", "analysis.toml"), kRecorded);
  EXPECT_EQ(reanalysis_scene_text(kRecorded, "[observables]\ncutoff_a = [0.6, 1.0]\n[chi4]\nsubbox_particles = [10, 40, 300]\n",
                                  "analysis.toml"),
            kRecorded);
}

TEST(Reanalysis, AnalysisKeysReplaceTheRecordedOnes) {
  const std::string text = reanalysis_scene_text(
      kRecorded, "[observables]\ncutoff_a = [0.6, 0.8]\ncage_relative = true\n[overlap]\nsubbox_particles = 50\n",
      "analysis.toml");
  const dynhet::Scene s = parse_scene_text(text, "merged");
  ASSERT_EQ(s.cutoff_a.size(), 2u);
  EXPECT_EQ(s.cutoff_a[0], 0.6);
  EXPECT_EQ(s.cutoff_a[1], 0.8);
  EXPECT_TRUE(s.cage_relative);
  EXPECT_EQ(s.overlap_subbox_particles, 50);
  // Everything else as recorded, to the bit.
  const dynhet::Scene r = parse_scene_text(kRecorded, "recorded");
  EXPECT_EQ(s.n_particles, r.n_particles);
  EXPECT_EQ(s.packing_fraction, r.packing_fraction);
  EXPECT_EQ(s.seed, r.seed);
  EXPECT_EQ(s.schedule.lag_min, r.schedule.lag_min);
  EXPECT_EQ(s.schedule.origin_spacing, r.schedule.origin_spacing);
  EXPECT_EQ(s.keep_frames, r.keep_frames);
  EXPECT_EQ(s.observables, r.observables);
  EXPECT_EQ(s.chi4_subbox_particles, r.chi4_subbox_particles);
}

TEST(Reanalysis, WhatDecidedTheFramesIsRefusedByName) {
  const std::pair<const char*, const char*> cases[] = {
      {"[system]\nn_particles = 400\n", "system.n_particles"},  {"[schedule]\nlag_max = 20.0\n", "schedule.lag_max"},
      {"[observables]\nkeep_frames = false\n", "observables.keep_frames"},
      {"[driving]\nkick_rate = 1.0\n", "driving.kick_rate"}, {"[run]\nequilibration_time = 1.0\n", "run.equilibration_time"},
      {"[transport]\nchunk_particles = 64\n", "transport.chunk_particles"}};
  for (const auto& [analysis, key] : cases) {
    const std::string err = error_of(analysis);
    EXPECT_NE(err.find(std::string("refused: ") + key), std::string::npos) << analysis << " -> " << err;
  }
  // Every refused key is named, the allowed ones not.
  const std::string err = error_of("[observables]\ncutoff_a = [0.5]\n[system]\nn_particles = 400\nseed = 8\n");
  EXPECT_NE(err.find("system.n_particles, system.seed"), std::string::npos) << err;
  EXPECT_EQ(err.find("observables.cutoff_a"), std::string::npos) << err;
}

TEST(Reanalysis, TheMergedSceneIsCheckedLikeAnyScene) {
  EXPECT_NE(error_of("[observables]\ncutoff_a = [-1.0]\n").find("observables.cutoff_a"), std::string::npos);
  EXPECT_NE(error_of("[overlap]\nnot_a_key = 1\n").find("overlap.not_a_key"), std::string::npos);
  EXPECT_NE(error_of("[observables]\ncompute = [\"no_such\"]\n").find("known observables"), std::string::npos);
  EXPECT_NE(error_of("not toml [").find("not valid TOML"), std::string::npos);
}
