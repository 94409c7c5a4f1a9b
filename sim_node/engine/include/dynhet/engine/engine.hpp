// Event-driven molecular dynamics of the paper's driven granular disks.
//
// State as flat arrays; each particle carries its own clock (position at
// its local time t, advanced only when the particle takes part in an
// event). Neighbours come from per-particle neighbour lists with a skin
// (Donev, Torquato and Stillinger, J. Comput. Phys. 202, 737 (2005)): the
// list of i was built when i stood at its centre c_i and holds every j with
// |c_i - c_j| <= sigma_ij + skin; while each stays within skin / 2 of its
// centre, no pair outside the lists can touch. Lists are symmetric. Leaving
// that disc is i's "rebuild" event: only i's list is rebuilt, from a cell
// grid over the centres. An event costs O(1) work, calendar included.
//
// Each particle holds one event: the earliest of its own predictions (a
// collision with a partner, or its rebuild). A collision predicted with
// partner j is stale once j's collision counter has moved on, and i is then
// predicted again when it comes up. A prediction does not touch the
// neighbours' events: a collision of i and j that comes first is always
// held by whichever of them was predicted last (at that prediction both
// trajectories were final and the pair listed, and nothing of either comes
// up before it, or it would have been predicted again), so it is never
// lost; handing it to the other one as well only makes work (calendar
// updates, and stale events when the first one's plans change).
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "dynhet/engine/calendar.hpp"
#include "dynhet/engine/collision.hpp"
#include "dynhet/engine/memory.hpp"
#include "dynhet/engine/rng.hpp"
#include "dynhet/engine/rows.hpp"
#include "dynhet/model.hpp"

namespace dynhet::engine {

struct PairBlock; // a particle and a block of its neighbours, as the pair tests read them (engine.cpp)

// How the two particles of a kick are drawn (engine.cpp, kick_pair, says
// why neighbours are the default).
enum class KickPairs {
  neighbours, // the first uniform, the second uniform among those within kick_reach of it
  any,        // two distinct particles uniform over the whole system
};

struct Params {
  long n_particles = 1000;
  double packing_fraction = 0.7;
  double restitution = 1.0;  // eps
  double radius_ratio = kPaperRadiusRatio; // r2 / r1
  uint64_t seed = 1;
  bool driving = false;
  double kick_rate = 0.0; // kicks per particle per unit time (a pair kick counts for both)
  KickPairs kick_pairs = KickPairs::neighbours;
  // Neighbour pairs: the largest gap between the two surfaces, |r_i - r_j|
  // - sigma_ij, in small radii (the first minimum of g_ab lies about one
  // small radius beyond contact at phi = 0.6-0.8: docs/engine.md).
  double kick_reach = 1.0;
  // TC model against inelastic collapse: a collision within tc of either
  // particle's previous collision is elastic. 0: off.
  double tc = 0.0;
  // Width of the neighbour-list skin, in small radii (the small radius is
  // the unit of length); 0 picks auto_skin(packing_fraction). Only speed
  // depends on it (bench_engine --skin).
  double skin = 0;
  // Neighbour kick pairs: the second particle drawn from the first's kick
  // list (false, the default: rejection from a superset, docs/engine.md) or
  // by a search of the 3 x 3 cells around it (true: the earlier engine's,
  // kept as the reference the tests and bench_engine --kick-search compare
  // with). Both are uniform over the same partners; the trajectories differ.
  bool kick_search_cells = false;
};

// Fastest skin at N = 10^5 (bench_engine --skin, docs/engine.md), in small
// radii: 3.0 up to phi = 0.30, 2.5 at 0.50, 2.0 at 0.60, 1.8 at 0.70, 1.4
// at 0.78, 1.1 at 0.805, linear between and on to 0.9 from phi = 0.825.
// Denser packings rattle in smaller cages, so a thinner skin is left as
// rarely; a thicker one lists more neighbours (and lists longer than 15
// double the memory they take).
inline double auto_skin(double phi) {
  constexpr int k = 7;
  constexpr double p[k] = {0.30, 0.50, 0.60, 0.70, 0.78, 0.805, 0.825}, s[k] = {3.0, 2.5, 2.0, 1.8, 1.4, 1.1, 0.9};
  if (phi <= p[0]) return s[0];
  for (int i = 1; i < k; ++i)
    if (phi <= p[i]) return s[i - 1] + (phi - p[i - 1]) / (p[i] - p[i - 1]) * (s[i] - s[i - 1]);
  return s[k - 1];
}

// The paper's system: radius ratio kPaperRadiusRatio, kicks (if driven) to neighbour
// pairs at the Enskog frequency with the mixture's contact value.
inline Params paper_params(long n, double phi, double eps, bool driven, KickPairs pairs = KickPairs::neighbours) {
  Params p;
  p.n_particles = n;
  p.packing_fraction = phi;
  p.restitution = eps;
  p.driving = driven;
  p.kick_rate = enskog_frequency(phi, mixture_contact_value(phi, p.radius_ratio));
  p.kick_pairs = pairs;
  return p;
}

struct Counters {
  int64_t collisions = 0;
  int64_t kicks = 0;
  int64_t rebuilds = 0; // neighbour lists rebuilt one at a time (particle left its skin)
  int64_t stale = 0; // events found outdated and predicted again
  int64_t tc = 0;    // collisions made elastic by the TC model
  // Collision virial sum over collisions of sigma_ij * J_ij, J the normal
  // momentum transfer: P A = K + virial / (2 dt) in 2D (see reduced_pressure).
  double virial = 0;
  // Neighbour kick pairs: first particles drawn again because none lay in
  // reach of the one drawn, and kicks that found no neighbour pair in
  // kMaxKickDraws draws and took a pair from the whole system instead.
  int64_t kick_redraws = 0;
  int64_t kick_far = 0;
  template <class Ar> void state(Ar& ar) { ar(collisions, kicks, rebuilds, stale, tc, virial, kick_redraws, kick_far); }
};

// Reduced pressure Z = P A / (N T) from the collision virial accumulated
// over a time dt at kinetic energy per particle ke, as the canonical
// ensemble at temperature T defines it, so that it compares with
// equations of state at the same N (docs/analysis.md, "Which temperature").
// Every run is in the centre-of-mass frame: collisions and kicks conserve
// momentum, which starts at zero. Equipartition over the 2N - 2 degrees of
// freedom that this leaves gives T = K / (N - 1) (K the total kinetic
// energy), and a pair's relative velocity has exactly the variance 2T
// (per unit mass) it has in the canonical ensemble, so the collision term
// virial / (2 dt N T) is the canonical one (hard disks: the configurations
// are sampled uniformly either way). The kinetic term is the canonical N T,
// not the N - 1 free momenta's K: the frozen centre of mass would carry
// the missing T. So Z = 1 + (N - 1)/N virial / (2 dt K).
// With T = K / N, Z comes out high by about (Z - 1)/N (0.1% at N = 1000);
// with the mechanical P A = K + virial / (2 dt) of this fixed-momentum
// system over N T, low by exactly 1/N (-0.0045 at N = 224). Both are
// resolved by high-precision data (bench/pressure_reference.py).
inline double temperature(double ke_per_particle, long n) { return ke_per_particle * n / (n - 1.0); }
// Z from x = virial / (2 dt K), or from a mean of such ratios (sim_node
// averages the virial and K dt over blocks first); its error is (N-1)/N
// times x's.
inline double reduced_pressure_from_ratio(double x, long n) { return 1.0 + (n - 1.0) / n * x; }
inline double reduced_pressure(double virial, double dt, long n, double ke_per_particle) {
  return reduced_pressure_from_ratio(virial / (2.0 * n * ke_per_particle * dt), n);
}

// Everything needed to continue a run exactly: written to checkpoints.
// Taken right after synchronize(), when every particle is at time(). Times
// are kept relative to `time` as the engine holds them (adding and
// subtracting `time` again would round).
struct State {
  double time = 0;
  double kick_in = 0; // time until the next kick; infinite if not driven
  std::vector<double> x, y, vx, vy;
  std::vector<double> last_collision; // minus the time since each particle's last collision (TC model on; else -inf)
  std::vector<int32_t> image_x, image_y;
  std::vector<uint64_t> collision_count;
  uint64_t rng[4] = {0, 0, 0, 0};
  Counters counters;
  // Checkpoint cuts (dynhet/state_archive.hpp).
  template <class Ar> void state(Ar& ar) {
    ar(time, kick_in, x, y, vx, vy, last_collision, image_x, image_y, collision_count, rng, counters);
  }
};

// Everything the engine holds at any moment of a run, by storage slot: the
// particles at their own local times with their pending events, the list
// centres, the neighbour and kick lists and the cells with their members
// in order (a rebuild lists candidates in cell order, and a kick draws its
// partner by its place in a kick list). Engine::restore_snapshot() from it
// continues bit for bit from between two synchronised times, so a run
// stops in seconds (docs/checkpoints.md). The calendar alone is built
// anew: it returns events in the order (time, slot) whatever its buckets
// hold. The particle records are this build's bytes (a checkpoint part of
// another build is refused anyway). The lists, cells and images are packed
// (Rows::save_packed: small differences in 7-bit groups), about 2 bytes a
// list member and 1 an image where plain int32 take 4: the stop writes this
// whole snapshot, and its size is most of what a stop waits for.
struct Snapshot {
  double now = 0, offset = 0, kick_time = 0;
  int64_t events_since_rebase = 0;
  std::vector<uint8_t> particles;
  std::vector<int32_t> id;
  std::vector<uint8_t> images;        // image_x, image_y of each slot, zigzag varints
  std::vector<double> last_collision; // empty with the TC model off (every one is -inf then)
  std::vector<double> centres;        // x0 y0 x1 y1 ...
  // Rows::save_packed. A kick list holds only the kick candidates its
  // neighbour list does not (Engine::kick_lists()).
  std::vector<uint8_t> neighbours, kick_lists, cells;
  uint64_t rng[4] = {0, 0, 0, 0};
  Counters counters;
  size_t bytes() const {
    return particles.size() + images.size() + neighbours.size() + kick_lists.size() + cells.size() +
           4 * id.size() + 8 * (last_collision.size() + centres.size()) + 256;
  }
  template <class Ar> void state(Ar& ar) {
    ar(now, offset, kick_time, events_since_rebase, particles, id, images, last_collision, centres, neighbours,
       kick_lists, cells, rng, counters);
  }
};

class Engine {
public:
  explicit Engine(const Params& p);

  // Random non-overlapping disks at packing fraction min(phi, 0.35), then
  // Lubachevsky-Stillinger growth: all radii grow linearly in time during
  // elastic EDMD (velocities rescaled to kinetic energy 1 every few
  // collisions per particle) until they reach their true size. Finally
  // velocities are drawn with kinetic energy 1 per particle and the clock is
  // set to 0. `progress(phi_now)` is called now and then. Throws
  // std::runtime_error if the growth stalls (the packing jams).
  void prepare(const std::function<void(double phi_now)>& progress = {});
  // prepare() in its three steps: compress() (positions at the scene's phi,
  // the clock at 0), thermalize(1.0), begin() (restitution and driving on,
  // the first kick drawn, lists and events). A prepared state is the
  // state() between thermalize and begin: start_prepared() from it gives
  // the run prepare() would have given, bit for bit, whatever restitution
  // or driving the run has.
  void compress(const std::function<void(double phi_now)>& progress = {});
  void begin();
  // Positions (by particle id, in the box) of a state from elsewhere:
  // throws std::invalid_argument if one is not finite or any pair overlaps
  // by more than 1e-9 of its contact distance. Velocities: thermalize().
  void place(const std::vector<double>& x, const std::vector<double>& y);
  // Continues from a prepared state (time 0): positions, velocities and
  // random state as saved, then begin().
  void start_prepared(const State& s);

  // Maxwell-Boltzmann velocities, zero total momentum, kinetic energy per
  // particle exactly `energy` (the paper's time unit: 1 at t = 0).
  void thermalize(double energy = 1.0);

  // Brings every particle to the current time, rebuilds the cells and
  // predicts every event afresh. A run that passes through the same
  // synchronised times continues bit for bit like one restored from a
  // state() taken there; sim_node synchronises at fixed times for that.
  void synchronize();
  State state() const; // call right after synchronize()
  // Continues from a state (after prepare() was not called). Throws
  // std::invalid_argument if it does not fit these parameters.
  void restore(const State& s);
  const Params& params() const { return p_; }
  // The whole engine at any time of a run (begun: not while compressing),
  // and back: the run continues as if never stopped. restore_snapshot()
  // throws std::invalid_argument if the snapshot does not fit these
  // parameters or is not self-consistent.
  Snapshot snapshot() const;
  void restore_snapshot(const Snapshot& s);

  // Processes every event up to time t (absolute), then the system is at t.
  // Stops early, at an event, after max_events; returns true if t was reached.
  bool run_until(double t, int64_t max_events = INT64_MAX);

  double time() const { return offset_ + now_; }
  long size() const { return n_; }
  // Mean length of the neighbour lists, for the benchmark.
  double mean_neighbours() const;
  // Bytes held by the engine's arrays (their capacities), for the benchmark.
  size_t memory_bytes() const;
  double box_length() const { return box_; }
  double packing_fraction() const;
  double radius(int species) const { return radius_[species]; }
  double mass(int species) const { return mass_[species]; }
  const std::vector<uint8_t>& species() const { return species_by_id_; } // by particle id
  const Counters& counters() const { return count_; }
  double kinetic_energy_per_particle() const;
  void momentum(double& px, double& py) const;
  // The particle ids the next kick would take if it came now (positions as
  // they are now), and how many first particles it would draw in vain.
  struct KickPair {
    long i, j;
    int redraws;
  };
  KickPair next_kick_pair() const;
  static constexpr int kMaxKickDraws = 64;

  // Unwrapped positions at the current time, x0 y0 x1 y1 ...
  void unwrapped_positions(std::vector<double>& xy) const;

  // Largest overlap of any pair, (sigma - d) / sigma, or <= 0 if none; an
  // O(N) scan over the cell grid.
  double max_overlap() const;
  // Smallest d / sigma over all neighbouring pairs.
  double min_gap_ratio() const;
  // Whether the pair tests run as AVX2 vector code (pair_block_avx2), or
  // as the portable code that gives the same bits: the vector code where
  // the processor has AVX2, unless the environment sets
  // DYNHET_PORTABLE_PAIR_TESTS when the engine is made (the test that
  // compares the two sets it).
  bool vector_pair_tests() const { return vector_pair_tests_; }

private:
  // What predicting a collision reads of a neighbour, and what its own
  // event needs, in one cache line: an event coming up costs one miss for
  // the particle, not two.
  struct alignas(64) Particle {
    double x, y, vx, vy, t; // position (in the box) at local time t, velocity
    double event_time;      // its next event (the calendar reads it here)
    uint64_t coll : 63;     // collision counter (also counts kicks): staleness of predictions
    uint64_t species : 1;
    // The next event: a collision with `partner`, or (partner < 0) the
    // rebuild of its list. `partner_seen` is the low 32 bits of the
    // partner's counter when it was predicted: the prediction is stale once
    // they differ. (It would pass as current only if the partner made a
    // multiple of 2^32 = 4.3e9 collisions in between.)
    int32_t partner;
    uint32_t partner_seen;
  };
  static constexpr int32_t kRebuild = -1;
  static uint32_t seen(uint64_t coll) { return static_cast<uint32_t>(coll); }

  void build_cells();
  void build_lists(); // every list afresh, centres at the positions now (all synchronised)
  void clear_events();
  void predict(int i);
  // The pair tests of a block of neighbours l[0], ..., l[nk - 1] (nk <= 8):
  // the lane of the earliest collision if it comes before best (which then
  // becomes its time), else -1 (engine.cpp; pair_block_avx2 where the
  // processor has AVX2, the same results).
  int pair_block(const int32_t* l, int nk, PairBlock& blk, double& best) const;
  static int pair_block_avx2(const Particle* part, const int32_t* l, int nk, const double* radius, PairBlock& blk,
                             double& best);
  static bool avx2_gather_fits(); // this processor and this ABI's Particle suit pair_block_avx2
  void prefetch_neighbours(int i) const;
  void sync(int i);
  void collide(int i, int j);
  void rebuild(int i); // i left its skin: new centre, new list
  void wrap(int i);    // back into the box, counting the image
  void kick();
  // The pair of kick number k: two distinct storage slots drawn uniformly,
  // from a hash of the seed and k. It needs no state of its own (the kick
  // count is checkpointed) and is known ahead: its lines are requested
  // when the kick before it is done.
  // Returns how many first particles were drawn in vain (neighbour pairs;
  // kMaxKickDraws: the pair was taken from the whole system).
  int kick_pair(int64_t k, int& i, int& j) const;
  // Hash `which` (0: first particle, 1: second) of draw `draw` of kick k.
  uint64_t kick_hash(int64_t k, int draw, int which) const;
  // Slots within kick reach of slot i's position now, into out (at most
  // kMaxKickCandidates); returns their number.
  static constexpr int kMaxKickCandidates = 512;
  int kick_candidates(int i, int32_t* out) const;
  // Kick candidates (neighbour pairs, in the run): every slot whose list
  // centre is within r_i + r_j + kick_reach + skin of i's, so that they
  // hold everyone within kick reach of i now (centres are within skin / 2
  // of their particles), about twice as many. Those of them that i's
  // neighbour list holds are not kept again: i's kick list (kick_beyond_)
  // holds only the others, and the candidates are the neighbour list
  // followed by the kick list. (Every near pair is kick-near, so each
  // candidate is in one of the two, once.) The second particle is drawn
  // from them and kept if within reach (rejection: uniform over those
  // within reach); after kKickTrials draws in vain all are searched.
  static constexpr int kKickTrials = 8;
  bool kick_lists() const { return neighbour_kicks_ && driving_ && !p_.kick_search_cells; }
  bool kick_near(int i, int j) const;
  bool within_kick_reach(int i, int j) const; // now, by the particles' positions
  int kick_partner(int64_t k, int draw, int i) const; // -1: nobody within reach
  // Whether no kick list repeats a member of its neighbour list, or its own slot.
  bool kick_lists_apart() const;
  void link_kick(int i, int j) { kick_beyond_.push(i, j), kick_beyond_.push(j, i); }
  // Candidate u of i's kick candidates: its neighbour list a, then its kick list b.
  static int32_t kick_candidate(const int32_t* a, const int32_t* b, int u) { return u < a[0] ? a[1 + u] : b[1 + u - a[0]]; }
  void prefetch_list(int i) const;     // i's neighbour list and list centre
  void prefetch_particle(int i) const; // its line, list and centre
  void rebase();
  // Contact distance now, and its growth rate (compression only).
  double sigma(int i, int j) const { return scale() * (radius_[part_[i].species] + radius_[part_[j].species]); }
  double growth(int i, int j) const { return grow_ * (radius_[part_[i].species] + radius_[part_[j].species]); }
  double mass_of(int i) const { return mass_[part_[i].species]; }
  void set_event_time(int i, double t) {
    if (t == part_[i].event_time) return; // its entry in the calendar stands
    part_[i].event_time = t;
    cal_.push(i, t);
  }
  // What the calendar reads of the particles: their event times.
  struct EventTimes {
    const Particle* p;
    double operator()(int i) const { return p[i].event_time; }
    void prefetch(int i) const { __builtin_prefetch(&p[i]); }
  };
  EventTimes event_times() const { return EventTimes{part_.data()}; }
  double scale() const { return scale0_ + grow_ * now_; }
  void rescale_velocities(double energy);
  void start_run(); // restitution, driving on; the first kick drawn
  int cell_index(int cx, int cy) const { return cy * nc_ + cx; }
  // Cell (cx, cy) of a position in the box.
  int cell_coord(double x) const { return std::clamp(static_cast<int>(x / cw_), 0, nc_ - 1); }
  // The 3 x 3 cells around (cx, cy), periodic, row by row from (-1, -1).
  void cells_around(int cx, int cy, int out[9]) const;
  const int32_t* list(int i) const { return nbr_.row(static_cast<size_t>(i)); }
  void link(int i, int j) { nbr_.push(i, j), nbr_.push(j, i); } // i and j list each other
  // Whether the centres of i and j are close enough to be listed.
  bool near(int i, int j) const;
  // Nearest periodic image of a separation component.
  double min_image(double d) const { return nearest_image(d, box_, half_box_); }
  void cell_insert(int i, int cx, int cy);
  void cell_remove(int i);
  void clear_cells();
  void place_random(double scale);
  // Renumbers the storage slots in cell order (ties by particle id), so
  // that neighbours sit close in memory; then rebuilds the cells.
  void reorder();

  Params p_;
  long n_;
  double box_, half_box_;
  double radius_[2], mass_[2];
  // Radii are scale() * radius_; scale() = scale0_ + grow_ * now_ grows
  // only while compressing.
  double scale0_ = 1.0, grow_ = 0.0;
  double eps_;

  // Per-particle arrays are indexed by storage slot; id_[slot] is the
  // particle's id (its index in frames and checkpoints).
  std::vector<Particle, BigArrayAlloc<Particle>> part_;
  std::vector<uint8_t> species_by_id_;
  std::vector<int32_t> id_;
  // Species by slot, for the list criterion: a rebuild tests about 40
  // candidates, most of them not listed, and this spares reading their
  // particles' lines.
  std::vector<uint8_t> species_;
  std::vector<int32_t> image_x_, image_y_;
  std::vector<double> last_collision_; // internal time of each particle's last collision; kept only with the TC model on

  // Neighbour lists: row i holds the slots of i's neighbours, and in its
  // head i's list centre (where i was when the list was made): a
  // prediction's skin exit and its pair tests read one line of the list.
  struct Centre {
    double x, y;
  };
  Rows nbr_{sizeof(Centre) / sizeof(int32_t)};
  Centre centre(int i) const { return nbr_.head<Centre>(static_cast<size_t>(i)); }
  void set_centre(int i, double x, double y) { nbr_.set_head(static_cast<size_t>(i), Centre{x, y}); }
  // Kick lists (kick_lists()): row i holds i's kick candidates beyond its
  // neighbour list. About 5 at phi = 0.78, so a row stays one line.
  Rows kick_beyond_;
  double skin_;         // absolute
  double list_scale_ = 1; // radii scale the lists hold for (below 1 only while compressing)
  double list_margin_;  // roundoff allowance in the list criterion

  int nc_ = 0;   // cells per side: nc_compress_ while compressing, nc_run_ in the run
  int nc_compress_ = 0, nc_run_ = 0;
  void use_cells(bool run);
  double cw_ = 0; // cell width
  // Cells over the list centres, as rows (not linked lists): row
  // cell_index(cx, cy) holds the slots of its particles. cell_x_, cell_y_
  // are each particle's cell.
  Rows cells_;
  std::vector<int32_t> cell_x_, cell_y_;

  Calendar cal_;
  double kick_time_ = Calendar::kNever; // the next kick (it comes after a particle's event at the same time)
  bool driving_ = false;
  bool neighbour_kicks_ = false; // driven with KickPairs::neighbours: cells are wider by kick_reach
  double kick_pair_rate_ = 0; // pair kicks per unit time, whole system
  Rng rng_;
  bool vector_pair_tests_ = false;
  // The seed's hash that every kick's draws start from (kick_hash).
  uint64_t kick_key_ = mix64(p_.seed ^ 0x6b69636b70616972ULL);

  double now_ = 0, offset_ = 0;
  int64_t events_since_rebase_ = 0;
  Counters count_;
};

} // namespace dynhet::engine
