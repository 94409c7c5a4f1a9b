// RunRecorder fed with synthetic messages (no bus): what it writes, when a
// run counts as settled, and that anything missing is named in the file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>

#include "h5_read.hpp"
#include "run_recorder.hpp"

namespace {

using h5read::Attr;
using Shape = std::vector<hsize_t>;
constexpr int64_t kRun = 42;

std::string temp_file(const std::string &name) {
  return ::testing::TempDir() + "dynhet_rec_" + std::to_string(getpid()) + "_" + name + ".h5";
}

// Four particles in a box of 10, three frames, one origin and two lags,
// two cutoffs, frames kept in chunks of two particles.
dynhet::run_info_t run_info() {
  dynhet::run_info_t m{};
  m.utime = 1'000'000;
  m.run_id = kRun;
  m.n_particles = 4;
  m.box_length = 10;
  m.packing_fraction = 0.5;
  m.restitution = 0.9;
  m.radius[0] = 1, m.radius[1] = 1.43;
  m.mass[0] = 1, m.mass[1] = 1.43 * 1.43;
  m.n_small = 2;
  m.frame_time = {100, 100.5, 101};
  m.n_frames = 3;
  m.origin_frame = {0};
  m.n_origins = 1;
  m.lag_time = {0.5, 1};
  m.n_lags = 2;
  m.pair_frame = {1, 2};
  m.n_pairs = 2;
  m.cutoff_a = {0.6, 1.8};
  m.n_cutoffs = 2;
  m.observables = {"overlap"};
  m.n_observables = 1;
  m.overlap_subbox_particles = 4;
  m.keep_frames = true;
  m.chunk_particles = 2;
  m.scene_toml = "[system]\nn_particles = 4\n";
  return m;
}

dynhet::sim_status_t sim(double wall_s, const std::string &phase, double t, int frames_published = 3) {
  dynhet::sim_status_t m{};
  m.utime = static_cast<int64_t>(wall_s * 1e6);
  m.run_id = kRun;
  m.phase = phase;
  m.sim_time = t;
  m.n_collisions = static_cast<int64_t>(1000 * t);
  m.kinetic_energy = 1.0;
  m.frames_published = frames_published;
  return m;
}

dynhet::node_status_t node(double wall_s, const std::string &state, int whole) {
  dynhet::node_status_t m{};
  m.utime = static_cast<int64_t>(wall_s * 1e6);
  m.run_id = kRun;
  m.node = "overlap";
  m.state = state;
  m.frames_expected = 3;
  m.frames_whole = whole;
  return m;
}

// What every result message of cutoff a at frame `frame` says about itself.
template <class Msg> Msg result(double a, bool final, int frame) {
  Msg m{};
  m.run_id = kRun;
  m.sim_time = 100 + 0.5 * frame;
  m.frame_index = frame;
  m.is_final = final;
  m.cutoff_a = a;
  return m;
}

dynhet::overlap_t overlap(double a, bool final, int frame) {
  auto m = result<dynhet::overlap_t>(a, final, frame);
  m.subbox_per_side = 1;
  m.subbox_particles = 4;
  m.n_lags = 2;
  m.lag_time = {0.5, 1};
  m.q = {0.9, frame > 1 ? 0.5 : NAN};
  m.q_err = {NAN, NAN};
  m.n_origins = {1, frame > 1 ? 1 : 0};
  m.qr_var = {0, 0};
  m.tau_alpha = NAN;
  m.tau_alpha_err = NAN;
  m.n_t0 = 2;
  m.t0 = {100, 100.5};
  m.tau_alpha_t0 = {0.8, NAN};
  m.tau_alpha_t0_err = {0.1, NAN};
  return m;
}

// Frame f as two chunks (particles 0-1 and 2-3), positions f + particle.
void send_frame(dynhet::RunRecorder &rec, int f, bool drop_second_chunk = false) {
  for (int c = 0; c < (drop_second_chunk ? 1 : 2); ++c) {
    dynhet::frame_chunk_t m{};
    m.run_id = kRun;
    m.frame_index = f;
    m.time = 100 + 0.5 * f;
    m.n_particles = 4;
    m.chunk_index = c;
    m.chunk_count = 2;
    m.first_particle = 2 * c;
    m.count = 2;
    m.n_values = 4;
    for (int i = 0; i < 4; ++i) m.position.push_back(f + 2 * c + 0.25 * i);
    EXPECT_TRUE(rec.on_frame_chunk(m));
  }
}

// The run up to the sim saying done: statuses, frames, running results.
// Statuses before the first frame make no record; after frame f, the sim
// says it has published f + 1 frames and the node that it has f + 1 whole.
void run_until_done(dynhet::RunRecorder &rec, bool lose_a_frame = false) {
  ASSERT_TRUE(rec.on_run(run_info()));
  EXPECT_FALSE(rec.on_run(run_info())); // the repeats change nothing
  EXPECT_TRUE(rec.on_sim_status(sim(1.0, "production", 99.9, 0)));
  EXPECT_TRUE(rec.on_node_status(node(1.1, "running", 0)));
  for (int f = 0; f < 3; ++f) {
    send_frame(rec, f, lose_a_frame && f == 1);
    for (double a : {0.6, 1.8}) EXPECT_TRUE(rec.on_result(overlap(a, false, f)));
    EXPECT_TRUE(rec.on_sim_status(sim(1.2 + f, "production", 100.1 + 0.5 * f, f + 1)));
    EXPECT_TRUE(rec.on_node_status(node(1.2 + 0.1 * f, "running", f + 1)));
  }
  EXPECT_TRUE(rec.on_sim_status(sim(3.5, "production", 101.3))); // frame 2 again: dropped
  EXPECT_TRUE(rec.on_sim_status(sim(3.6, "done", 101.5)));       // the last word: replaces frame 2's
  EXPECT_TRUE(rec.completion().sim_ended());
}

TEST(RunRecorder, IgnoresOtherRuns) {
  const std::string path = temp_file("other");
  dynhet::RunRecorder rec(path, "test");
  auto o = overlap(0.6, true, 2);
  EXPECT_FALSE(rec.on_result(o)); // no run yet
  ASSERT_TRUE(rec.on_run(run_info()));
  o.run_id = 7;
  EXPECT_FALSE(rec.on_result(o));
  auto s = sim(1, "done", 1);
  s.run_id = 7;
  EXPECT_FALSE(rec.on_sim_status(s));
  EXPECT_FALSE(rec.completion().sim_ended());
  rec.finish("test over");
  std::remove(path.c_str());
}

TEST(RunRecorder, CompleteRunIsWrittenAndMarkedComplete) {
  const std::string path = temp_file("complete");
  dynhet::RunRecorder rec(path, "test", "Tess Ter", "tess@example.org");
  run_until_done(rec);
  EXPECT_FALSE(rec.completion().settled()); // no final results yet
  for (double a : {0.6, 1.8}) {
    auto final = overlap(a, true, 2); // the same frame as the last running result
    final.tau_alpha = 0.75;
    rec.on_result(final);
  }
  EXPECT_FALSE(rec.completion().settled()); // the node has not said done
  EXPECT_TRUE(rec.on_node_status(node(2.7, "done", 3)));
  EXPECT_TRUE(rec.completion().settled());
  EXPECT_TRUE(rec.finish().empty());

  h5read::File f(path);
  EXPECT_EQ(Attr(f, "/h5md/author", "name").strings().at(0), "Tess Ter");
  EXPECT_EQ(Attr(f, "/h5md/author", "email").strings().at(0), "tess@example.org");
  EXPECT_EQ(Attr(f, "/", "complete").values<int32_t>(), std::vector<int32_t>{1});
  EXPECT_EQ(Attr(f, "/", "missing").strings().at(0), "");
  EXPECT_EQ(Attr(f, "/", "run_id").values<int64_t>(), std::vector<int64_t>{kRun});
  EXPECT_EQ(Attr(f, "/", "frames_lost_overlap").values<int32_t>(), std::vector<int32_t>{0});
  EXPECT_EQ(Attr(f, "/observables/nodes/overlap", "state").strings().at(0), "done");

  // Every series on the frame clock: step f, time frame_time[f] = 100, 100.5, 101.
  const std::vector<int64_t> steps{0, 1, 2};
  const std::vector<double> frame_times{100, 100.5, 101};
  // Sim: the first status after each frame; its "done" replaces frame 2's. sim_time is its own.
  EXPECT_EQ(h5read::read<int64_t>(f, "/observables/sim/kinetic_energy/step"), steps);
  EXPECT_EQ(h5read::read<double>(f, "/observables/sim/kinetic_energy/time"), frame_times);
  EXPECT_EQ(h5read::read<double>(f, "/observables/sim/sim_time/value"),
            (std::vector<double>{100.1, 100.6, 101.5}));
  EXPECT_EQ(h5read::read<int64_t>(f, "/observables/sim/n_collisions/value"),
            (std::vector<int64_t>{100100, 100600, 101500}));
  EXPECT_EQ(h5read::read<int32_t>(f, "/observables/sim/frames_published/value"),
            (std::vector<int32_t>{1, 2, 3}));
  // Node: step = frames handled - 1, time that frame's; done (2.7 s) replaces frame 2's;
  // the wall clock in its own element, seconds since the first node status recorded (1.2 s,
  // frame 0's; the waiting one at 1.1 s made no record).
  EXPECT_EQ(h5read::read<int64_t>(f, "/observables/nodes/overlap/frames_whole/step"), steps);
  EXPECT_EQ(h5read::read<double>(f, "/observables/nodes/overlap/frames_whole/time"), frame_times);
  EXPECT_EQ(h5read::read<int32_t>(f, "/observables/nodes/overlap/frames_whole/value"),
            (std::vector<int32_t>{1, 2, 3}));
  const auto wall = h5read::read<double>(f, "/observables/nodes/overlap/wall_time/value");
  ASSERT_EQ(wall.size(), 3u);
  EXPECT_NEAR(wall[0], 0.0, 1e-5);
  EXPECT_NEAR(wall[1], 0.1, 1e-5);
  EXPECT_NEAR(wall[2], 1.5, 1e-5);

  // Results: the final result (frame 2, like the last running one) replaces that record.
  const std::string q = "/observables/overlap/a1.8/q";
  EXPECT_EQ(h5read::shape(f, q + "/value"), (Shape{3, 2}));
  EXPECT_EQ(h5read::read<int64_t>(f, q + "/step"), steps);
  EXPECT_EQ(h5read::read<double>(f, q + "/time"), frame_times);
  const auto tau = h5read::read<double>(f, "/observables/overlap/a0.6/tau_alpha/value");
  ASSERT_EQ(tau.size(), 3u);
  EXPECT_EQ(tau[2], 0.75);
  // tau_alpha per origin with its error, [record][t0]; t0 an axis written once.
  EXPECT_EQ(h5read::read<double>(f, "/observables/overlap/a0.6/t0"), (std::vector<double>{100, 100.5}));
  EXPECT_EQ(h5read::shape(f, "/observables/overlap/a0.6/tau_alpha_t0_err/value"), (Shape{3, 2}));
  const auto t0_err = h5read::read<double>(f, "/observables/overlap/a0.6/tau_alpha_t0_err/value");
  EXPECT_EQ(t0_err[4], 0.1);
  EXPECT_TRUE(std::isnan(t0_err[5]));
  EXPECT_EQ(h5read::shape(f, "/observables/schedule/pair_frame"), (Shape{1, 2})); // [origin][lag]
  EXPECT_EQ(h5read::read<double>(f, "/observables/overlap/a0.6/lag_time"), (std::vector<double>{0.5, 1}));
  EXPECT_EQ(Attr(f, "/observables/overlap/a0.6", "subbox_per_side").values<int32_t>(),
            std::vector<int32_t>{1});
  EXPECT_EQ(h5read::read<double>(f, "/observables/schedule/frame_time"),
            (std::vector<double>{100, 100.5, 101}));

  EXPECT_EQ(h5read::shape(f, "/particles/all/position/value"), (Shape{3, 4, 2}));
  EXPECT_EQ(h5read::read<int64_t>(f, "/particles/all/position/step"), steps);
  EXPECT_TRUE(h5read::same_object(f, "/particles/all/position/step", "/particles/all/image/step"));
  EXPECT_TRUE(h5read::same_object(f, "/particles/all/position/time", "/particles/all/image/time"));
  const auto pos = h5read::read<double>(f, "/particles/all/position/value");
  EXPECT_EQ(pos[8 + 5], 3.25); // frame 1, particle 2, y: 1 + 2 + 0.25
  EXPECT_EQ(h5read::read<int32_t>(f, "/particles/all/species"), (std::vector<int32_t>{0, 0, 1, 1}));
  EXPECT_EQ(h5read::read_string(f, "/parameters/scene_toml"), run_info().scene_toml);
  std::remove(path.c_str());
}

TEST(RunRecorder, MissingResultsAreNamed) {
  const std::string path = temp_file("missing");
  dynhet::RunRecorder rec(path, "test");
  run_until_done(rec, /*lose_a_frame=*/true);
  rec.on_result(overlap(0.6, true, 2));
  rec.on_node_status(node(2.7, "done", 3));
  EXPECT_FALSE(rec.completion().settled()); // a1.8 has no final result
  const auto missing = rec.finish("timeout");
  const std::vector<std::string> expect = {"timeout", "overlap a1.8: no final result",
                                           "frames: 1 of 3 lost by the recorder"};
  EXPECT_EQ(missing, expect);

  h5read::File f(path);
  EXPECT_EQ(Attr(f, "/", "complete").values<int32_t>(), std::vector<int32_t>{0});
  EXPECT_EQ(Attr(f, "/", "missing").strings().at(0),
            "timeout; overlap a1.8: no final result; frames: 1 of 3 lost by the recorder");
  EXPECT_EQ(Attr(f, "/", "frames_lost_recorder").values<int32_t>(), std::vector<int32_t>{1});
  EXPECT_EQ(h5read::shape(f, "/particles/all/position/value"), (Shape{2, 4, 2}));
  std::remove(path.c_str());
}

// One S4 message of cutoff a: two grids (m = 2 and the whole box), two shells each, two lags.
dynhet::s4_t s4(double a, bool final, int frame) {
  auto m = result<dynhet::s4_t>(a, final, frame);
  m.q_max = 1;
  m.qxi_max = 1;
  m.tau_alpha = NAN;
  m.t_s4 = 1;
  m.lag_index = 1;
  m.n_origins = 1;
  m.xi = a, m.chi0 = 2 * a;
  m.n_grids = 2;
  m.subbox_particles = {1, 4};
  m.subbox_per_side = {2, 1};
  m.grid_spacing = {1.5, 1.5};
  m.grid_points = {4, 8};
  m.n_shells = {2, 2};
  for (auto *v : {&m.oz_chi0, &m.oz_chi0_err, &m.oz_xi, &m.oz_xi_err, &m.oz_q_fit_max, &m.a2_chi0, &m.a2_chi0_err,
                  &m.a2_xi, &m.a2_xi_err, &m.a2_a, &m.a2_a_err, &m.a2_q_fit_max, &m.chi4, &m.chi4_err})
    *v = {a, a};
  m.oz_n_fit = {0, 2}, m.a2_n_fit = {0, 2};
  m.n_values = 4;
  m.q = {0, 1.2, 0.6, 1.2};
  m.shell_vectors = {1, 8, 4, 8};
  m.s4 = {a, a, NAN, a}, m.s4_err = {0, 0, NAN, 0};
  m.n_lags = 2;
  m.lag_time = {0.5, 1};
  m.n_lag_values = 8;
  m.s4_lag.assign(8, a);
  m.n_lag_fits = 4;
  m.xi_lag.assign(4, a), m.chi0_lag.assign(4, a), m.xi_lag_rule.assign(4, 0);
  m.xi_lag_err = {0, 1, 10, 11}, m.chi0_lag_err = {0, 1, 10, 11}; // [l * 2 + g] = 10 l + g
  m.xi_lag_err[3] = NAN;                                           // no error at that lag and grid
  return m;
}

// S4 depends on the cutoff: one group and one final result per cutoff, as overlap, chi4 and clusters.
TEST(RunRecorder, S4IsRecordedPerCutoff) {
  const std::string path = temp_file("s4");
  dynhet::RunRecorder rec(path, "test");
  auto info = run_info();
  info.observables = {"s4"};
  info.keep_frames = false;
  ASSERT_TRUE(rec.on_run(info));
  rec.on_sim_status(sim(1.0, "done", 101));
  auto n = node(1.1, "done", 3);
  n.node = "s4";
  rec.on_node_status(n);
  for (double a : {0.6, 1.8}) EXPECT_TRUE(rec.on_result(s4(a, false, 1)));
  EXPECT_TRUE(rec.on_result(s4(0.6, true, 2)));
  EXPECT_FALSE(rec.completion().settled()); // a1.8 has no final S4 yet
  EXPECT_EQ(rec.completion().missing(), std::vector<std::string>{"s4 a1.8: no final result"});
  EXPECT_TRUE(rec.on_result(s4(1.8, true, 2)));
  EXPECT_TRUE(rec.completion().settled());
  EXPECT_TRUE(rec.finish().empty());

  h5read::File f(path);
  for (double a : {0.6, 1.8}) {
    const std::string g = "/observables/s4/" + dynhet::cutoff_label(a);
    EXPECT_EQ(Attr(f, g, "cutoff_a").values<double>(), std::vector<double>{a});
    EXPECT_EQ(h5read::read<double>(f, g + "/lag_time"), (std::vector<double>{0.5, 1}));
    EXPECT_EQ(h5read::read<int32_t>(f, g + "/subbox_per_side"), (std::vector<int32_t>{2, 1}));
    EXPECT_EQ(h5read::shape(f, g + "/s4_lag/value"), (Shape{2, 2, 4})); // [record][lag][value]
    EXPECT_EQ(h5read::shape(f, g + "/xi_lag/value"), (Shape{2, 2, 2})); // [record][lag][grid]
    EXPECT_EQ(h5read::shape(f, g + "/xi_lag_err/value"), (Shape{2, 2, 2}));
    const std::vector<double> xi_err = h5read::read<double>(f, g + "/xi_lag_err/value");
    EXPECT_EQ(std::vector<double>(xi_err.begin() + 4, xi_err.begin() + 7), (std::vector<double>{0, 1, 10}));
    EXPECT_TRUE(std::isnan(xi_err[7]));
    EXPECT_EQ(h5read::shape(f, g + "/chi0_lag_err/value"), (Shape{2, 2, 2}));
    EXPECT_EQ(h5read::shape(f, g + "/oz_xi/value"), (Shape{2, 2}));
    EXPECT_EQ(h5read::read<double>(f, g + "/xi/value"), (std::vector<double>{a, a}));
    EXPECT_EQ(h5read::read<int64_t>(f, g + "/chi0/step"), (std::vector<int64_t>{1, 2}));
  }
  std::remove(path.c_str());
}

// chi4 [record][grid][lag] and P(dx) [record][set][target][bin] keep their
// dimensions (the messages' flat arrays in C order); a result whose sizes
// do not fit its dimensions, or whose frame is not one of the run's, is
// rejected and counted, not written.
TEST(RunRecorder, MultiDimensionalResultsKeepTheirShape) {
  const std::string path = temp_file("shapes");
  dynhet::RunRecorder rec(path, "test");
  auto info = run_info();
  info.observables = {"overlap"};
  info.keep_frames = false;
  ASSERT_TRUE(rec.on_run(info));

  auto c = result<dynhet::chi4_t>(0.6, false, 1);
  c.n_grids = 2, c.subbox_particles = {1, 4}, c.subbox_per_side = {2, 1};
  c.n_lags = 3, c.lag_time = {0.5, 1, 1.5};
  c.n_values = 6;
  for (int i = 0; i < 6; ++i) c.chi4.push_back(i), c.chi4_err.push_back(10 + i); // [g * 3 + j] = 3 g + j
  c.chi4_per_origin = c.chi4, c.chi4_per_origin_err = c.chi4_err;
  c.chi4_peak = c.tau4 = c.chi4_peak_err = c.tau4_err = {1, 2};
  c.tau4_interior = {1, 0};
  EXPECT_TRUE(rec.on_result(c));
  auto wrong = c;
  wrong.n_lags = 2, wrong.lag_time = {0.5, 1}; // 6 values are not 2 x 2
  EXPECT_FALSE(rec.on_result(wrong));
  auto late = c;
  late.frame_index = 3; // the run has frames 0 .. 2
  EXPECT_FALSE(rec.on_result(late));
  EXPECT_EQ(rec.messages_rejected(), 2);

  auto d = result<dynhet::displacement_t>(0.6, false, 2);
  d.n_bins = 3, d.x = {-1, 0, 1}, d.bin_width = 1;
  d.n_targets = 2, d.target_time = {0.5, 1}, d.target_tau_alpha = {NAN, NAN}, d.lag_index = {0, 1};
  d.lag_time = {0.5, 1};
  d.n_sets = 2, d.n_series = 4;
  d.n_pairs = {1, 2, 3, 4}, d.samples = {1, 2, 3, 4};
  for (auto *v : {&d.fraction_outside, &d.gauss_d, &d.gauss_d_err, &d.tail_x0, &d.tail_x0_err,
                  &d.tail_amplitude, &d.tail_x_min, &d.tail_x_max})
    *v = {0, 1, 10, 11}; // [s * 2 + l] = 10 s + l
  d.gauss_bins = d.tail_bins = {0, 1, 10, 11};
  d.n_values = 12;
  for (int i = 0; i < 12; ++i) d.p.push_back(i), d.p_err.push_back(i), d.count.push_back(i);
  EXPECT_TRUE(rec.on_result(d));
  rec.finish("test over");

  h5read::File f(path);
  const std::string g = "/observables/chi4/a0.6";
  EXPECT_EQ(h5read::shape(f, g + "/chi4/value"), (Shape{1, 2, 3}));
  EXPECT_EQ(h5read::shape(f, g + "/chi4_err/value"), (Shape{1, 2, 3}));
  EXPECT_EQ(h5read::read<double>(f, g + "/chi4/value"), (std::vector<double>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(h5read::shape(f, g + "/chi4_peak/value"), (Shape{1, 2}));
  EXPECT_EQ(h5read::shape(f, g + "/chi4_per_origin/value"), (Shape{1, 2, 3}));
  EXPECT_EQ(h5read::read<int32_t>(f, g + "/tau4_interior/value"), (std::vector<int32_t>{1, 0}));
  EXPECT_EQ(h5read::read<int64_t>(f, g + "/chi4/step"), std::vector<int64_t>{1});
  EXPECT_EQ(h5read::read<double>(f, g + "/chi4/time"), std::vector<double>{100.5});
  const std::string p = "/observables/displacement";
  EXPECT_EQ(h5read::shape(f, p + "/p/value"), (Shape{1, 2, 2, 3}));
  EXPECT_EQ(h5read::shape(f, p + "/count/value"), (Shape{1, 2, 2, 3}));
  EXPECT_EQ(h5read::shape(f, p + "/gauss_d/value"), (Shape{1, 2, 2}));
  EXPECT_EQ(h5read::read<double>(f, p + "/gauss_d/value"), (std::vector<double>{0, 1, 10, 11}));
  EXPECT_EQ(h5read::shape(f, p + "/lag_time/value"), (Shape{1, 2}));
  EXPECT_EQ(h5read::shape(f, p + "/tau_alpha/value"), Shape{1});
  EXPECT_EQ(Attr(f, "/", "messages_rejected_recorder").values<int64_t>(), std::vector<int64_t>{2});
  EXPECT_NE(Attr(f, "/", "last_rejection_recorder").strings().at(0).find("frame_index 3"), std::string::npos);
  std::remove(path.c_str());
}

// The sim fails before its first frame: the nodes' final results carry
// frame_index -1 (no frame yet); they count as final, make no record, and
// are not rejected.
TEST(RunRecorder, FailedSimSettlesButIsIncomplete) {
  const std::string path = temp_file("failed");
  dynhet::RunRecorder rec(path, "test");
  ASSERT_TRUE(rec.on_run(run_info()));
  auto s = sim(1.0, "failed", 100, 0);
  s.message = "boom";
  rec.on_sim_status(s);
  for (double a : {0.6, 1.8}) EXPECT_TRUE(rec.on_result(overlap(a, true, -1)));
  rec.on_node_status(node(1.5, "failed", 0));
  EXPECT_TRUE(rec.completion().settled());
  EXPECT_EQ(rec.messages_rejected(), 0);
  const auto missing = rec.finish();
  ASSERT_FALSE(missing.empty());
  EXPECT_EQ(missing[0], "sim: failed (boom)");
  EXPECT_EQ(missing[1], "overlap node: failed");
  h5read::File f(path);
  EXPECT_FALSE(h5read::exists(f, "/observables/overlap/a0.6/q"));
  EXPECT_FALSE(h5read::exists(f, "/observables/sim"));
  EXPECT_TRUE(h5read::exists(f, "/observables/overlap/a0.6/lag_time"));
  std::remove(path.c_str());
}

// complete means complete: a node that says done but lost a frame (or
// never completed one) computed its results from fewer frames: the file
// is incomplete and says which node and how many. A "done" of the sim
// followed by a live status (a forgery, then the sim's own) is not the end.
TEST(RunRecorder, ANodeThatLostFramesMakesTheFileIncomplete) {
  const std::string path = temp_file("lost");
  dynhet::RunRecorder rec(path, "test");
  ASSERT_TRUE(rec.on_run(run_info()));
  rec.on_sim_status(sim(0.5, "done", 0.5)); // forged, early
  EXPECT_TRUE(rec.completion().sim_ended());
  rec.on_sim_status(sim(0.9, "production", 0.9)); // the sim goes on
  EXPECT_FALSE(rec.completion().sim_ended());
  rec.on_sim_status(sim(1.0, "done", 100));
  for (double a : {0.6, 1.8}) rec.on_result(overlap(a, true, 2));
  auto n = node(1.5, "done", 2);
  n.frames_lost = 1;
  rec.on_node_status(n);
  EXPECT_TRUE(rec.completion().settled());
  const auto missing = rec.finish();
  std::string all;
  for (const auto& m : missing) all += m + "; ";
  EXPECT_NE(all.find("overlap node: 2 of 3 frames whole, 1 lost"), std::string::npos) << all;
  EXPECT_EQ(all.find("sim:"), std::string::npos) << all; // the sim's own "done" stands
  std::remove(path.c_str());
}

} // namespace

// The fit-range scan of an S4 message is [grid][range]: recorded with that
// shape, and a message whose scan does not fill n_grids x n_scan (a hostile
// or broken sender) is rejected and counted, not written.
TEST(RunRecorder, S4RangeScanKeepsItsShapeAndAMismatchIsRejected) {
  const std::string path = temp_file("s4scan");
  dynhet::RunRecorder rec(path, "test");
  auto info = run_info();
  info.observables = {"s4"};
  info.keep_frames = false;
  ASSERT_TRUE(rec.on_run(info));
  auto m = s4(0.6, false, 1);
  m.n_scan = 3, m.scan_qxi_max = {0.5, 1, 2};
  m.n_scan_values = 6; // 2 grids x 3 ranges
  for (auto *v : {&m.scan_oz_xi, &m.scan_oz_chi0, &m.scan_a2_xi, &m.scan_a2_chi0}) *v = {0, 1, 2, 10, 11, 12};
  EXPECT_TRUE(rec.on_result(m));
  auto wrong = m;
  wrong.n_scan_values = 4; // 4 values are not 2 x 3
  for (auto *v : {&wrong.scan_oz_xi, &wrong.scan_oz_chi0, &wrong.scan_a2_xi, &wrong.scan_a2_chi0}) v->resize(4);
  wrong.frame_index = 2;
  EXPECT_FALSE(rec.on_result(wrong));
  EXPECT_EQ(rec.messages_rejected(), 1);
  rec.finish("test over");

  h5read::File f(path);
  const std::string g = "/observables/s4/a0.6";
  EXPECT_EQ(h5read::shape(f, g + "/scan_oz_xi/value"), (Shape{1, 2, 3})); // [record][grid][range]
  EXPECT_EQ(h5read::read<double>(f, g + "/scan_a2_chi0/value"), (std::vector<double>{0, 1, 2, 10, 11, 12}));
  EXPECT_EQ(h5read::read<double>(f, g + "/scan_qxi_max/value"), (std::vector<double>{0.5, 1, 2}));
  EXPECT_EQ(h5read::read<int64_t>(f, g + "/xi/step"), std::vector<int64_t>{1}); // the mismatch wrote nothing
  std::remove(path.c_str());
}
