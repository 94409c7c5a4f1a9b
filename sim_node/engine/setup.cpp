// How a run starts and stops (engine.hpp, class Engine): velocities,
// random placement and Lubachevsky-Stillinger compression, a state placed
// or restored, synchronisation and the state written out. None of it is
// on the event loop's path (engine.cpp).
#include "dynhet/engine/engine.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "dynhet/engine/collision.hpp"
#include "dynhet/model.hpp"

namespace dynhet::engine {

void Engine::thermalize(double energy) {
  double px = 0, py = 0, mtot = 0;
  for (long i = 0; i < n_; ++i) {
    const double m = mass_of(static_cast<int>(i));
    double gx, gy;
    rng_.normal_pair(gx, gy);
    part_[i].vx = gx / std::sqrt(m);
    part_[i].vy = gy / std::sqrt(m);
    px += m * part_[i].vx;
    py += m * part_[i].vy;
    mtot += m;
  }
  for (long i = 0; i < n_; ++i) part_[i].vx -= px / mtot, part_[i].vy -= py / mtot;
  rescale_velocities(energy);
}

// Random sequential placement with radii scaled by `scale` (cells make each
// trial O(1)).
void Engine::place_random(double scale) {
  scale0_ = scale;
  grow_ = 0;
  now_ = 0;
  clear_cells();
  for (long i = 0; i < n_; ++i) {
    bool placed = false;
    for (int attempt = 0; attempt < 100000 && !placed; ++attempt) {
      const double x = rng_.uniform() * box_, y = rng_.uniform() * box_;
      const int cx = cell_coord(x), cy = cell_coord(y);
      placed = true;
      int around[9];
      cells_around(cx, cy, around);
      for (int a = 0; a < 9 && placed; ++a) {
        const int32_t* c = cells_.row(around[a]);
        for (int k = 1; k <= c[0]; ++k) {
          const int j = c[k];
          const double ddx = min_image(x - part_[j].x), ddy = min_image(y - part_[j].y);
          const double s = sigma(static_cast<int>(i), j);
          if (ddx * ddx + ddy * ddy < s * s) {
            placed = false;
            break;
          }
        }
      }
      if (placed) {
        Particle& p = part_[i];
        p.x = x, p.y = y, p.vx = p.vy = p.t = 0;
        cell_insert(static_cast<int>(i), cx, cy);
      }
    }
    if (!placed) throw std::runtime_error("engine: random placement failed at particle " + std::to_string(i));
  }
}

void Engine::rescale_velocities(double energy) {
  const double f = std::sqrt(energy / kinetic_energy_per_particle());
  for (auto& a : part_) a.vx *= f, a.vy *= f;
}

void Engine::prepare(const std::function<void(double)>& progress) {
  compress(progress);
  thermalize(1.0);
  begin();
}

void Engine::use_cells(bool run) {
  nc_ = run ? nc_run_ : nc_compress_;
  cw_ = box_ / nc_;
}

void Engine::compress(const std::function<void(double)>& progress) {
  use_cells(false);
  const double phi = p_.packing_fraction;
  const double phi_start = std::min(phi, 0.35);
  place_random(std::sqrt(phi_start / phi));
  reorder();
  if (progress) progress(packing_fraction());

  // Grow elastically and without driving, radii scale0_ + grow_ t. The
  // rate is fast while the packing is far below its target and slow (against
  // the thermal speed ~1) near it, so the packing stays a fluid and does not
  // jam early.
  eps_ = 1.0;
  driving_ = false;
  now_ = offset_ = 0;
  thermalize(1.0);
  auto rate = [&] { return packing_fraction() < phi - 0.1 ? 0.01 : 0.002; };
  grow_ = rate();
  clear_events(); // predictions know the growth rate of this round
  while (scale0_ < 1.0) {
    const double t_full = (1.0 - scale0_) / grow_; // radii reach their size
    // About a collision per particle, then back to kinetic energy 1 (growth
    // heats the system) and predict everything again.
    const double t_stop = std::min(t_full, 1.0);
    const bool reached = run_until(offset_ + t_stop, 2 * n_);
    rebase(); // now_ = 0: scale0_ is the scale reached
    if (reached && t_stop == t_full) scale0_ = 1.0;
    grow_ = scale0_ < 1.0 ? rate() : 0.0;
    if (count_.collisions > 20000 * n_)
      throw std::runtime_error("engine: compression stalled at phi = " +
                               std::to_string(packing_fraction()) + " (target " +
                               std::to_string(phi) + "): the packing jams; lower phi");
    rescale_velocities(1.0);
    reorder();
    clear_events();
    if (progress) progress(packing_fraction());
  }
  // Exactly the true radii from here on.
  for (long i = 0; i < n_; ++i) sync(static_cast<int>(i)), part_[i].t = 0;
  grow_ = 0;
  scale0_ = 1.0;
  if (const double ov = max_overlap(); ov > 1e-9)
    throw std::runtime_error("engine: compression left an overlap of " + std::to_string(ov) +
                             " of a contact distance (a bug)");

  // The run proper starts at t = 0 (with kinetic energy 1 per particle:
  // thermalize(), then begin()).
  now_ = offset_ = 0;
  last_collision_.assign(n_, -kNever);
  events_since_rebase_ = 0;
  count_ = Counters{};
  kick_time_ = kNever;
}

void Engine::begin() {
  start_run();
  kick_time_ = driving_ ? now_ + rng_.exponential(kick_pair_rate_) : kNever;
  reorder();
  clear_events();
}

void Engine::place(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() != static_cast<size_t>(n_) || y.size() != static_cast<size_t>(n_))
    throw std::invalid_argument("engine: " + std::to_string(x.size()) + " positions for " + std::to_string(n_) +
                                " particles");
  for (long i = 0; i < n_; ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i]) || x[i] < 0 || x[i] >= box_ || y[i] < 0 || y[i] >= box_)
      throw std::invalid_argument("engine: particle " + std::to_string(i) + " at (" + std::to_string(x[i]) + ", " +
                                  std::to_string(y[i]) + ") is not in the box [0, " + std::to_string(box_) + ")");
  }
  scale0_ = 1.0;
  grow_ = 0.0;
  now_ = offset_ = 0;
  for (long i = 0; i < n_; ++i)
    part_[i] = Particle{x[i], y[i], 0.0, 0.0, 0.0, kNever, 0, species_by_id_[i], kRebuild, 0};
  for (long i = 0; i < n_; ++i) id_[i] = static_cast<int32_t>(i);
  species_ = species_by_id_;
  image_x_.assign(n_, 0);
  image_y_.assign(n_, 0);
  last_collision_.assign(n_, -kNever);
  events_since_rebase_ = 0;
  count_ = Counters{};
  kick_time_ = kNever;
  reorder(); // cells over the positions, for the overlap check
  clear_events();
  if (const double ov = max_overlap(); ov > 1e-9)
    throw std::invalid_argument("engine: the positions overlap: a pair is closer than its contact distance by " +
                                std::to_string(ov) + " of it");
}

void Engine::start_prepared(const State& s) {
  if (s.time != 0.0)
    throw std::invalid_argument("engine: a prepared state is at time 0, this one at " + std::to_string(s.time));
  restore(s);
  begin();
}

void Engine::start_run() {
  use_cells(true); // the caller sorts the particles into them (reorder)
  eps_ = p_.restitution;
  driving_ = p_.driving && p_.kick_rate > 0 && eps_ < 1.0;
  kick_pair_rate_ = 0.5 * p_.kick_rate * n_;
}

void Engine::synchronize() {
  rebase();
  reorder();
  clear_events();
}

State Engine::state() const {
  State s;
  s.time = time();
  s.kick_in = kick_time_ - now_; // now_ is 0 after synchronize()
  s.x.resize(n_), s.y.resize(n_), s.vx.resize(n_), s.vy.resize(n_), s.last_collision.resize(n_);
  s.image_x.resize(n_), s.image_y.resize(n_), s.collision_count.resize(n_);
  for (long k = 0; k < n_; ++k) { // stored by particle id
    const long i = id_[k];
    const double dt = now_ - part_[k].t; // 0 after synchronize()
    s.x[i] = part_[k].x + part_[k].vx * dt;
    s.y[i] = part_[k].y + part_[k].vy * dt;
    s.vx[i] = part_[k].vx;
    s.vy[i] = part_[k].vy;
    s.last_collision[i] = last_collision_[k] - now_;
    s.image_x[i] = image_x_[k];
    s.image_y[i] = image_y_[k];
    s.collision_count[i] = part_[k].coll;
  }
  for (int k = 0; k < 4; ++k) s.rng[k] = rng_.state()[k];
  s.counters = count_;
  return s;
}

void Engine::restore(const State& s) {
  const size_t n = static_cast<size_t>(n_);
  if (s.x.size() != n || s.y.size() != n || s.vx.size() != n || s.vy.size() != n ||
      s.last_collision.size() != n || s.image_x.size() != n || s.image_y.size() != n ||
      s.collision_count.size() != n)
    throw std::invalid_argument("engine: checkpoint holds " + std::to_string(s.x.size()) +
                                " particles, the scene " + std::to_string(n_));
  scale0_ = 1.0;
  grow_ = 0.0;
  offset_ = s.time;
  now_ = 0;
  events_since_rebase_ = 0;
  for (long i = 0; i < n_; ++i) {
    part_[i] = Particle{s.x[i], s.y[i], s.vx[i], s.vy[i], 0.0, kNever, s.collision_count[i], species_by_id_[i],
                        kRebuild, 0};
    last_collision_[i] = s.last_collision[i];
  }
  image_x_ = s.image_x;
  image_y_ = s.image_y;
  for (long i = 0; i < n_; ++i) id_[i] = static_cast<int32_t>(i);
  species_ = species_by_id_;
  rng_.set_state(s.rng);
  count_ = s.counters;
  start_run();
  kick_time_ = s.kick_in;
  reorder(); // the same slot order as the run that wrote the state
  clear_events();
}

} // namespace dynhet::engine

namespace dynhet::engine {

Snapshot Engine::snapshot() const {
  Snapshot s;
  s.now = now_;
  s.offset = offset_;
  s.kick_time = kick_time_;
  s.events_since_rebase = events_since_rebase_;
  s.particles.resize(part_.size() * sizeof(Particle));
  std::memcpy(s.particles.data(), part_.data(), s.particles.size());
  s.id = id_;
  s.images.reserve(2 * static_cast<size_t>(n_));
  auto zigzag = [](int32_t v) { // small of either sign: small unsigned
    const int64_t w = v;
    return (static_cast<uint64_t>(w) << 1) ^ static_cast<uint64_t>(w >> 63);
  };
  for (long i = 0; i < n_; ++i) {
    Rows::put_varint(s.images, zigzag(image_x_[i]));
    Rows::put_varint(s.images, zigzag(image_y_[i]));
  }
  if (p_.tc > 0) s.last_collision = last_collision_;
  s.centres.resize(2 * static_cast<size_t>(n_));
  for (long i = 0; i < n_; ++i) {
    const Centre c = centre(static_cast<int>(i));
    s.centres[2 * i] = c.x, s.centres[2 * i + 1] = c.y;
  }
  nbr_.save_packed(s.neighbours, true);
  if (kick_lists()) kick_beyond_.save_packed(s.kick_lists, true);
  cells_.save_packed(s.cells, false);
  for (int k = 0; k < 4; ++k) s.rng[k] = rng_.state()[k];
  s.counters = count_;
  return s;
}

void Engine::restore_snapshot(const Snapshot& s) {
  const size_t n = static_cast<size_t>(n_);
  auto refuse = [&](const std::string& why) {
    throw std::invalid_argument("engine: a snapshot that does not fit this run: " + why);
  };
  if (s.particles.size() != n * sizeof(Particle) || s.id.size() != n ||
      s.last_collision.size() != (p_.tc > 0 ? n : 0) || s.centres.size() != 2 * n)
    refuse("its arrays are not of " + std::to_string(n) + " particles");
  std::vector<int32_t> image_x(n), image_y(n);
  {
    const uint8_t* p = s.images.data();
    const uint8_t* const end = p + s.images.size();
    auto image = [&](int32_t& out) {
      uint64_t z = 0;
      if (!Rows::get_varint(p, end, z)) refuse("its images are not of " + std::to_string(n) + " particles");
      const int64_t v = static_cast<int64_t>(z >> 1) ^ -static_cast<int64_t>(z & 1);
      if (v < INT32_MIN || v > INT32_MAX) refuse("an image is out of range");
      out = static_cast<int32_t>(v);
    };
    for (size_t k = 0; k < n; ++k) image(image_x[k]), image(image_y[k]);
    if (p != end) refuse("its images are not of " + std::to_string(n) + " particles");
  }
  if (!std::isfinite(s.now) || !std::isfinite(s.offset) || s.events_since_rebase < 0)
    refuse("its clock is not finite");
  start_run();
  scale0_ = 1.0;
  grow_ = 0.0;
  list_scale_ = 1.0;
  now_ = s.now;
  offset_ = s.offset;
  kick_time_ = s.kick_time;
  events_since_rebase_ = s.events_since_rebase;
  std::memcpy(part_.data(), s.particles.data(), s.particles.size());
  std::vector<uint8_t> seen(n, 0);
  for (size_t k = 0; k < n; ++k) {
    const int32_t i = s.id[k];
    if (i < 0 || static_cast<size_t>(i) >= n || seen[i]++) refuse("its ids are not a permutation");
    if (part_[k].species != species_by_id_[i]) refuse("a species differs from the scene's");
    if (part_[k].partner < kRebuild || part_[k].partner >= n_) refuse("a partner is out of range");
    if (!(part_[k].event_time >= now_)) refuse("an event lies in the past");
    species_[k] = species_by_id_[i];
  }
  id_ = s.id;
  image_x_ = std::move(image_x);
  image_y_ = std::move(image_y);
  if (p_.tc > 0) last_collision_ = s.last_collision;
  else last_collision_.assign(n, -kNever);
  const auto limit = static_cast<int32_t>(n_);
  if (!nbr_.load_packed(n, s.neighbours, limit, true)) refuse("its neighbour lists are malformed");
  for (size_t k = 0; k < n; ++k) set_centre(static_cast<int>(k), s.centres[2 * k], s.centres[2 * k + 1]);
  if (!kick_beyond_.load_packed(kick_lists() ? n : 0, s.kick_lists, limit, true))
    refuse("its kick lists are malformed");
  if (kick_lists() && !kick_lists_apart())
    refuse("its kick lists repeat members of the neighbour lists (kick lists that hold every kick candidate, "
           "not only those beyond the neighbour list, are another layout)");
  const size_t cells = static_cast<size_t>(nc_) * nc_;
  if (!cells_.load_packed(cells, s.cells, limit, false)) refuse("its cells are malformed");
  cell_x_.assign(n, -1);
  cell_y_.assign(n, -1);
  for (size_t c = 0; c < cells; ++c) {
    const int32_t* row = cells_.row(c);
    for (int k = 1; k <= row[0]; ++k) {
      if (cell_x_[row[k]] >= 0) refuse("a particle is in two cells");
      cell_x_[row[k]] = static_cast<int32_t>(c % nc_);
      cell_y_[row[k]] = static_cast<int32_t>(c / nc_);
    }
  }
  for (size_t k = 0; k < n; ++k)
    if (cell_x_[k] < 0) refuse("a particle is in no cell");
  rng_.set_state(s.rng);
  count_ = s.counters;
  cal_.rebuild(n_, now_, event_times());
}

} // namespace dynhet::engine
