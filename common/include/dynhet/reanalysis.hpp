// Re-analysis of a recorded run: its frames analysed again with another
// analysis section (cutoffs a, sub-box sizes, cage-relative on or off, the
// observables computed), without simulating again. Only what the frames
// of the recording serve may change: the system, the driving, the run, the
// schedule of origins and lags, the transport and whether frames are kept
// decided which frames exist, so a change to any of them is refused by name.
#pragma once

#include <string>

#include "dynhet/scene.hpp"

namespace dynhet {

// The scene a re-analysis goes by: the recorded scene's TOML with the keys
// of `analysis_toml` (a TOML holding analysis tables only) put in place of
// the recorded ones. When no value changes, the recorded text itself, so
// that a re-analysis at the original settings records the scene the live
// run did, byte for byte. Throws SceneError naming every refused key
// (`origin` names the analysis file), or the merged scene's problems.
std::string reanalysis_scene_text(const std::string& recorded_toml, const std::string& analysis_toml,
                                  const std::string& origin);

// The analysis keys a re-analysis may change, for messages:
// "[observables] compute, cutoff_a, cage_relative, cage; [overlap], [chi4], ...".
std::string reanalysis_keys();

} // namespace dynhet
