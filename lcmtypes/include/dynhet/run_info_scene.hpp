// The run info's fields that repeat the scene's analysis section, set from
// the scene in one place: by the sim when it makes the run info, and by a
// process that re-analyses a recorded run (dynhet/reanalysis.hpp) on its
// own copy of the recorded, authenticated run info.
#pragma once

#include <string>

#include "dynhet/reanalysis.hpp"
#include "dynhet/run_info_t.hpp"
#include "dynhet/scene.hpp"

namespace dynhet {

inline void set_analysis_fields(run_info_t& m, const Scene& sc) {
  m.cutoff_a = sc.cutoff_a;
  m.n_cutoffs = static_cast<int32_t>(m.cutoff_a.size());
  m.observables = sc.computed_observables();
  m.n_observables = static_cast<int32_t>(m.observables.size());
  m.overlap_subbox_particles = sc.overlap_subbox_particles;
  m.chi4_subbox_particles = sc.chi4_subbox_particles;
  m.n_chi4_sizes = static_cast<int32_t>(m.chi4_subbox_particles.size());
}

// The recorded run info `m` with the analysis of `analysis_toml` in place
// (scene text and the fields above); the frames, the schedule and the run
// id stay the recording's. Throws SceneError naming what is refused.
inline void apply_reanalysis(run_info_t& m, const std::string& analysis_toml, const std::string& origin) {
  const std::string text = reanalysis_scene_text(m.scene_toml, analysis_toml, origin);
  if (text == m.scene_toml) return; // the original settings: the recorded run info as it is
  set_analysis_fields(m, parse_scene_text(text, origin + " over the recorded scene"));
  m.scene_toml = text;
}

} // namespace dynhet
