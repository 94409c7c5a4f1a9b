// The checks between a scene's keys (scene_check.hpp): run after every key
// has been read alone, each problem named with the values involved.
#include <algorithm>
#include <cmath>

#include "dynhet/lcm_url.hpp" // cutoff_label
#include "dynhet/model.hpp"
#include "scene_check.hpp"

namespace dynhet::scene_detail {

void check_relations(Scene& s, Checker& c) {
  const auto& cl = s.clusters;
  const auto& dp = s.displacement;
  const auto& sch = s.schedule;
  for (double t : sch.extra_lags)
    if (t < sch.lag_min || t > sch.lag_max)
      c.fail("schedule.extra_lags", "value " + num(t) + " is outside [lag_min, lag_max] = [" + num(sch.lag_min) +
                                        ", " + num(sch.lag_max) + "]");
  if (sch.lag_min >= sch.lag_max)
    c.fail("schedule.lag_min", "value " + num(sch.lag_min) +
                                   " must be smaller than schedule.lag_max = " +
                                   num(sch.lag_max));
  // Every (origin, lag) pair is a frame to publish and a pass to make, and
  // the run info carries them all (4 bytes each, in one LCM message).
  const double n_lags = std::floor(std::log10(sch.lag_max / sch.lag_min) * sch.lags_per_decade) + 2;
  if (sch.lag_min < sch.lag_max && sch.origins * n_lags > 1e6)
    c.fail("schedule", "origins x lags = " + std::to_string(sch.origins) + " x " +
                           std::to_string(static_cast<long>(n_lags)) +
                           " pairs is more than 10^6 (the run info could not carry them); use fewer origins "
                           "or lags per decade");
  const double needed = (sch.origins - 1) * sch.origin_spacing + sch.lag_max;
  if (s.production_time < 0) {
    s.production_time = needed;
  } else if (s.production_time < needed * (1 - 1e-12)) {
    c.fail("run.production_time",
           "value " + num(s.production_time) + " is shorter than the schedule needs: " +
               "(origins - 1) * origin_spacing + lag_max = " + num(needed));
  }
  const Model m = make_model(s.n_particles, s.packing_fraction, s.radius_ratio);
  const double min_box = 3 * 2 * std::max(m.radius[0], m.radius[1]);
  if (m.box_length < min_box)
    c.fail("system.n_particles",
           "value " + std::to_string(s.n_particles) + " is too small at this packing fraction: " +
               "the box side " + num(m.box_length) +
               " must hold 3 cells of the largest diameter (" + num(min_box) + ")");
  // The NUFFT grid must resolve q_max (Nyquist: h < pi / q_max).
  if (s.s4_grid_spacing > 0 && s.s4_grid_spacing * s.s4_q_max >= 3.14159265358979)
    c.fail("s4.grid_spacing", "value " + num(s.s4_grid_spacing) +
                                  " is too coarse for s4.q_max = " + num(s.s4_q_max) +
                                  "; allowed: 0 (the default, pi / (2 q_max)) or spacing < pi / q_max");
  for (double t : s.s4_lags)
    if (t < sch.lag_min * (1 - 1e-12) || t > sch.lag_max * (1 + 1e-12))
      c.fail("s4.lags", "value " + num(t) + " is outside the scheduled lags [" +
                            num(sch.lag_min) + ", " + num(sch.lag_max) + "]");
  if (cl.cutoff_frames > sch.origins)
    c.fail("clusters.cutoff_frames", "value " + std::to_string(cl.cutoff_frames) +
                                         " is more than the schedule's origins (" +
                                         std::to_string(sch.origins) + ")");
  if (cl.gr_r_max > m.box_length / 2)
    c.fail("clusters.gr_r_max", "value " + num(cl.gr_r_max) + " is more than half the box side (" +
                                    num(m.box_length / 2) + ")");
  if (cl.gr_r_max / cl.gr_bin > 1e5)
    c.fail("clusters.gr_bin", "value " + num(cl.gr_bin) + " makes more than 10^5 bins below clusters.gr_r_max = " +
                                  num(cl.gr_r_max));
  // The whole box's NUFFT grid: L / h points per side, h the spacing.
  if (s.wants("s4")) {
    const double h = s.s4_grid_spacing > 0 ? s.s4_grid_spacing : 3.14159265358979 / (2 * s.s4_q_max);
    if (m.box_length / h > 8192)
      c.fail(s.s4_grid_spacing > 0 ? "s4.grid_spacing" : "s4.q_max",
             "makes a NUFFT grid of " + num(std::ceil(m.box_length / h)) +
                 " points per box side (more than 8192); allowed: grid_spacing >= box side / 8192 = " +
                 num(m.box_length / 8192) + ", q_max <= " + num(8192 * 3.14159265358979 / (2 * m.box_length)));
  }
  // Kicks so frequent that simulated time hardly moves.
  if (s.driving && s.restitution < 1 && scene_kick_rate(s) > 1e4)
    c.fail("driving.kick_rate", "value " + num(scene_kick_rate(s)) +
                                    " kicks per particle per unit time is more than 10^4: the clock would "
                                    "hardly move (the Enskog rate, the default, is about 1-100)");
  // Inelastic collapse: without the TC model, strongly inelastic disks
  // collide infinitely often in finite time.
  if (s.restitution < 0.3 && s.tc_time <= 0)
    c.fail("system.restitution", "value " + num(s.restitution) +
                                     " below 0.3 needs the TC model (system.tc_time > 0): without it "
                                     "inelastic collapse stops the clock");
  if ((s.equilibration_time + s.production_time) / s.checkpoint_interval > 1e6)
    c.fail("run.checkpoint_interval", "value " + num(s.checkpoint_interval) +
                                          " makes more than 10^6 checkpoints (and synchronisations) in the run");
  if (cl.gr_bin * 10 > cl.gr_r_max)
    c.fail("clusters.gr_bin", "value " + num(cl.gr_bin) +
                                  " leaves fewer than 10 bins below clusters.gr_r_max = " +
                                  num(cl.gr_r_max));
  if (const auto& r = cl.neighbour_cutoffs; !r.empty() && *std::max_element(r.begin(), r.end()) * 3 > m.box_length)
    c.fail("clusters.neighbour_cutoffs", "the largest cutoff must be under a third of the box side (" +
                                             num(m.box_length / 3) + ")");
  if (const auto& p = cl.power_law_sizes; !(p[0] >= 1 && p[0] < p[1]))
    c.fail("clusters.power_law_sizes", "[" + std::to_string(p[0]) + ", " + std::to_string(p[1]) +
                                           "] is not allowed; allowed: [lo, hi] with 1 <= lo < hi");
  // P(dx, t): a message of 2 sets x targets x bins x 24 bytes must stay well
  // under what survives UDP whole (~200 KB).
  const size_t targets = dp.lags_tau_alpha.size() + dp.lags.size();
  const double bins = 2 * dp.x_max / dp.bin_width;
  if (s.wants("displacement") && targets == 0)
    c.fail("displacement.lags_tau_alpha", "and displacement.lags are both empty; name at least one lag");
  if (targets > 16)
    c.fail("displacement.lags_tau_alpha", "with displacement.lags names " + std::to_string(targets) +
                                              " lags; at most 16");
  if (!(bins >= 10 && bins <= 4000))
    c.fail("displacement.bin_width", "value " + num(dp.bin_width) + " makes " +
                                         std::to_string(static_cast<long>(bins)) +
                                         " bins over [-x_max, x_max); allowed: 10 to 4000 bins");
  else if (targets * dp.bins() > 4096)
    c.fail("displacement.bin_width", "value " + num(dp.bin_width) + ": " + std::to_string(targets) +
                                         " lags x " + std::to_string(dp.bins()) +
                                         " bins is more than 4096 (the message would not survive UDP)");
  if (s.cage_relative && std::none_of(s.observables.begin(), s.observables.end(), has_cage_relative))
    c.fail("observables.cage_relative", "is true, but no observable named has a cage-relative version (overlap, "
                                        "chi4, msd, displacement, s4 and clusters have)");
  if (const auto& bb = s.bond_breaking; !(bb.a1 > 0 && bb.a2 > bb.a1 && bb.a2 < 10))
    c.fail("bond_breaking.a2", "with a1 = " + num(bb.a1) + ", a2 = " + num(bb.a2) +
                                   " is not allowed; allowed: 0 < a1 < a2 < 10 (a bond forms below a1 sigma_ij "
                                   "and breaks beyond a2 sigma_ij)");
  if (s.msd.fs_q.size() > 16)
    c.fail("msd.fs_q", "lists " + std::to_string(s.msd.fs_q.size()) + " wave numbers; at most 16");
  if (s.observables.empty())
    c.fail("observables.compute", "is empty; name at least one of the known observables");
}

} // namespace dynhet::scene_detail
