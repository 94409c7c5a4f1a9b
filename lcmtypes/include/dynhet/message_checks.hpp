// Checks of a decoded message's contents against itself, before any
// process trusts it (every LCM message is untrusted input: any process on
// the host or LAN can publish). The encoding itself is checked first by
// guard::safe_decode (lcm_guard.hpp, generated).
#pragma once

#include <cctype>
#include <cmath>
#include <cstdint>
#include <string>

#include "dynhet/checkpoint_t.hpp"
#include "dynhet/run_info_t.hpp"

namespace dynhet {

// The largest run any process accepts: N up to 2^26 (67 million; the
// paper's largest is 4 x 10^6) and 10^6 frames.
constexpr int32_t kMaxParticles = 1 << 26;
constexpr int32_t kMaxFrames = 1000000;

// "" if the run info is consistent (sizes, indices into its own arrays,
// finite and ordered numbers), else the first problem found.
inline std::string run_info_problem(const run_info_t& m) {
  auto finite_pos = [](double v) { return std::isfinite(v) && v > 0; };
  if (m.n_particles < 1 || m.n_particles > kMaxParticles) return "n_particles " + std::to_string(m.n_particles);
  if (m.n_small < 0 || m.n_small > m.n_particles) return "n_small " + std::to_string(m.n_small);
  if (!finite_pos(m.box_length) || !finite_pos(m.packing_fraction) || !std::isfinite(m.restitution))
    return "box, packing fraction or restitution not finite";
  for (int s = 0; s < 2; ++s)
    if (!finite_pos(m.radius[s]) || !finite_pos(m.mass[s])) return "radius or mass not finite and positive";
  if (m.n_frames < 1 || m.n_frames > kMaxFrames) return "n_frames " + std::to_string(m.n_frames);
  for (int f = 0; f < m.n_frames; ++f)
    if (!std::isfinite(m.frame_time[f]) || (f > 0 && !(m.frame_time[f] > m.frame_time[f - 1])))
      return "frame_time not finite and increasing at frame " + std::to_string(f);
  if (m.n_origins < 1 || m.n_origins > m.n_frames) return "n_origins " + std::to_string(m.n_origins);
  for (int k = 0; k < m.n_origins; ++k)
    if (m.origin_frame[k] < 0 || m.origin_frame[k] >= m.n_frames) return "origin_frame out of range";
  if (m.n_lags < 1 || m.n_lags > kMaxFrames) return "n_lags " + std::to_string(m.n_lags);
  for (int j = 0; j < m.n_lags; ++j)
    if (!finite_pos(m.lag_time[j]) || (j > 0 && !(m.lag_time[j] > m.lag_time[j - 1])))
      return "lag_time not positive and increasing";
  if (int64_t(m.n_pairs) != int64_t(m.n_origins) * m.n_lags) return "n_pairs is not n_origins x n_lags";
  for (int i = 0; i < m.n_pairs; ++i)
    if (m.pair_frame[i] < -1 || m.pair_frame[i] >= m.n_frames) return "pair_frame out of range";
  if (m.n_cutoffs < 1 || m.n_cutoffs > 255) return "n_cutoffs " + std::to_string(m.n_cutoffs);
  for (int c = 0; c < m.n_cutoffs; ++c)
    if (!finite_pos(m.cutoff_a[c])) return "cutoff_a not finite and positive";
  if (m.overlap_subbox_particles < 1) return "overlap_subbox_particles < 1";
  if (m.n_chi4_sizes < 0 || m.n_chi4_sizes > 64) return "n_chi4_sizes " + std::to_string(m.n_chi4_sizes);
  for (int g = 0; g < m.n_chi4_sizes; ++g)
    if (m.chi4_subbox_particles[g] < 1) return "chi4_subbox_particles < 1";
  if (m.chunk_particles < 1) return "chunk_particles < 1";
  return "";
}

// "" if a checkpoint request or answer is sane for a run of n_frames frames:
// a cut number, a frame of the run (or -1), a finite time, a process name
// that can be a file name (letters, digits, '_'), a known state.
inline std::string checkpoint_problem(const checkpoint_t& m, int32_t n_frames) {
  if (m.cut < 0) return "cut " + std::to_string(m.cut);
  if (m.frame < -1 || m.frame >= n_frames) return "frame " + std::to_string(m.frame) + " not one of the run's";
  if (!std::isfinite(m.sim_time) || m.sim_time < 0) return "sim_time not finite and >= 0";
  if (m.process.empty() || m.process.size() > 32) return "process name of " + std::to_string(m.process.size()) + " characters";
  for (char c : m.process)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return "process name not [A-Za-z0-9_]";
  if (m.state != "save" && m.state != "saved" && m.state != "failed" && m.state != "whole")
    return "state \"" + m.state.substr(0, 16) + "\"";
  return "";
}

} // namespace dynhet
