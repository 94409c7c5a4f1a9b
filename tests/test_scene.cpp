// Scene validation: bad input is refused before anything runs, with a
// message naming the key, the value and what is allowed.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "dynhet/model.hpp"
#include "dynhet/scene.hpp"

using dynhet::parse_scene_text;
using dynhet::SceneError;

namespace {

// The error text of parsing `text`, or "" if it parses.
std::string error_of(const std::string& text) {
  try {
    parse_scene_text(text, "test.toml");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

void expect_error(const std::string& text, std::initializer_list<const char*> parts) {
  const std::string err = error_of(text);
  ASSERT_FALSE(err.empty()) << "accepted:\n" << text;
  for (const char* p : parts) EXPECT_NE(err.find(p), std::string::npos) << "'" << p << "' not in: " << err;
}

} // namespace

TEST(Scene, ShippedScenesParse) {
  for (const char* name : {"default.toml", "tiny.toml"}) {
    const auto s = dynhet::parse_scene_file(std::string(DYNHET_SOURCE_DIR) + "/scenes/" + name);
    EXPECT_GT(s.n_particles, 1);
    EXPECT_TRUE(s.wants("overlap"));
    EXPECT_GE(s.production_time, (s.schedule.origins - 1) * s.schedule.origin_spacing + s.schedule.lag_max);
  }
}

TEST(Scene, EmptySceneTakesDefaults) {
  const auto s = parse_scene_text("", "empty");
  EXPECT_EQ(s.n_particles, 1000);
  EXPECT_DOUBLE_EQ(s.radius_ratio, 1.43);
  EXPECT_DOUBLE_EQ(s.cutoff_a.at(0), 0.6);
}

TEST(Scene, DrivingDefaultsToNeighbourPairsAndTheMixtureContactValue) {
  const auto s = parse_scene_text("[system]\npacking_fraction = 0.78\n", "driving");
  EXPECT_EQ(s.kick_pairs, "neighbours");
  EXPECT_DOUBLE_EQ(s.kick_reach, 1.0);
  EXPECT_DOUBLE_EQ(dynhet::scene_contact_value(s), dynhet::mixture_contact_value(0.78, 1.43));
  EXPECT_DOUBLE_EQ(dynhet::scene_kick_rate(s), 2.59 * 0.78 * dynhet::scene_contact_value(s) / std::sqrt(M_PI));
  const auto h = parse_scene_text("[driving]\ncontact_value = \"henderson\"\npairs = \"any\"\nreach = 0.5\n", "h");
  EXPECT_EQ(h.kick_pairs, "any");
  EXPECT_DOUBLE_EQ(h.kick_reach, 0.5);
  EXPECT_DOUBLE_EQ(dynhet::scene_contact_value(h), dynhet::henderson_contact_value(0.7));
  const auto n = parse_scene_text("[driving]\ncontact_value = 3.5\nkick_rate = 2\n", "n");
  EXPECT_DOUBLE_EQ(dynhet::scene_contact_value(n), 3.5);
  EXPECT_DOUBLE_EQ(dynhet::scene_kick_rate(n), 2.0);
}

TEST(Scene, UnknownKeyAndTableAreRefused) {
  expect_error("[system]\nn_partcles = 100\n", {"system.n_partcles", "unknown key", "n_particles"});
  expect_error("[sytem]\nn_particles = 100\n", {"sytem", "unknown table"});
}

TEST(Scene, WrongTypesAreRefused) {
  expect_error("[system]\nn_particles = \"many\"\n", {"system.n_particles", "many", "a string", "an integer"});
  expect_error("[system]\nn_particles = 100.5\n", {"system.n_particles", "100.5", "an integer"});
  expect_error("[driving]\nenabled = 1\n", {"driving.enabled", "boolean"});
  expect_error("[observables]\ncutoff_a = 0.6\n", {"observables.cutoff_a", "array"});
}

TEST(Scene, ImpossibleValuesAreRefused) {
  expect_error("[system]\npacking_fraction = 0.9\n", {"system.packing_fraction", "0.9", "0 < phi < 0.9"});
  expect_error("[system]\npacking_fraction = -0.1\n", {"system.packing_fraction"});
  expect_error("[system]\nrestitution = 0.0\n", {"system.restitution", "0 < eps <= 1"});
  expect_error("[system]\nrestitution = 1.2\n", {"system.restitution", "1.2"});
  expect_error("[system]\nn_particles = 1\n", {"system.n_particles", "2 <= value"});
  expect_error("[system]\nn_particles = 10\n", {"system.n_particles", "too small"});
  expect_error("[run]\nequilibration_time = -5\n", {"run.equilibration_time", "-5", ">= 0"});
  expect_error("[schedule]\nlag_min = -1\n", {"schedule.lag_min", "> 0"});
  expect_error("[schedule]\nlag_min = 10\nlag_max = 5\n", {"schedule.lag_min", "smaller than schedule.lag_max"});
  expect_error("[run]\nproduction_time = 5\n", {"run.production_time", "shorter than the schedule needs"});
  expect_error("[observables]\ncompute = [\"entropy\"]\n", {"observables.compute", "entropy", "overlap"});
  expect_error("[observables]\ncutoff_a = [0.6, -1]\n", {"observables.cutoff_a", "-1"});
  expect_error("[driving]\nkick_rate = \"fast\"\n", {"driving.kick_rate", "enskog"});
  expect_error("[driving]\npairs = \"nearest\"\n", {"driving.pairs", "nearest", "\"neighbours\" or \"any\""});
  expect_error("[driving]\npairs = 1\n", {"driving.pairs", "a string"});
  expect_error("[driving]\nreach = 0\n", {"driving.reach", "0 < reach <= 10"});
  expect_error("[driving]\nreach = 11\n", {"driving.reach", "11"});
  expect_error("[driving]\ncontact_value = \"carnahan\"\n", {"driving.contact_value", "\"mixture\", \"henderson\""});
  expect_error("[transport]\nchunk_particles = 100000\n", {"transport.chunk_particles", "65000"});
  expect_error("[observables]\ncutoff_a = [0.6, 0.6]\n", {"observables.cutoff_a", "once"});
  // Two cutoffs that print alike would share a channel and a group (a0.6).
  expect_error("[observables]\ncutoff_a = [0.6, 0.6000001]\n",
               {"observables.cutoff_a", "six significant", "a0.6"});
  expect_error("[observables]\ncompute = [\"overlap\", \"overlap\"]\n", {"observables.compute", "once"});
  expect_error("[system]\nn_particles = 2147483648\n", {"system.n_particles", "2147483647"});
  expect_error("[overlap]\nsubbox_particles = 2147483648\n", {"overlap.subbox_particles"});
  expect_error("[schedule]\norigins = 1000000\nlags_per_decade = 1000\nlag_min = 1e-9\nlag_max = 1e9\n",
               {"schedule", "more than 10^6"});
  // Values are shown as written, not as the nearest double's long expansion.
  expect_error("[system]\npacking_fraction = 0.9\n", {"value 0.9 is"});
}

TEST(Scene, AllProblemsAreReportedTogether) {
  const std::string err = error_of("[system]\nrestitution = 2\npacking_fraction = 0.95\n");
  EXPECT_NE(err.find("2 problems"), std::string::npos) << err;
}

TEST(Scene, SyntaxErrorNamesLine) {
  expect_error("[system]\nn_particles = = 3\n", {"test.toml:2", "not valid TOML"});
}

TEST(Scene, S4TableIsValidated) {
  const auto s = parse_scene_text("[s4]\nlags = [1.0, 5]\nq_max = 2\nhalf_width = 6\nsubbox_particles = [64]\n", "ok");
  EXPECT_EQ(s.s4_lags, (std::vector<double>{1.0, 5.0}));
  EXPECT_DOUBLE_EQ(s.s4_q_max, 2.0);
  EXPECT_EQ(s.s4_half_width, 6);
  EXPECT_EQ(s.s4_subbox_particles, (std::vector<int>{64}));
  EXPECT_TRUE(parse_scene_text("[s4]\nlags = \"all\"\n", "ok").s4_lags.empty());
  EXPECT_EQ(dynhet::nodes_for({"overlap", "chi4", "s4"}), (std::vector<std::string>{"overlap_node", "s4_node"}));
  expect_error("[s4]\nlags = \"tau\"\n", {"s4.lags", "\"all\""});
  expect_error("[s4]\nlags = [1000.0]\n", {"s4.lags", "outside the scheduled lags"});
  expect_error("[s4]\nlags = [-1]\n", {"s4.lags", "> 0"});
  expect_error("[s4]\nq_max = 0\n", {"s4.q_max", "> 0"});
  expect_error("[s4]\ngrid_spacing = 4.0\n", {"s4.grid_spacing", "too coarse", "pi / q_max"});
  expect_error("[s4]\nhalf_width = 1\n", {"s4.half_width", "2 <= value <= 16"});
  expect_error("[s4]\nsubbox_particles = [0]\n", {"s4.subbox_particles", ">= 1"});
  expect_error("[s4]\nxi = 1\n", {"s4.xi", "unknown key", "q_max"});
}

TEST(Scene, ClustersTableIsValidated) {
  const auto d = parse_scene_text("", "test.toml");
  EXPECT_LT(d.clusters.lag, 0); // tau_alpha
  EXPECT_TRUE(d.clusters.neighbour_cutoffs.empty()); // from g_ab
  const auto s = parse_scene_text("[observables]\ncompute = [\"clusters\"]\n[clusters]\nlag = 2.5\n"
                                  "neighbour_cutoffs = [2.6, 3.2, 3.8]\npower_law_sizes = [2, 50]\n",
                                  "test.toml");
  EXPECT_TRUE(s.wants("clusters"));
  EXPECT_EQ(dynhet::nodes_for(s.observables), std::vector<std::string>{"clusters_node"});
  EXPECT_DOUBLE_EQ(s.clusters.lag, 2.5);
  EXPECT_EQ(s.clusters.neighbour_cutoffs, (std::vector<double>{2.6, 3.2, 3.8}));
  EXPECT_EQ(s.clusters.power_law_sizes, (std::vector<int64_t>{2, 50}));
  expect_error("[clusters]\nlag = \"tau\"\n", {"clusters.lag", "\"tau_alpha\" or a number > 0"});
  expect_error("[clusters]\nneighbour_cutoffs = [2.6, 3.2]\n", {"clusters.neighbour_cutoffs", "[r11, r12, r22]"});
  expect_error("[clusters]\nneighbour_cutoffs = [2.6, -3.2, 3.8]\n", {"clusters.neighbour_cutoffs", "> 0"});
  expect_error("[clusters]\npower_law_sizes = [50, 2]\n", {"clusters.power_law_sizes", "1 <= lo < hi"});
  expect_error("[clusters]\ncutoff_frames = 11\n", {"clusters.cutoff_frames", "origins"});
  expect_error("[clusters]\ngr_r_max = 1000.0\n", {"clusters.gr_r_max", "half the box"});
  expect_error("[clusters]\ngr_bin = 1.0\n", {"clusters.gr_bin", "10 bins"});
  expect_error("[clusters]\nerror_blocks = 1\n", {"clusters.error_blocks", "2 <= value"});
  expect_error("[clusters]\nsmoothing = 1\n", {"clusters.smoothing", "unknown key", "gr_smoothing"});
}

TEST(Scene, MsdAndDisplacementTablesAreValidated) {
  const auto d = parse_scene_text("", "test.toml");
  EXPECT_DOUBLE_EQ(d.msd.fraction_all, 0.1);   // the paper's 10% of all particles
  EXPECT_DOUBLE_EQ(d.msd.fraction_small, 0.2); // and 20% of small ones
  EXPECT_EQ(d.displacement.lags_tau_alpha, (std::vector<double>{0.01, 1.0, 8.5})); // its fig. "tails"
  EXPECT_EQ(d.displacement.bins(), 400);
  const auto s = parse_scene_text("[observables]\ncompute = [\"displacement\"]\n[msd]\nfraction_small = 0.5\n"
                                  "[displacement]\nlags_tau_alpha = []\nlags = [2, 4.5]\nx_max = 3\n"
                                  "bin_width = 0.1\n",
                                  "test.toml");
  EXPECT_EQ(dynhet::nodes_for(s.observables), std::vector<std::string>{"overlap_node"});
  EXPECT_DOUBLE_EQ(s.msd.fraction_small, 0.5);
  EXPECT_EQ(s.displacement.lags, (std::vector<double>{2.0, 4.5}));
  EXPECT_EQ(s.displacement.bins(), 60);
  expect_error("[msd]\nfraction_all = 0.6\n", {"msd.fraction_all", "0 < fraction <= 0.5"});
  expect_error("[msd]\nfraction_small = 0\n", {"msd.fraction_small", "0 < fraction <= 0.5"});
  expect_error("[displacement]\nlags = [1, -2]\n", {"displacement.lags", "> 0"});
  expect_error("[displacement]\nlags_tau_alpha = 1.0\n", {"displacement.lags_tau_alpha", "an array"});
  expect_error("[observables]\ncompute = [\"displacement\"]\n[displacement]\nlags_tau_alpha = []\n",
               {"displacement.lags_tau_alpha", "both empty"});
  expect_error("[displacement]\nbin_width = 5.0\n", {"displacement.bin_width", "10 to 4000 bins"});
  expect_error("[displacement]\nbin_width = 0.005\n", {"displacement.bin_width", "more than 4096"});
  expect_error("[displacement]\nerror_blocks = 1\n", {"displacement.error_blocks", "2 <= value"});
  expect_error("[displacement]\ntail = 2\n", {"displacement.tail", "unknown key", "tail_sigmas"});
}

// Sub-box sizes as the nested grids realise them (paper's chi4 of sub-boxes):
// at N = 4096, 2048 per box has no grid of its own nested in the finer ones
// (the nearest divisor of 3 is 1, the whole box), which 8192 already asks
// for: it is dropped, with a note, never computed twice.
TEST(Scene, SubboxSizesThatNoGridRealisesAreDroppedOrNoted) {
  const auto s = parse_scene_text(
      "[system]\nn_particles = 4096\n[chi4]\nsubbox_particles = [32, 128, 512, 2048, 8192]\n", "subbox");
  EXPECT_EQ(s.chi4_subbox_particles, (std::vector<int>{32, 128, 512, 8192}));
  ASSERT_EQ(s.notes.size(), 1u);
  EXPECT_NE(s.notes[0].find("chi4.subbox_particles: 2048 particles per sub-box is not realised at N = 4096"),
            std::string::npos)
      << s.notes[0];
  // 1600 alone: a 2 x 2 grid, 1024 per box, 36% off: kept, and said.
  const auto t = parse_scene_text("[system]\nn_particles = 4096\n[chi4]\nsubbox_particles = [1600]\n", "far");
  EXPECT_EQ(t.chi4_subbox_particles, (std::vector<int>{1600}));
  ASSERT_EQ(t.notes.size(), 1u);
  EXPECT_NE(t.notes[0].find("realised as 1024.0"), std::string::npos) << t.notes[0];
  // The default list at N = 10^5: every size within 25%, no note.
  const auto d = parse_scene_text("[system]\nn_particles = 100000\n", "default sizes");
  EXPECT_EQ(d.chi4_subbox_particles.size(), 6u);
  EXPECT_TRUE(d.notes.empty());
}

// Values --check used to accept that failed or hung at run time are refused
// up front with a reason; numbers are printed as written; integers beyond
// 2^53 in float keys are refused, not rounded.
TEST(Scene, ValuesThatCannotRunAreRefusedUpFront) {
  const std::string s4 = "[observables]\ncompute = [\"overlap\", \"s4\"]\n";
  expect_error(s4 + "[s4]\nq_max = 1e9\n", {"s4.q_max", "points per box side"});
  expect_error(s4 + "[s4]\ngrid_spacing = 1e-9\n", {"s4.grid_spacing", "points per box side"});
  expect_error("[clusters]\ngr_bin = 1e-12\n", {"clusters.gr_bin", "10^5 bins"});
  expect_error("[system]\nrestitution = 0.9\n[driving]\nkick_rate = 1e300\n", {"driving.kick_rate", "1e+300"});
  expect_error("[run]\ncheckpoint_interval = 1e-300\n", {"run.checkpoint_interval", "1e-300", "10^6 checkpoints"});
  expect_error("[system]\nrestitution = 1e-12\n", {"system.restitution", "TC model"});
  expect_error("[schedule]\norigins = 1000000\n", {"schedule", "more than 10^6"});
  expect_error("[system]\nrestitution = 1.0000000000000002\n", {"system.restitution", "1.0000000000000002"});
  expect_error("[schedule]\norigin_spacing = 9007199254740993\n", {"schedule.origin_spacing", "2^53"});
  // Exactly representable integers in float keys are read exactly.
  const auto s = parse_scene_text(
      "[schedule]\norigin_spacing = 9007199254740992\nlag_max = 10\n[run]\ncheckpoint_interval = 1e12\n", "exact");
  EXPECT_EQ(s.schedule.origin_spacing, 9007199254740992.0);
}

// The resolved scene (scene_toml, sim_node --resolved) is the scene: it
// reads back as itself, every key written out, defaults filled in.
TEST(Scene, ResolvedSceneReadsBackAsItself) {
  const std::string dir = std::string(DYNHET_SOURCE_DIR) + "/scenes/";
  std::vector<dynhet::Scene> scenes{parse_scene_text("", "empty.toml"), dynhet::parse_scene_file(dir + "default.toml"),
                                    dynhet::parse_scene_file(dir + "tiny.toml"),
                                    parse_scene_text("[driving]\nkick_rate = 3.5\ncontact_value = 1.25\n"
                                                     "[clusters]\nlag = 2.0\nneighbour_cutoffs = [2.5, 3.0, 3.5]\n"
                                                     "[s4]\nlags = [1.0, 10.0]\nsubbox_particles = [50]\n"
                                                     "[system]\ninitial_state = \"a \\\"b\\\".h5\"\n",
                                                     "numbers.toml")};
  for (const auto& s : scenes) {
    const std::string text = dynhet::scene_toml(s);
    const dynhet::Scene again = parse_scene_text(text, s.path + " (resolved)");
    EXPECT_EQ(dynhet::scene_toml(again), text) << s.path;
    EXPECT_EQ(dynhet::scene_kick_rate(again), dynhet::scene_kick_rate(s)) << s.path;
    EXPECT_EQ(again.initial_state, s.initial_state);
    for (const std::string& key : dynhet::scene_key_names()) {
      if (key == "system.initial_state" && s.initial_state.empty()) continue; // no path: compress
      const std::string name = key.substr(key.find('.') + 1);
      EXPECT_NE(text.find("\n" + name + " = "), std::string::npos) << key << " missing in\n" << text;
    }
  }
  const std::string defaults = dynhet::scene_toml(scenes[0]);
  for (const char* line : {"packing_fraction = 0.7\n", "radius_ratio = 1.43\n", "kick_rate = \"enskog\"\n",
                           "contact_value = \"mixture\"\n", "cutoff_a = [0.6]\n", "production_time = 190.0\n",
                           "lags = \"all\"\n", "neighbour_cutoffs = \"g_ab\"\n"})
    EXPECT_NE(defaults.find(line), std::string::npos) << line << " not in\n" << defaults;
}

// [model]: what the simulator derives, by model.hpp's formulas.
TEST(Scene, ModelTableHoldsTheEngineFormulas) {
  const auto s = parse_scene_text("[system]\npacking_fraction = 0.76\nradius_ratio = 1.2\nrestitution = 0.8\n", "m");
  const std::string t = dynhet::model_toml(s);
  auto value = [&](const std::string& key) {
    const auto at = t.find("\n" + key + " = ");
    EXPECT_NE(at, std::string::npos) << key;
    return std::stod(t.substr(at + key.size() + 4));
  };
  EXPECT_EQ(value("kick_rate"), dynhet::scene_kick_rate(s));
  EXPECT_EQ(value("collision_frequency"),
            dynhet::enskog_frequency(0.76, dynhet::mixture_contact_value(0.76, 1.2)));
  EXPECT_EQ(value("kick_amplitude"), dynhet::kick_amplitude(0.8, 1.0, 1.44));
  EXPECT_EQ(value("box_length"), dynhet::make_model(1000, 0.76, 1.2).box_length);
  EXPECT_EQ(value("sim_time"), s.equilibration_time + s.production_time);
}
