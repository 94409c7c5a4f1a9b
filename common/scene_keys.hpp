#pragma once
// The one description of a scene (scene_keys.cpp): every table and key, the
// values it allows, what it means, how a value is checked and stored, and
// how a scene's value is written back as TOML. The parser (scene.cpp), the
// resolved scene (scene_toml, sim_node --resolved), the reference in
// docs/scenes.md and the check of scenes/default.toml's keys are all read
// from it. The defaults are Scene's member initialisers (scene.hpp), written
// out through `write` from a default Scene. Private to dynhet_common.
#include <functional>
#include <string>
#include <vector>

#include "scene_check.hpp"

namespace dynhet::scene_detail {

struct SceneKey {
  std::string table, key;
  std::string allowed; // the type and the values allowed, as the reference states them
  std::string meaning; // what it is, in one line
  // A checked reader of the key into a scene (the Checker and the Scene
  // must outlive it).
  std::function<Handler(Checker&, Scene&)> reader;
  // The scene's value as TOML text; "" leaves the key out (a default that
  // the scene derives, such as production_time before the schedule is read).
  std::function<std::string(const Scene&)> write;
  // The reference's default where a default Scene writes none.
  std::string default_text;
};

// Every key, table by table, in the order of scenes/default.toml.
const std::vector<SceneKey>& scene_keys();

} // namespace dynhet::scene_detail
