// H5mdWriter round trip: write a small run, read it back with the HDF5 C
// API, and compare exactly (positions: to rounding, via position + image L).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "dynhet/h5md.hpp"
#include "h5_read.hpp"

namespace {

using h5read::Attr;
using Shape = std::vector<hsize_t>;

std::string temp_file(const std::string &name) {
  return ::testing::TempDir() + "dynhet_" + std::to_string(getpid()) + "_" + name + ".h5";
}

const char *kScene = R"(title = "round trip"
[system]
n_particles = 1000
packing_fraction = 0.7
driving = true
[schedule]
lags = [0.1, 1, 10.5]
counts = [1, 2, 3]
flags = [true, false]
empty = []
[observables]
names = ["overlap", "chi4"]
[a.b]
x = 1.5
)";

constexpr double kBox = 10.0;
constexpr int kN = 4;

// Three frames of unwrapped positions, with images of both signs and
// coordinates on and a hair off the box edges.
std::vector<std::vector<double>> unwrapped_frames() {
  std::vector<std::vector<double>> f = {{1, 2, 9.5, 0.5, -0.5, 10.0, 25.0, -13.7},
                                        {-1e-17, 3, 10 - 1e-15, 20.0000001, -30.25, 0, 1e3 + 0.1, -1e3 - 0.1},
                                        {}};
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-50, 50);
  for (int i = 0; i < 2 * kN; ++i) f[2].push_back(u(rng));
  return f;
}

struct Written {
  std::string path;
  std::vector<std::vector<double>> frames = unwrapped_frames();
  std::vector<std::vector<double>> q = {{1, 0.9, 0.5}, {1, 0.8, 0.4}, {1, 0.7, 0.3}, {1, 0.6, 0.2}};
  std::vector<double> tau = {NAN, 3.5, 3.25, 3.125};
  std::vector<int32_t> whole = {1, 2, 3, 4};
  std::vector<int64_t> collisions = {int64_t{1} << 40, (int64_t{1} << 40) + 1, 5, 6};
};

Written write_small_run() {
  Written w;
  w.path = temp_file("roundtrip");
  dynhet::H5mdWriter h(w.path, "test creator", "9.9", "tester", "tester@example.org");
  h.write_parameters(kScene);
  h.set_particles("all", kBox, std::vector<int8_t>{0, 1, 1, 0});
  for (int f = 0; f < 3; ++f) h.append_frame(10 * f, 0.5 * f, w.frames[f]);
  for (int r = 0; r < 4; ++r) {
    h.append_observable("overlap/a0.6/q", 100 + r, 1.5 * r, w.q[r]);
    h.append_observable("overlap/a0.6/tau_alpha", 100 + r, 1.5 * r, &w.tau[r], 1);
    h.append_observable("nodes/x/frames_whole", r, 0.25 * r, &w.whole[r], 1);
    h.append_observable("sim/n_collisions", r, 0.25 * r, &w.collisions[r], 1);
  }
  h.write_fixed("overlap/a0.6/lag_time", std::vector<double>{0.1, 1, 10});
  h.set_attribute("", "complete", 1);
  h.set_attribute("observables/overlap/a0.6", "subbox_particles", 62.5);
  h.close();
  return w;
}

class H5mdRoundTrip : public ::testing::Test {
protected:
  static void SetUpTestSuite() { written_ = new Written(write_small_run()); }
  static void TearDownTestSuite() {
    std::remove(written_->path.c_str());
    delete written_;
  }
  static Written *written_;
  const Written &w() { return *written_; }
};
Written *H5mdRoundTrip::written_ = nullptr;

TEST_F(H5mdRoundTrip, H5mdGroup) {
  h5read::File f(w().path);
  Attr version(f, "/h5md", "version");
  EXPECT_EQ(version.shape(), Shape{2});
  EXPECT_EQ(version.type().cls, H5T_INTEGER);
  EXPECT_EQ(version.type().size, 4u);
  EXPECT_EQ(version.values<int32_t>(), (std::vector<int32_t>{1, 1}));
  EXPECT_EQ(Attr(f, "/h5md/creator", "name").strings().at(0), "test creator");
  EXPECT_EQ(Attr(f, "/h5md/creator", "version").strings().at(0), "9.9");
  EXPECT_EQ(Attr(f, "/h5md/author", "name").strings().at(0), "tester");
  EXPECT_EQ(Attr(f, "/h5md/author", "email").strings().at(0), "tester@example.org");
  // Fixed-length, as H5MD asks (strings() refuses variable-length ones): the string's own size.
  EXPECT_EQ(Attr(f, "/h5md/author", "name").type().cls, H5T_STRING);
  EXPECT_EQ(Attr(f, "/h5md/author", "name").type().size, 6u);
  EXPECT_EQ(Attr(f, "/", "complete").values<int32_t>(), std::vector<int32_t>{1});
}

TEST_F(H5mdRoundTrip, ParametersKeepTextAndTypes) {
  h5read::File f(w().path);
  EXPECT_EQ(h5read::read_string(f, "/parameters/scene_toml"), kScene);
  EXPECT_EQ(Attr(f, "/parameters", "title").strings().at(0), "round trip");

  Attr n(f, "/parameters/system", "n_particles");
  EXPECT_EQ(n.type().cls, H5T_INTEGER);
  EXPECT_EQ(n.type().size, 8u);
  EXPECT_EQ(n.values<int64_t>(), std::vector<int64_t>{1000});
  Attr phi(f, "/parameters/system", "packing_fraction");
  EXPECT_EQ(phi.type().cls, H5T_FLOAT);
  EXPECT_EQ(phi.values<double>(), std::vector<double>{0.7});
  Attr driving(f, "/parameters/system", "driving");
  EXPECT_EQ(driving.type().cls, H5T_ENUM); // h5py reads it as bool
  EXPECT_EQ(driving.stored_values<int8_t>(), std::vector<int8_t>{1});

  EXPECT_EQ(Attr(f, "/parameters/schedule", "lags").values<double>(), (std::vector<double>{0.1, 1, 10.5}));
  Attr counts(f, "/parameters/schedule", "counts");
  EXPECT_EQ(counts.type().cls, H5T_INTEGER);
  EXPECT_EQ(counts.values<int64_t>(), (std::vector<int64_t>{1, 2, 3}));
  EXPECT_EQ(Attr(f, "/parameters/schedule", "flags").stored_values<int8_t>(), (std::vector<int8_t>{1, 0}));
  EXPECT_TRUE(Attr(f, "/parameters/schedule", "empty").is_null());
  EXPECT_EQ(Attr(f, "/parameters/observables", "names").strings(),
            (std::vector<std::string>{"overlap", "chi4"}));
  EXPECT_EQ(Attr(f, "/parameters/a/b", "x").values<double>(), std::vector<double>{1.5});
}

TEST_F(H5mdRoundTrip, BoxAndSpecies) {
  h5read::File f(w().path);
  Attr dim(f, "/particles/all/box", "dimension");
  EXPECT_EQ(dim.shape(), Shape{});
  EXPECT_EQ(dim.values<int32_t>(), std::vector<int32_t>{2});
  EXPECT_EQ(Attr(f, "/particles/all/box", "boundary").strings(),
            (std::vector<std::string>{"periodic", "periodic"}));
  EXPECT_EQ(h5read::read<double>(f, "/particles/all/box/edges"), (std::vector<double>{kBox, kBox}));
  EXPECT_EQ(h5read::dataset_type(f, "/particles/all/species").size, 4u);
  EXPECT_EQ(h5read::read<int32_t>(f, "/particles/all/species"), (std::vector<int32_t>{0, 1, 1, 0}));
}

TEST_F(H5mdRoundTrip, PositionPlusImageIsTheUnwrappedInput) {
  h5read::File f(w().path);
  for (const char *g : {"/particles/all/position", "/particles/all/image"}) {
    const std::string base(g);
    EXPECT_EQ(h5read::shape(f, base + "/value"), (Shape{3, kN, 2}));
    EXPECT_EQ(h5read::read<int64_t>(f, base + "/step"), (std::vector<int64_t>{0, 10, 20}));
    EXPECT_EQ(h5read::read<double>(f, base + "/time"), (std::vector<double>{0, 0.5, 1.0}));
  }
  // image shares position's step and time: hard links to the same datasets.
  for (const char *d : {"step", "time"}) {
    EXPECT_TRUE(h5read::same_object(f, std::string("/particles/all/position/") + d,
                                    std::string("/particles/all/image/") + d))
        << d;
    EXPECT_EQ(h5read::object_info(f, std::string("/particles/all/image/") + d).links, 2u) << d;
  }
  EXPECT_FALSE(h5read::same_object(f, "/particles/all/position/value", "/particles/all/image/value"));
  EXPECT_EQ(h5read::dataset_type(f, "/particles/all/image/value").cls, H5T_INTEGER);
  const auto pos = h5read::read<double>(f, "/particles/all/position/value");
  const auto img = h5read::read<int32_t>(f, "/particles/all/image/value");
  for (int fr = 0; fr < 3; ++fr)
    for (int i = 0; i < 2 * kN; ++i) {
      const size_t k = static_cast<size_t>(fr) * 2 * kN + i;
      const double x = w().frames[fr][i];
      EXPECT_GE(pos[k], 0.0);
      EXPECT_LT(pos[k], kBox);
      EXPECT_NEAR(pos[k] + img[k] * kBox, x, 1e-12 * kBox) << "frame " << fr << " coord " << i;
    }
  // Values away from rounding trouble fold exactly.
  EXPECT_EQ(pos[4], 9.5); // x = -0.5
  EXPECT_EQ(img[4], -1);
  EXPECT_EQ(pos[5], 0.0); // y = 10 = L
  EXPECT_EQ(img[5], 1);
  EXPECT_EQ(pos[6], 5.0); // x = 25
  EXPECT_EQ(img[6], 2);
}

TEST_F(H5mdRoundTrip, ObservableTimeSeries) {
  h5read::File f(w().path);
  const std::string q = "/observables/overlap/a0.6/q";
  EXPECT_EQ(h5read::shape(f, q + "/value"), (Shape{4, 3}));
  std::vector<double> flat;
  for (const auto &r : w().q) flat.insert(flat.end(), r.begin(), r.end());
  EXPECT_EQ(h5read::read<double>(f, q + "/value"), flat);
  EXPECT_EQ(h5read::read<int64_t>(f, q + "/step"), (std::vector<int64_t>{100, 101, 102, 103}));
  EXPECT_EQ(h5read::read<double>(f, q + "/time"), (std::vector<double>{0, 1.5, 3, 4.5}));

  const std::string tau = "/observables/overlap/a0.6/tau_alpha/value";
  EXPECT_EQ(h5read::shape(f, tau), Shape{4});
  const auto t = h5read::read<double>(f, tau);
  EXPECT_TRUE(std::isnan(t[0]));
  EXPECT_EQ(std::vector<double>(t.begin() + 1, t.end()), (std::vector<double>{3.5, 3.25, 3.125}));

  const std::string whole = "/observables/nodes/x/frames_whole/value";
  EXPECT_EQ(h5read::dataset_type(f, whole).size, 4u);
  EXPECT_EQ(h5read::read<int32_t>(f, whole), w().whole);
  const std::string coll = "/observables/sim/n_collisions/value";
  EXPECT_EQ(h5read::dataset_type(f, coll).size, 8u);
  EXPECT_EQ(h5read::read<int64_t>(f, coll), w().collisions);

  EXPECT_EQ(h5read::read<double>(f, "/observables/overlap/a0.6/lag_time"), (std::vector<double>{0.1, 1, 10}));
  EXPECT_EQ(Attr(f, "/observables/overlap/a0.6", "subbox_particles").values<double>(),
            std::vector<double>{62.5});
}

// Steps strictly increase in every series: a record of an older or equal
// step is dropped, one of the last step replaces the last record when asked.
TEST(H5mdSteps, StrictlyIncreaseAndTheLastWordReplaces) {
  using R = dynhet::H5mdWriter::Recorded;
  using St = dynhet::H5mdWriter::Stamp;
  const std::string path = temp_file("steps");
  {
    dynhet::H5mdWriter h(path, "t", "0");
    const std::vector<double> a{1, 2}, b{3, 4}, c{5, 6}, d{7, 8};
    EXPECT_EQ(h.append_observable("x", St{3, 1.5}, a), R::appended);
    EXPECT_EQ(h.append_observable("x", St{3, 1.5}, b), R::dropped);       // same step, not the last word
    EXPECT_EQ(h.append_observable("x", St{2, 1.0, true}, b), R::dropped); // an older step, even replacing
    EXPECT_EQ(h.append_observable("x", St{5, 2.5}, b), R::appended);
    EXPECT_EQ(h.append_observable("x", St{5, 2.5, true}, c), R::replaced); // the last word of step 5
    EXPECT_EQ(h.append_observable("x", St{6, 3.0, true}, d), R::appended); // a new step is appended
    h.set_particles("all", kBox, std::vector<int32_t>{0, 1});
    EXPECT_EQ(h.append_frame(St{0, 0.0}, {1, 2, 3, 4}), R::appended);
    EXPECT_EQ(h.append_frame(St{0, 0.0}, {5, 6, 7, 8}), R::dropped);
    EXPECT_EQ(h.append_frame(St{1, 0.5, true}, {1, 1, 1, 1}), R::appended);
    EXPECT_EQ(h.append_frame(St{1, 0.5, true}, {2, 2, 2, 2}), R::replaced);
  }
  h5read::File f(path);
  EXPECT_EQ(h5read::read<int64_t>(f, "/observables/x/step"), (std::vector<int64_t>{3, 5, 6}));
  EXPECT_EQ(h5read::read<double>(f, "/observables/x/time"), (std::vector<double>{1.5, 2.5, 3.0}));
  EXPECT_EQ(h5read::read<double>(f, "/observables/x/value"), (std::vector<double>{1, 2, 5, 6, 7, 8}));
  EXPECT_EQ(h5read::read<int64_t>(f, "/particles/all/image/step"), (std::vector<int64_t>{0, 1}));
  EXPECT_EQ(h5read::read<double>(f, "/particles/all/position/value"),
            (std::vector<double>{1, 2, 3, 4, 2, 2, 2, 2}));
  EXPECT_EQ(h5read::read<int32_t>(f, "/particles/all/image/value"),
            (std::vector<int32_t>{0, 0, 0, 0, 0, 0, 0, 0}));
  std::remove(path.c_str());
}

// A record keeps the dimensions it is given; a later record of another shape is refused.
TEST(H5mdShapes, RecordsKeepTheirDimensions) {
  using St = dynhet::H5mdWriter::Stamp;
  const std::string path = temp_file("shapes");
  {
    dynhet::H5mdWriter h(path, "t", "0");
    const std::vector<double> v{0, 1, 2, 3, 4, 5}; // [2][3]
    h.append_observable("m", St{0, 0}, v.data(), {2, 3});
    h.append_observable("m", St{1, 1}, v.data(), {2, 3});
    EXPECT_THROW(h.append_observable("m", St{2, 2}, v.data(), {3, 2}), std::runtime_error);
    const int32_t one = 7;
    h.append_scalar("s", St{0, 0}, one);
    h.append_observable("v1", St{0, 0}, std::vector<int64_t>{9}); // a vector of one stays a vector
    h.write_fixed("grid", std::vector<int32_t>{1, 2, 3, 4, 5, 6}, {3, 2});
    EXPECT_THROW(h.write_fixed("bad", std::vector<int32_t>{1, 2, 3}, {2, 2}), std::runtime_error);
  }
  h5read::File f(path);
  EXPECT_EQ(h5read::shape(f, "/observables/m/value"), (Shape{2, 2, 3}));
  EXPECT_EQ(h5read::read<double>(f, "/observables/m/value"),
            (std::vector<double>{0, 1, 2, 3, 4, 5, 0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(h5read::shape(f, "/observables/s/value"), Shape{1});
  EXPECT_EQ(h5read::shape(f, "/observables/v1/value"), (Shape{1, 1}));
  EXPECT_EQ(h5read::shape(f, "/observables/grid"), (Shape{3, 2}));
  std::remove(path.c_str());
}

// No author given: $DYNHET_AUTHOR, else $USER, else "unknown"; never an email.
TEST(H5mdAuthor, DefaultsFromTheEnvironment) {
  const char *keep_author = std::getenv("DYNHET_AUTHOR"), *keep_user = std::getenv("USER");
  const std::string saved_author = keep_author ? keep_author : "", saved_user = keep_user ? keep_user : "";
  const std::string path = temp_file("author");
  auto author_of = [&] {
    { dynhet::H5mdWriter h(path, "t", "0"); }
    h5read::File f(path);
    EXPECT_FALSE(H5Aexists_by_name(f, "/h5md/author", "email", H5P_DEFAULT) > 0);
    return Attr(f, "/h5md/author", "name").strings().at(0);
  };
  setenv("DYNHET_AUTHOR", "Ada Lovelace", 1);
  setenv("USER", "ada", 1);
  EXPECT_EQ(author_of(), "Ada Lovelace");
  unsetenv("DYNHET_AUTHOR");
  EXPECT_EQ(author_of(), "ada");
  unsetenv("USER");
  EXPECT_EQ(author_of(), "unknown");
  if (keep_author) setenv("DYNHET_AUTHOR", saved_author.c_str(), 1);
  if (keep_user) setenv("USER", saved_user.c_str(), 1);
  std::remove(path.c_str());
}

TEST(H5mdErrors, NameThePathAndLeaveTheFileUsable) {
  try {
    dynhet::H5mdWriter bad("/nonexistent-dir/x.h5", "t", "0");
    FAIL() << "no exception";
  } catch (const std::runtime_error &e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.h5"), std::string::npos) << e.what();
  }

  const std::string path = temp_file("errors");
  {
    dynhet::H5mdWriter h(path, "t", "0");
    EXPECT_THROW(h.append_frame(0, 0, {1, 2}), std::logic_error);
    const double v[3] = {1, 2, 3};
    h.append_observable("x", 0, 0, v, 3);
    try {
      h.append_observable("x", 1, 1, v, 2);
      FAIL() << "no exception";
    } catch (const std::runtime_error &e) {
      EXPECT_NE(std::string(e.what()).find("observables/x"), std::string::npos) << e.what();
    }
    h.append_observable("x", 1, 1, v, 3);
    EXPECT_THROW(h.write_parameters("a = [1,"), std::runtime_error);
  }
  h5read::File f(path);
  EXPECT_EQ(h5read::shape(f, "/observables/x/value"), (Shape{2, 3}));
  EXPECT_EQ(h5read::shape(f, "/observables/x/step"), Shape{2});
  EXPECT_EQ(h5read::read_string(f, "/parameters/scene_toml"), "a = [1,");
  std::remove(path.c_str());
}

} // namespace
