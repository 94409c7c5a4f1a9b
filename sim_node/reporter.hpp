// sim_node's status: everything the sim status message (DYNHET_SIM_STATUS)
// and the terminal line show, and the pressure and collision-frequency
// blocks behind Z and its error (a checkpoint cut keeps them: state()).
#pragma once

#include <chrono>
#include <functional>
#include <cmath>
#include <cstdio>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include "dynhet/engine/engine.hpp"
#include "dynhet/bus.hpp"
#include "dynhet/lcm_url.hpp"
#include "dynhet/sim_status_t.hpp"
#include "dynhet/stats.hpp"

namespace dynhet {

// h:mm:ss, or "?".
inline std::string hms(double s) {
  if (!(s >= 0) || !std::isfinite(s)) return "?";
  char buf[32];
  const long t = std::lround(s);
  std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
  return buf;
}

// Everything the status message and the terminal line show.
class Reporter {
  using Clock = std::chrono::steady_clock;
public:
  Reporter(lcm::LCM& lcm, Bus bus, int64_t run_id, bool tty) : lcm_(lcm), bus_(std::move(bus)), tty_(tty) {
    msg_.run_id = run_id;
    msg_.eta_seconds = -1;
  }
  sim_status_t& msg() { return msg_; }
  // Where the count of messages the bus dropped comes from (the pacer's
  // and the cut coordinator's subscriptions), read at each publish.
  void count_unauthenticated(std::function<long()> f) { unauthenticated_ = std::move(f); }

  // Adds what happened since the last sample (every slice of events, at
  // most a few N events apart) to the pressure and collision-frequency
  // blocks, which are in simulation time. Then publishes (and prints) if a
  // second has passed, or if forced.
  void update(const engine::Engine& e, double remaining_sim_time, bool force = false) {
    const auto& c = e.counters();
    const long n = e.size();
    const double ke = e.kinetic_energy_per_particle();
    const double dsim = e.time() - s_time_;
    if (dsim > 0 && msg_.phase != "compress") {
      // Z = 1 + (N-1)/N sum virial / (2 N sum ke dt) (engine.hpp): the
      // blocks hold the virial and ke dt; the frequency 2 collisions / N and dt.
      pressure_.add((c.virial - s_virial_) / (2.0 * n), 0.5 * (ke + s_ke_) * dsim, dsim);
      frequency_.add(2.0 * (c.collisions - s_coll_) / double(n), dsim, dsim);
    }
    s_time_ = e.time(), s_coll_ = c.collisions, s_virial_ = c.virial, s_ke_ = ke;
    const double dt = std::chrono::duration<double>(Clock::now() - last_).count();
    if (!force && dt < 1.0) return;
    msg_.utime = utime_now();
    msg_.sim_time = e.time();
    msg_.packing_fraction = e.packing_fraction();
    msg_.n_collisions = c.collisions;
    msg_.n_kicks = c.kicks;
    const double dpub = e.time() - last_sim_;
    msg_.collisions_per_second = dt > 0 && c.collisions >= last_coll_ ? (c.collisions - last_coll_) / dt : 0;
    const double f = (n - 1.0) / n;
    msg_.reduced_pressure = engine::reduced_pressure_from_ratio(pressure_.mean(), n);
    msg_.reduced_pressure_err = f * pressure_.standard_error();
    msg_.collision_frequency = frequency_.mean();
    msg_.collision_frequency_err = frequency_.standard_error();
    msg_.n_tc = c.tc;
    msg_.kinetic_energy = ke;
    if (dpub > 0 && remaining_sim_time >= 0) msg_.eta_seconds = remaining_sim_time / (dpub / dt);
    if (unauthenticated_)
      msg_.messages_unauthenticated = static_cast<int32_t>(std::min<long>(unauthenticated_(), INT32_MAX));
    const auto drops = bus_.drops();
    std::copy(drops.begin(), drops.end(), msg_.bus_drops);
    bus_.publish(lcm_, kChanSimStatus, msg_);
    print();
    last_ = Clock::now();
    last_sim_ = e.time();
    last_coll_ = c.collisions;
  }
  // Fine blocks of the pressure and frequency in this phase.
  long blocks() const { return pressure_.blocks(); }
  // What a checkpoint cut keeps: the blocks and the last sample, so that a
  // resumed run's Z and collision frequency equal the uninterrupted run's.
  template <class Ar> void state(Ar& ar) { ar(pressure_, frequency_, s_time_, s_virial_, s_ke_, s_coll_); }
  // A new phase of this length in simulation time: rates and block
  // averages start afresh, with 256 fine blocks over the phase.
  void reset_rates(const engine::Engine& e, double phase_length) {
    last_sim_ = s_time_ = e.time();
    last_coll_ = s_coll_ = e.counters().collisions;
    s_virial_ = e.counters().virial;
    msg_.kinetic_energy = s_ke_ = e.kinetic_energy_per_particle();
    msg_.eta_seconds = -1;
    pressure_.reset(phase_length / 256);
    frequency_.reset(phase_length / 256);
  }
  void print() {
    std::fprintf(stderr, "%s[%-11s] t=%-10.4g/%-10.4g phi=%.4f  coll/s=%.3g  T=%.4f  Z=%.4g  frames %d/%d  ETA %s%s",
                 tty_ ? "\r" : "", msg_.phase.c_str(), msg_.sim_time, msg_.phase_end_time,
                 msg_.packing_fraction, msg_.collisions_per_second, msg_.kinetic_energy, msg_.reduced_pressure,
                 msg_.frames_published, msg_.frames_total, hms(msg_.eta_seconds).c_str(),
                 tty_ ? "   " : "\n");
    std::fflush(stderr);
  }

private:
  lcm::LCM& lcm_;
  Bus bus_;
  std::function<long()> unauthenticated_;
  bool tty_;
  sim_status_t msg_{};
  Clock::time_point last_ = Clock::now();
  double last_sim_ = 0;
  int64_t last_coll_ = 0;
  double s_time_ = 0, s_virial_ = 0, s_ke_ = 0; // the last sample
  int64_t s_coll_ = 0;
  RatioBlocks pressure_, frequency_;
};


} // namespace dynhet
