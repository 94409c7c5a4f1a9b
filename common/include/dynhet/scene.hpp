// Scene files: what to simulate and what to measure (TOML, see scenes/).
// parse_scene() refuses unknown keys, wrong types and impossible values
// before anything runs, with a message naming the key, the value and what
// is allowed.
#pragma once

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "dynhet/model.hpp"

namespace dynhet {

struct SceneError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct ScheduleSpec {
  int origins = 10;             // number of time origins t0
  double origin_spacing = 10.0; // dt0 between origins
  double lag_min = 0.1;         // smallest lag tau
  double lag_max = 100.0;       // largest lag tau
  int lags_per_decade = 8;      // log spacing of the lags
  // Lags added to the log-spaced ones (e.g. at a tau_alpha estimate, so
  // that what the paper takes at tau_alpha is taken there, not up to a
  // lag spacing away); within [lag_min, lag_max].
  std::vector<double> extra_lags;
};

struct Scene {
  std::string path;
  std::string text; // the whole file, recorded in the HDF5 parameters
  // What the parse changed from what the file asks, one line each (sub-box
  // sizes that no grid realises): sim_node prints them at the start.
  std::vector<std::string> notes;

  // [system]
  int64_t n_particles = 1000;
  double packing_fraction = 0.7;
  double restitution = 0.9;
  double radius_ratio = kPaperRadiusRatio; // r2 / r1; 1 is monodisperse
  uint64_t seed = 1;
  double tc_time = 0.0; // TC model: collisions within tc of a particle's previous one are elastic; 0 off
  // Start from this state instead of compressing (path, relative to the
  // scene file): a prepared state (sim_node --prepare-only) or an H5MD file
  // with particles/all/position. Empty: compress.
  std::string initial_state;

  // [driving]
  bool driving = true;
  // Kicks per particle per unit time; < 0 means the Enskog collision
  // frequency of the paper, omega = 2.59 phi G_c / sqrt(pi).
  double kick_rate = -1.0;
  // Pair correlation at contact G_c used in omega; < 0 means the recipe
  // `contact_recipe` names: "mixture" (Jenkins-Mancini g_ij of the binary
  // mixture, averaged over pair types with their Enskog collision weights;
  // model.hpp) or "henderson" ((1 - 7 phi/16)/(1 - phi)^2, monodisperse disks).
  double contact_value = -1.0;
  std::string contact_recipe = "mixture";
  // How kick pairs are drawn: "neighbours" (the second particle within
  // kick_reach of the first's surface) or "any" (engine.cpp, kick_pair).
  std::string kick_pairs = "neighbours";
  double kick_reach = 1.0; // largest surface gap of a neighbour pair, in r1

  // [run]
  double equilibration_time = 100.0;
  double production_time = -1.0; // < 0: exactly what the schedule needs
  // The engine synchronises every particle at multiples of this time (and
  // writes a checkpoint there when asked), so that a resumed run goes on
  // bit for bit like the uninterrupted one.
  double checkpoint_interval = 10.0;
  // Wall-clock seconds between checkpoint cuts (docs/checkpoints.md): 0
  // takes one at every checkpoint_interval; else at the first synchronised
  // time after this many seconds since the last (cuts are only ever taken
  // at those times, so keep checkpoint_interval short in wall time).
  double checkpoint_wall_interval = 0;

  ScheduleSpec schedule;

  // [observables]
  std::vector<std::string> observables{"overlap"};
  std::vector<double> cutoff_a{0.6};
  bool keep_frames = false;
  // Also every displacement observable of the cage-relative displacements
  // dr_i - (mean dr of i's Voronoi neighbours at the origin):
  // overlap, chi4, msd, displacement, s4 and clusters, in groups <name>_cr.
  bool cage_relative = false;
  // The cages: "voronoi" (Voronoi neighbours) or "g_ab" (within the first
  // minima of g_ab, clusters.neighbour_cutoffs if given).
  std::string cage = "voronoi";

  // [overlap]
  int overlap_subbox_particles = 100; // target N = <N_r> per sub-box

  // [chi4]: target N = <N_r> of each sub-box grid; >= n_particles is the whole box
  std::vector<int> chi4_subbox_particles{25, 100, 400, 1600, 6400, 1 << 30};

  // [s4]: the four-point structure factor S4(q,t) (s4_node)
  std::vector<double> s4_lags;          // lag times S4 is computed at (nearest scheduled lag); empty: every lag
  double s4_q_max = 1.0;                // largest |q| (units 1/r1)
  double s4_grid_spacing = 0.0;         // NUFFT grid spacing h; 0: pi / (2 q_max) (oversampling 2)
  int s4_half_width = 4;                // Gaussian half-width in grid points
  std::vector<int> s4_subbox_particles; // sub-box sizes (the whole box is always added); empty: chi4's

  // [clusters]: clusters of slow and fast particles (paper sec. 3.3)
  struct Clusters {
    // The lag t of the clusters: < 0 ("tau_alpha") the scheduled lag nearest
    // (in ln t) the node's running tau_alpha of each cutoff; else the
    // scheduled lag nearest this time.
    double lag = -1.0;
    // r^min_11, r^min_12, r^min_22; empty ("g_ab"): the first minima of the
    // smoothed g_ab(r) of the first `cutoff_frames` origin frames.
    std::vector<double> neighbour_cutoffs;
    int cutoff_frames = 1;
    double gr_r_max = 8.0;      // g_ab(r) on [0, gr_r_max) (at most box/2) ...
    double gr_bin = 0.05;       // ... in bins of this width
    double gr_smoothing = 0.1;  // Gaussian width of the smoothing before the minimum is sought
    int bins_per_decade = 5;    // log bins of N_c for P(N_c) and the R_g - N_c bins
    std::vector<int64_t> power_law_sizes{1, 100}; // N_c range of the kappa fit (slow clusters)
    int min_bin_count = 5;      // bins with fewer clusters are left out of the fits
    int fractal_min_size = 10;  // smallest N_c in the d_f fit
    int error_blocks = 20;      // errors from at most this many blocks of consecutive origins
  } clusters;

  // [msd]: the instantaneous fastest and slowest subsets (paper fig. MSD)
  struct Msd {
    double fraction_all = 0.1;   // fastest / slowest 10% of all particles
    double fraction_small = 0.2; // fastest / slowest 20% of the small ones
    // F_s(q, t) at q = 2 pi / sigma_11, 2 pi / sigma_12, 2 pi / sigma_22
    // (fs = true) and at these wave numbers too (units 1/r1). Each q costs
    // one Bessel J0 per particle and pair (about 70 ns: docs/analysis.md).
    bool fs = true;
    std::vector<double> fs_q;
  } msd;

  // [displacement]: P(dx, t) of x displacements with Gaussian and
  // exponential-tail fits (paper sec. 3.2, fig. "tails")
  struct Displacement {
    // The lags: the scheduled lags nearest these multiples of tau_alpha
    // (the paper's 0.01, 1 and 8.5 tau_alpha) and nearest these times.
    std::vector<double> lags_tau_alpha{0.01, 1.0, 8.5};
    std::vector<double> lags;
    double x_max = 10.0;     // histogram over -x_max <= dx < x_max ...
    double bin_width = 0.05; // ... in bins of this width
    double tail_sigmas = 2.0; // exponential tail over |dx| >= tail_sigmas sqrt(<dx^2>)
    int min_bin_count = 5;    // bins with fewer displacements stay out of the fits
    int error_blocks = 20;    // errors: jackknife over at most this many blocks of origins
    int bins() const { return static_cast<int>(std::lround(2 * x_max / bin_width)); }
  } displacement;

  // [bond_breaking]: bonds r_ij < a1 sigma_ij at t0, broken at r_ij > a2 sigma_ij
  struct BondBreaking {
    double a1 = 1.1;
    double a2 = 1.5;
  } bond_breaking;

  // [transport]
  int chunk_particles = 8192; // 16 bytes each: 128 KiB of positions

  bool wants(const std::string& observable) const;
  // The observables the run computes: those named, and with cage_relative
  // the "<name>_cr" of each that has a cage-relative version.
  std::vector<std::string> computed_observables() const;
};

// Parse and validate a scene given its text; `origin` names it in errors.
Scene parse_scene_text(const std::string& text, const std::string& origin);
// Read the file and parse it.
Scene parse_scene_file(const std::string& path);

// The scene as TOML with every key written out: the defaults filled in and
// the production time the schedule needs; it reads back as the same scene.
// Keys and defaults come from one description (common/scene_keys.cpp).
std::string scene_toml(const Scene& s);
// What the simulator derives from a scene, as the TOML table [model] (not a
// scene table): the species' radii and masses, the box, G_c, the Enskog
// collision frequency, the kick rate and amplitude the engine is given
// (model.hpp's formulas), the number of frames and the simulated time.
std::string model_toml(const Scene& s);
// Every key of every table with its default, the values allowed and its
// meaning, as Markdown tables (the reference in docs/scenes.md).
std::string scene_reference_markdown();
// Every key as "table.key", table by table.
std::vector<std::string> scene_key_names();

// G_c of the scene: its number, or its recipe at its phi and radius ratio.
double scene_contact_value(const Scene& s);
// Kicks per particle per unit time: the scene's number, or the paper's
// omega_coll = 2.59 phi G_c / sqrt(pi) with scene_contact_value().
double scene_kick_rate(const Scene& s);

// Observables this build knows how to compute: those declared in
// lcmtypes/*.lcm (dynhet/observables.hpp).
const std::vector<std::string>& known_observables();

// Whether an observable has a cage-relative version ("overlap" -> "overlap_cr").
bool has_cage_relative(const std::string& observable);

// The node that computes an observable (a "<name>_cr" too, beside <name>),
// its declaration's @node: Q(t), chi4(t), the MSD and P(dx, t)
// come from the same pass over the displacements of the same (origin, lag)
// pairs, so one node, "overlap", serves all four (one pass, one copy of the
// frames). S4(q,t) has its own node, "s4" (an FFT per pair and grid: its own
// core), and so have the clusters.
std::string node_of(const std::string& observable);
// The executables a list of observables needs ("overlap_node", ...), each once.
std::vector<std::string> nodes_for(const std::vector<std::string>& observables);

} // namespace dynhet
