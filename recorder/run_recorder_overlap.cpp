// The RunRecorder's writers of the overlap node's results (overlap, chi4,
// msd, displacement, bond breaking, and their cage-relative versions), apart
// from run_recorder.cpp, which checks the messages (on_overlap, on_msd, ...).
#include "run_recorder.hpp"

#include <algorithm>
#include <cstdio>

#include "dynhet/lcm_url.hpp"
#include "run_recorder_util.hpp"

namespace dynhet {

using namespace recorder_util;

// msd/{msd_all, msd_small, msd_{fast,slow}_{all,small}} and their _err:
// (records, lags), the subsets' fractions as attributes; diffusion,
// diffusion_err, fit_t_min, fit_t_max: one number per record.
void RunRecorder::write_msd(const msd_t &m) {
  const std::string group = result_group("msd", m.cage_relative);
  if (started_.insert(group).second) {
    writer_->write_fixed(group + "/lag_time", m.lag_time);
    writer_->set_attribute("observables/" + group, "fraction_all", m.fraction_all);
    writer_->set_attribute("observables/" + group, "fraction_small", m.fraction_small);
    if (m.cage_relative) writer_->set_attribute("observables/" + group, "displacements", kCageRelative);
    if (m.n_q > 0) writer_->write_fixed(group + "/fs_q", m.fs_q);
  }
  if (m.n_lags <= 0) return;
  if (m.frame_index < 0) return; // no frame folded in yet: nothing to record
  const Stamp at = *at_frame(m.frame_index, m.is_final);
  const std::pair<const char *, const std::vector<double> *> per_lag[] = {
      {"msd_all", &m.msd_all},
      {"msd_all_err", &m.msd_all_err},
      {"msd_small", &m.msd_small},
      {"msd_small_err", &m.msd_small_err},
      {"msd_fast_all", &m.msd_fast_all},
      {"msd_fast_all_err", &m.msd_fast_all_err},
      {"msd_slow_all", &m.msd_slow_all},
      {"msd_slow_all_err", &m.msd_slow_all_err},
      {"msd_fast_small", &m.msd_fast_small},
      {"msd_fast_small_err", &m.msd_fast_small_err},
      {"msd_slow_small", &m.msd_slow_small},
      {"msd_slow_small_err", &m.msd_slow_small_err}};
  const std::string base = group + "/";
  for (const auto &[name, v] : per_lag) writer_->append_observable(base + name, at, *v);
  writer_->append_scalar(base + "diffusion", at, m.diffusion);
  writer_->append_scalar(base + "diffusion_err", at, m.diffusion_err);
  writer_->append_scalar(base + "diffusion_flow", at, m.diffusion_flow);
  writer_->append_scalar(base + "diffusion_flow_err", at, m.diffusion_flow_err);
  writer_->append_scalar(base + "fit_t_min", at, m.fit_t_min);
  writer_->append_scalar(base + "fit_t_max", at, m.fit_t_max);
  for (const auto &[name, v] : {std::pair<const char *, const std::vector<double> *>{"alpha2_all", &m.alpha2_all},
                                {"alpha2_all_err", &m.alpha2_all_err},
                                {"alpha2_small", &m.alpha2_small},
                                {"alpha2_small_err", &m.alpha2_small_err}})
    writer_->append_observable(base + name, at, *v);
  if (m.n_fs > 0) {
    const Shape q_lag{dim(m.n_q), dim(m.n_lags)};
    writer_->append_observable(base + "fs_all", at, m.fs_all.data(), q_lag);
    writer_->append_observable(base + "fs_all_err", at, m.fs_all_err.data(), q_lag);
    writer_->append_observable(base + "fs_small", at, m.fs_small.data(), q_lag);
    writer_->append_observable(base + "fs_small_err", at, m.fs_small_err.data(), q_lag);
  }
}

// displacement/: x (bin centres) once, with the settings as attributes; per
// record the targets and their lags (records, targets), per series the fits
// (records, sets, targets), and per bin p, p_err, count (records, sets,
// targets, bins); set 0 is all particles, set 1 the small ones.
void RunRecorder::write_displacement(const displacement_t &m) {
  const std::string group = result_group("displacement", m.cage_relative), base = group + "/";
  if (started_.insert(group).second) {
    writer_->write_fixed(base + "x", m.x);
    const std::string g = "observables/" + group;
    if (m.cage_relative) writer_->set_attribute(g, "displacements", kCageRelative);
    writer_->set_attribute(g, "bin_width", m.bin_width);
    writer_->set_attribute(g, "n_sets", m.n_sets);
    writer_->set_attribute(g, "sets", "all,small");
    writer_->set_attribute(g, "n_blocks", m.n_blocks);
    writer_->set_attribute(g, "tail_sigmas", m.tail_sigmas);
    writer_->set_attribute(g, "min_bin_count", m.min_bin_count);
    writer_->set_attribute(g, "cutoff_a", m.cutoff_a);
    writer_->set_attribute(g, "layout",
                           "per target [record][target]; per series [record][set][target]; "
                           "per bin [record][set][target][bin]");
  }
  if (m.n_values <= 0) return;
  if (m.frame_index < 0) return; // no frame folded in yet: nothing to record
  const Stamp at = *at_frame(m.frame_index, m.is_final);
  const Shape series{dim(m.n_sets), dim(m.n_targets)}, bins{dim(m.n_sets), dim(m.n_targets), dim(m.n_bins)};
  auto scalar = [&](const char *name, const auto &v) { writer_->append_scalar(base + name, at, v); };
  auto per_target = [&](const char *name, const auto &v) { writer_->append_observable(base + name, at, v); };
  auto shaped = [&](const char *name, const auto &v, const Shape &shape) {
    writer_->append_observable(base + name, at, v.data(), shape);
  };
  scalar("tau_alpha", m.tau_alpha);
  per_target("target_time", m.target_time), per_target("target_tau_alpha", m.target_tau_alpha);
  per_target("lag_index", m.lag_index), per_target("lag_time", m.lag_time);
  shaped("n_pairs", m.n_pairs, series), shaped("samples", m.samples, series);
  shaped("fraction_outside", m.fraction_outside, series);
  shaped("p", m.p, bins), shaped("p_err", m.p_err, bins), shaped("count", m.count, bins);
  shaped("gauss_d", m.gauss_d, series), shaped("gauss_d_err", m.gauss_d_err, series);
  shaped("gauss_bins", m.gauss_bins, series);
  shaped("tail_x0", m.tail_x0, series), shaped("tail_x0_err", m.tail_x0_err, series);
  shaped("tail_amplitude", m.tail_amplitude, series);
  shaped("tail_x_min", m.tail_x_min, series), shaped("tail_x_max", m.tail_x_max, series);
  shaped("tail_bins", m.tail_bins, series);
  scalar("gauss_d_small_tau_alpha", m.gauss_d_small_tau_alpha);
  scalar("tail_x0_small_tau_alpha", m.tail_x0_small_tau_alpha);
}

// bond_breaking/: lag_time, subbox_particles, subbox_per_side once (a1, a2
// as attributes); per record c_b, c_b_err [lag], tau_b, tau_b_err,
// bonds_per_particle, chi_b, chi_b_err [grid][lag], chi_b_peak, tau_chi_b
// and their errors [grid].
void RunRecorder::write_bond_breaking(const bond_breaking_t &m) {
  const std::string base = "bond_breaking/";
  if (started_.insert(base).second) {
    writer_->write_fixed(base + "lag_time", m.lag_time);
    writer_->write_fixed(base + "subbox_particles", m.subbox_particles);
    writer_->write_fixed(base + "subbox_per_side", m.subbox_per_side);
    writer_->set_attribute("observables/bond_breaking", "a1", m.a1);
    writer_->set_attribute("observables/bond_breaking", "a2", m.a2);
    writer_->set_attribute("observables/bond_breaking", "layout",
                           "c_b, c_b_err [record][lag]; chi_b, chi_b_err [record][grid][lag]; chi_b_peak, "
                           "tau_chi_b and their errors [record][grid]");
  }
  if (m.n_lags <= 0 || m.frame_index < 0) return; // no frame folded in yet: nothing to record
  const Stamp at = *at_frame(m.frame_index, m.is_final);
  writer_->append_observable(base + "c_b", at, m.c_b);
  writer_->append_observable(base + "c_b_err", at, m.c_b_err);
  writer_->append_scalar(base + "tau_b", at, m.tau_b);
  writer_->append_scalar(base + "tau_b_err", at, m.tau_b_err);
  writer_->append_scalar(base + "bonds_per_particle", at, m.bonds_per_particle);
  if (m.n_values > 0) {
    const Shape grid_lag{dim(m.n_grids), dim(m.n_lags)};
    writer_->append_observable(base + "chi_b", at, m.chi_b.data(), grid_lag);
    writer_->append_observable(base + "chi_b_err", at, m.chi_b_err.data(), grid_lag);
    writer_->append_observable(base + "chi_b_peak", at, m.chi_b_peak);
    writer_->append_observable(base + "tau_chi_b", at, m.tau_chi_b);
    writer_->append_observable(base + "chi_b_peak_err", at, m.chi_b_peak_err);
    writer_->append_observable(base + "tau_chi_b_err", at, m.tau_chi_b_err);
  }
}

// chi4/a<cutoff>/{chi4, chi4_err}: (records, grids, lags); chi4_peak, tau4
// and their errors: (records, grids).
void RunRecorder::write_chi4(const chi4_t &m) {
  const std::string label = cutoff_label(m.cutoff_a);
  const std::string base = result_group("chi4", m.cage_relative) + "/" + label + "/";
  if (started_.insert(base).second) {
    writer_->write_fixed(base + "lag_time", m.lag_time);
    writer_->write_fixed(base + "subbox_particles", m.subbox_particles);
    writer_->write_fixed(base + "subbox_per_side", m.subbox_per_side);
    writer_->set_attribute("observables/" + base, "cutoff_a", m.cutoff_a);
    writer_->set_attribute("observables/" + base, "layout",
                           "chi4, chi4_err, chi4_per_origin, chi4_per_origin_err [record][grid][lag]; chi4_peak, "
                           "tau4, their errors, tau4_interior [record][grid]");
    writer_->set_attribute("observables/" + base, "estimator",
                           "chi4: the pooled estimator, N_r times the variance of Q_r over every sub-box of every origin, denominator "
                           "n - 1 (unbiased for any number of sub-boxes), error a jackknife over blocks of "
                           "origins; chi4_per_origin: paper eq. (14) as written, the variance about each "
                           "origin's own mean averaged over origins (low by about chi4 / n_boxes); chi4_peak, "
                           "tau4: the half-maximum peak fit of chi4, tau4_interior 0 where the peak is at "
                           "the first or last lag (a bound)");
    if (m.cage_relative) writer_->set_attribute("observables/" + base, "displacements", kCageRelative);
  }
  if (m.n_values <= 0) return;
  if (m.frame_index < 0) return; // no frame folded in yet: nothing to record
  const Stamp at = *at_frame(m.frame_index, m.is_final);
  const Shape grid_lag{dim(m.n_grids), dim(m.n_lags)};
  writer_->append_observable(base + "chi4", at, m.chi4.data(), grid_lag);
  writer_->append_observable(base + "chi4_err", at, m.chi4_err.data(), grid_lag);
  writer_->append_observable(base + "chi4_peak", at, m.chi4_peak);
  writer_->append_observable(base + "tau4", at, m.tau4);
  writer_->append_observable(base + "chi4_peak_err", at, m.chi4_peak_err);
  writer_->append_observable(base + "tau4_err", at, m.tau4_err);
  writer_->append_observable(base + "chi4_per_origin", at, m.chi4_per_origin.data(), grid_lag);
  writer_->append_observable(base + "chi4_per_origin_err", at, m.chi4_per_origin_err.data(), grid_lag);
  std::vector<int32_t> interior(m.tau4_interior.begin(), m.tau4_interior.end());
  writer_->append_observable(base + "tau4_interior", at, interior);
}

void RunRecorder::write_overlap(const overlap_t &m) {
  const std::string label = cutoff_label(m.cutoff_a);
  const std::string base = result_group("overlap", m.cage_relative) + "/" + label + "/";
  if (started_.insert(base).second) {
    writer_->write_fixed(base + "lag_time", m.lag_time);
    writer_->set_attribute("observables/" + base, "cutoff_a", m.cutoff_a);
    writer_->set_attribute("observables/" + base, "subbox_per_side", m.subbox_per_side);
    writer_->set_attribute("observables/" + base, "subbox_particles", m.subbox_particles);
    if (m.cage_relative) writer_->set_attribute("observables/" + base, "displacements", kCageRelative);
  }
  if (m.n_lags <= 0) return;
  if (m.frame_index < 0) return; // no frame folded in yet: nothing to record
  const Stamp at = *at_frame(m.frame_index, m.is_final);
  writer_->append_observable(base + "q", at, m.q);
  writer_->append_observable(base + "q_err", at, m.q_err);
  writer_->append_observable(base + "n_origins", at, m.n_origins);
  writer_->append_observable(base + "qr_var", at, m.qr_var);
  writer_->append_scalar(base + "tau_alpha", at, m.tau_alpha);
  writer_->append_scalar(base + "tau_alpha_err", at, m.tau_alpha_err);
  writer_->append_scalar(base + "beta", at, m.beta);
  writer_->append_scalar(base + "beta_err", at, m.beta_err);
  writer_->append_scalar(base + "tau0", at, m.tau0);
  writer_->append_scalar(base + "tau0_err", at, m.tau0_err);
  if (m.n_t0 > 0) {
    if (started_.insert(base + "t0").second) writer_->write_fixed(base + "t0", m.t0);
    writer_->append_observable(base + "tau_alpha_t0", at, m.tau_alpha_t0);
  }
}

} // namespace dynhet
