#include "dynhet/reanalysis.hpp"

#include <algorithm>
#include <sstream>

#include <toml++/toml.h>

#include "dynhet/observables.hpp"
#include "scene_check.hpp"

namespace dynhet {

namespace {

// Tables whose every key is analysis, what is computed from frames the
// recording has and how: an observable's own table ([overlap], [s4], ...).
bool analysis_table(const std::string& t) { return find_observable(t) != nullptr; }
// The analysis keys of [observables] (keep_frames is not one: the recording
// decided which frames a file may keep).
const char* const kObservableKeys[] = {"compute", "cutoff_a", "cage_relative", "cage"};
// Tables that decided the recorded frames.
const char* const kFrameTables[] = {"system", "driving", "run", "schedule", "transport"};

template <size_t N> bool among(const char* const (&list)[N], const std::string& s) {
  return std::find(std::begin(list), std::end(list), s) != std::end(list);
}

} // namespace

std::string reanalysis_keys() {
  std::string s = "[observables] ";
  for (const char* k : kObservableKeys) s += std::string(k) + (k == kObservableKeys[3] ? "" : ", ");
  for (const ObservableInfo& o : kObservables) s += std::string("; [") + o.name + "]";
  return s;
}

std::string reanalysis_scene_text(const std::string& recorded_toml, const std::string& analysis_toml,
                                  const std::string& origin) {
  const toml::table recorded = scene_detail::parse_toml(recorded_toml, "the recorded scene");
  const toml::table analysis = scene_detail::parse_toml(analysis_toml, origin);

  // Refused by name: every key that decided which frames exist. Keys and
  // tables the scene does not know are left to the scene's own check below.
  std::string refused;
  auto refuse = [&](const std::string& key) { refused += (refused.empty() ? "" : ", ") + key; };
  for (const auto& [tname, node] : analysis) {
    const std::string t(tname.str());
    const auto* table = node.as_table();
    if (analysis_table(t) || !table) continue;
    if (t == "observables") {
      for (const auto& [key, v] : *table)
        if (std::string(key.str()) == "keep_frames") refuse(t + ".keep_frames");
    } else if (among(kFrameTables, t)) {
      for (const auto& [key, v] : *table) refuse(t + "." + std::string(key.str()));
      if (table->empty()) refuse("[" + t + "]");
    }
  }
  if (!refused.empty())
    throw SceneError(origin + ": refused: " + refused + ": a re-analysis keeps what decided the recorded frames (the "
                     "system, the driving, the run, the schedule of origins and lags, the transport, the frames kept); "
                     "it may change only " + reanalysis_keys());

  toml::table merged = recorded;
  for (const auto& [tname, node] : analysis) {
    const auto* table = node.as_table();
    if (!table) { // not a table: the scene's check names it
      merged.insert_or_assign(tname, node);
      continue;
    }
    if (!merged.contains(tname)) merged.insert(tname, toml::table{});
    toml::table* into = merged[tname].as_table();
    if (!into) throw SceneError("the recorded scene: " + std::string(tname.str()) + " is not a table");
    for (const auto& [key, v] : *table) into->insert_or_assign(key, v);
  }
  if (merged == recorded) return recorded_toml;

  std::ostringstream os;
  os << "# The recorded scene with the analysis of " << origin << " in place (a re-analysis)\n"
     << toml::toml_formatter(merged) << "\n";
  // What is written must read back as what was merged (every number to
  // its last bit), or the nodes and the file would go by another scene.
  if (scene_detail::parse_toml(os.str(), "the re-analysis scene") != merged)
    throw SceneError(origin + ": the merged scene does not read back as itself");
  parse_scene_text(os.str(), origin + " over the recorded scene"); // the scene's own checks
  return os.str();
}

} // namespace dynhet
