// The RunRecorder's writers of the s4 and clusters nodes' results (and their
// cage-relative versions): the two largest layouts, apart from the rest of
// run_recorder.cpp (which checks the messages: on_s4, on_clusters).
#include "run_recorder.hpp"

#include "dynhet/lcm_url.hpp"
#include "run_recorder_util.hpp"

namespace dynhet {

using namespace recorder_util;

// s4/a<cutoff>/: fixed lag_time (the computed lags) and, per grid,
// subbox_particles, subbox_per_side, grid_spacing, grid_points, n_shells;
// per shell value q, shell_vectors (grid g's shells follow grid g-1's). Per
// record: s4, s4_err (records, values) at t_s4; s4_lag (records, lags,
// values); xi_lag, chi0_lag (records, lags, grids); scan_qxi_max
// (records, ranges), scan_{oz,a2}_{xi,chi0} (records, grids, ranges); oz_*, a2_*, chi4,
// chi4_err (records, grids); scalars tau_alpha, t_s4, lag_index, lag_lo,
// lag_hi, lag_weight, lag_third, n_origins, xi, xi_err, chi0, chi0_err,
// chi4_box, chi4_box_err.
void RunRecorder::write_s4(const s4_t &m) {
  const std::string label = cutoff_label(m.cutoff_a);
  const std::string base = result_group("s4", m.cage_relative) + "/" + label + "/";
  if (started_.insert(base).second) {
    writer_->write_fixed(base + "lag_time", m.lag_time);
    writer_->write_fixed(base + "subbox_particles", m.subbox_particles);
    writer_->write_fixed(base + "subbox_per_side", m.subbox_per_side);
    writer_->write_fixed(base + "grid_spacing", m.grid_spacing);
    writer_->write_fixed(base + "grid_points", m.grid_points);
    writer_->write_fixed(base + "n_shells", m.n_shells);
    writer_->write_fixed(base + "q", m.q);
    writer_->write_fixed(base + "shell_vectors", m.shell_vectors);
    const std::string g = "observables/" + base;
    writer_->set_attribute(g, "cutoff_a", m.cutoff_a);
    writer_->set_attribute(g, "q_max", m.q_max);
    writer_->set_attribute(g, "qxi_max", m.qxi_max);
    writer_->set_attribute(g, "layout",
                           "s4[record][value], grid g's shells after grid g-1's; s4_lag[record][lag][value]; "
                           "xi_lag, chi0_lag, xi_lag_rule[record][lag][grid]");
    writer_->set_attribute(g, "xi_lag_rule",
                           "0: the OZ fit at that lag kept; 1: fewer than 3 shells with q xi <= qxi_max (xi and "
                           "chi0 NaN); 2: xi below the q range, q xi < 0.5 at the largest q fitted (xi NaN); "
                           "3: no fit. The same rule as oz_xi at t_s4 (whose jackknife error must also be "
                           "below xi)");
    if (m.cage_relative) writer_->set_attribute(g, "displacements", kCageRelative);
  }
  if (m.n_values <= 0) return;
  if (m.frame_index < 0) return; // no frame folded in yet: nothing to record
  const Stamp at = *at_frame(m.frame_index, m.is_final);
  const std::pair<const char *, const std::vector<double> *> arrays[] = {{"s4", &m.s4},
                                                                         {"s4_err", &m.s4_err},
                                                                         {"oz_chi0", &m.oz_chi0},
                                                                         {"oz_chi0_err", &m.oz_chi0_err},
                                                                         {"oz_xi", &m.oz_xi},
                                                                         {"oz_xi_err", &m.oz_xi_err},
                                                                         {"oz_q_fit_max", &m.oz_q_fit_max},
                                                                         {"a2_chi0", &m.a2_chi0},
                                                                         {"a2_chi0_err", &m.a2_chi0_err},
                                                                         {"a2_xi", &m.a2_xi},
                                                                         {"a2_xi_err", &m.a2_xi_err},
                                                                         {"a2_a", &m.a2_a},
                                                                         {"a2_a_err", &m.a2_a_err},
                                                                         {"a2_q_fit_max", &m.a2_q_fit_max},
                                                                         {"chi4", &m.chi4},
                                                                         {"chi4_err", &m.chi4_err}};
  for (const auto &[name, v] : arrays) writer_->append_observable(base + name, at, *v);
  writer_->append_observable(base + "s4_lag", at, m.s4_lag.data(), {dim(m.n_lags), dim(m.n_values)});
  writer_->append_observable(base + "xi_lag", at, m.xi_lag.data(), {dim(m.n_lags), dim(m.n_grids)});
  writer_->append_observable(base + "chi0_lag", at, m.chi0_lag.data(), {dim(m.n_lags), dim(m.n_grids)});
  const std::vector<int32_t> rule(m.xi_lag_rule.begin(), m.xi_lag_rule.end());
  writer_->append_observable(base + "xi_lag_rule", at, rule.data(), {dim(m.n_lags), dim(m.n_grids)});
  writer_->append_observable(base + "oz_n_fit", at, m.oz_n_fit);
  if (m.n_scan > 0) { // a sender without the range scan (n_scan 0) still has its S4 recorded
    writer_->append_observable(base + "scan_qxi_max", at, m.scan_qxi_max);
    for (const auto &[name, v] : {std::pair<const char *, const std::vector<double> *>{"scan_oz_xi", &m.scan_oz_xi},
                                  {"scan_oz_chi0", &m.scan_oz_chi0},
                                  {"scan_a2_xi", &m.scan_a2_xi},
                                  {"scan_a2_chi0", &m.scan_a2_chi0}})
      writer_->append_observable(base + name, at, v->data(), {dim(m.n_grids), dim(m.n_scan)});
  }
  writer_->append_observable(base + "a2_n_fit", at, m.a2_n_fit);
  const std::pair<const char *, double> scalars[] = {
      {"tau_alpha", m.tau_alpha}, {"t_s4", m.t_s4}, {"xi", m.xi}, {"xi_err", m.xi_err}, {"chi0", m.chi0},
      {"chi0_err", m.chi0_err}, {"chi4_box", m.chi4_box}, {"chi4_box_err", m.chi4_box_err}, {"lag_weight", m.lag_weight}};
  for (const auto &[name, v] : scalars) writer_->append_scalar(base + name, at, v);
  writer_->append_scalar(base + "lag_index", at, m.lag_index);
  writer_->append_scalar(base + "lag_lo", at, m.lag_lo);
  writer_->append_scalar(base + "lag_hi", at, m.lag_hi);
  writer_->append_scalar(base + "lag_third", at, m.lag_third);
  writer_->append_scalar(base + "n_origins", at, m.n_origins);
}

// clusters/a<cutoff>/: lag_time, r (of g_ab) and size_lo, size_hi,
// size_centre (the N_c bins) written once; per record: the scalars, the
// per-lag arrays (records, lags), g11/g12/g22 (records, r) and the per-bin
// arrays (records, bins), the latter two from the first record that has them.
void RunRecorder::write_clusters(const clusters_t &m) {
  const std::string label = cutoff_label(m.cutoff_a);
  const std::string base = result_group("clusters", m.cage_relative) + "/" + label + "/";
  if (started_.insert(base).second) {
    writer_->write_fixed(base + "lag_time", m.lag_time);
    writer_->set_attribute("observables/" + base, "cutoff_a", m.cutoff_a);
    writer_->set_attribute("observables/" + base, "n_blocks", m.n_blocks);
    writer_->set_attribute("observables/" + base, "kappa_n_min", m.kappa_n_min);
    writer_->set_attribute("observables/" + base, "kappa_n_max", m.kappa_n_max);
    if (m.cage_relative) writer_->set_attribute("observables/" + base, "displacements", kCageRelative);
  }
  if (m.frame_index < 0) return; // no frame folded in yet: nothing to record
  const Stamp at = *at_frame(m.frame_index, m.is_final);
  auto scalar = [&](const char *name, const auto &v) { writer_->append_scalar(base + name, at, v); };
  auto array = [&](const char *name, const auto &v) { writer_->append_observable(base + name, at, v); };
  writer_->append_observable(base + "neighbour_cutoff", at, m.neighbour_cutoff, {3});
  writer_->append_observable(base + "pooled_minimum", at, m.pooled_minimum, {3});
  scalar("g_frames", m.g_frames);
  if (m.n_r > 0) {
    if (started_.insert(base + "r").second) writer_->write_fixed(base + "r", m.r);
    array("g11", m.g11), array("g12", m.g12), array("g22", m.g22);
  }
  scalar("tau_alpha", m.tau_alpha), scalar("tau_alpha_err", m.tau_alpha_err);
  scalar("lag_index", m.lag_index), scalar("lag", m.lag);
  scalar("lag_lo", m.lag_lo), scalar("lag_hi", m.lag_hi), scalar("lag_weight", m.lag_weight), scalar("lag_third", m.lag_third);
  array("n_origins", m.n_origins), array("n_slow", m.n_slow), array("n_fast", m.n_fast);
  array("mean_size_slow", m.mean_size_slow), array("mean_size_slow_err", m.mean_size_slow_err);
  array("mean_size_fast", m.mean_size_fast), array("mean_size_fast_err", m.mean_size_fast_err);
  scalar("origins_at_lag", m.origins_at_lag);
  scalar("slow_clusters", m.slow_clusters), scalar("fast_clusters", m.fast_clusters);
  scalar("slow_mean_size", m.slow_mean_size), scalar("slow_mean_size_err", m.slow_mean_size_err);
  scalar("fast_mean_size", m.fast_mean_size), scalar("fast_mean_size_err", m.fast_mean_size_err);
  scalar("slow_largest", m.slow_largest), scalar("fast_largest", m.fast_largest);
  scalar("slow_spanning", m.slow_spanning), scalar("fast_spanning", m.fast_spanning);
  scalar("slow_d_f", m.slow_d_f), scalar("slow_d_f_err", m.slow_d_f_err);
  scalar("fast_d_f", m.fast_d_f), scalar("fast_d_f_err", m.fast_d_f_err);
  scalar("slow_kappa", m.slow_kappa), scalar("slow_kappa_err", m.slow_kappa_err);
  scalar("fast_n0", m.fast_n0), scalar("fast_n0_err", m.fast_n0_err);
  scalar("fast_sigma", m.fast_sigma), scalar("fast_sigma_err", m.fast_sigma_err);
  scalar("fast_n_sigma", m.fast_n_sigma), scalar("fast_p0", m.fast_p0);
  if (m.n_bins > 0) {
    if (started_.insert(base + "size_bins").second) {
      writer_->write_fixed(base + "size_lo", m.size_lo);
      writer_->write_fixed(base + "size_hi", m.size_hi);
      writer_->write_fixed(base + "size_centre", m.size_centre);
    }
    array("p_slow", m.p_slow), array("p_slow_err", m.p_slow_err);
    array("p_fast", m.p_fast), array("p_fast_err", m.p_fast_err);
    array("count_slow", m.count_slow), array("count_fast", m.count_fast);
    array("rg_size_slow", m.rg_size_slow), array("rg_slow", m.rg_slow), array("rg_slow_err", m.rg_slow_err);
    array("rg_size_fast", m.rg_size_fast), array("rg_fast", m.rg_fast), array("rg_fast_err", m.rg_fast_err);
  }
}

} // namespace dynhet
