// Scene files: the file's TOML read key by key against the description of
// every table and key (scene_keys.cpp), each key checked alone as it is read
// (scene_check.cpp), then the checks between keys (scene_relations.cpp);
// every problem is named before one error is thrown.
#include "dynhet/scene.hpp"

#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>

#include <toml++/toml.h>

#include "dynhet/model.hpp"
#include "dynhet/observables.hpp"
#include "dynhet/subbox.hpp"
#include "scene_check.hpp"
#include "scene_keys.hpp"

namespace dynhet {
using namespace scene_detail;

// The observables are declared in their .lcm files (dynhet/observables.hpp).
const std::vector<std::string>& known_observables() {
  static const std::vector<std::string> v = [] {
    std::vector<std::string> names;
    for (const ObservableInfo& o : kObservables) names.push_back(o.name);
    return names;
  }();
  return v;
}

bool has_cage_relative(const std::string& o) {
  const ObservableInfo* info = find_observable(o);
  return info && info->cage_relative;
}

std::string node_of(const std::string& observable) {
  const ObservableInfo* info = find_computed_observable(observable);
  return info ? info->node : observable;
}

std::vector<std::string> nodes_for(const std::vector<std::string>& observables) {
  std::vector<std::string> nodes;
  for (const auto& o : observables) {
    const std::string n = node_of(o) + "_node";
    if (std::find(nodes.begin(), nodes.end(), n) == nodes.end()) nodes.push_back(n);
  }
  return nodes;
}

double scene_contact_value(const Scene& s) {
  if (s.contact_value > 0) return s.contact_value;
  return s.contact_recipe == "henderson" ? henderson_contact_value(s.packing_fraction)
                                         : mixture_contact_value(s.packing_fraction, s.radius_ratio);
}

double scene_kick_rate(const Scene& s) {
  return s.kick_rate > 0 ? s.kick_rate : enskog_frequency(s.packing_fraction, scene_contact_value(s));
}

bool Scene::wants(const std::string& o) const {
  return std::find(observables.begin(), observables.end(), o) != observables.end();
}

std::vector<std::string> Scene::computed_observables() const {
  std::vector<std::string> v = observables;
  if (cage_relative)
    for (const auto& o : observables)
      if (has_cage_relative(o)) v.push_back(o + "_cr");
  return v;
}

namespace {

// Every table's keys (scene_keys.cpp), each bound to its place in s.
std::map<std::string, Table> bind_schema(Checker& c, Scene& s) {
  std::map<std::string, Table> schema;
  for (const SceneKey& k : scene_keys()) schema[k.table][k.key] = k.reader(c, s);
  return schema;
}

// Each key of the file read alone; unknown tables and keys named with the
// known ones.
void read_keys(const toml::table& root, std::map<std::string, Table>& schema, Checker& c) {
  for (const auto& [table_name, node] : root) {
    const std::string tname(table_name.str());
    auto it = schema.find(tname);
    if (it == schema.end()) {
      std::string list;
      for (const auto& [k, t] : schema) list += (list.empty() ? "" : ", ") + ("[" + k + "]");
      c.fail(tname, "unknown table; known tables: " + list);
      continue;
    }
    const auto* table = node.as_table();
    if (!table) {
      c.bad_type(tname, node, "a table [" + tname + "]");
      continue;
    }
    for (const auto& [key, value] : *table) {
      const std::string full = tname + "." + std::string(key.str());
      auto h = it->second.find(std::string(key.str()));
      if (h == it->second.end()) {
        c.fail(full, "unknown key; known keys in [" + tname + "]: " + known_keys(it->second));
        continue;
      }
      h->second(full, value);
    }
  }
}

// Sub-box sizes as the grids realise them: no size twice (notes say what
// was dropped, and which sizes lie far from what was asked).
void realise_subbox_sizes(Scene& s) {
  s.chi4_subbox_particles = realisable_subbox_sizes(s.n_particles, s.chi4_subbox_particles, "chi4.subbox_particles",
                                                    s.notes);
  if (!s.s4_subbox_particles.empty())
    s.s4_subbox_particles = realisable_subbox_sizes(s.n_particles, s.s4_subbox_particles, "s4.subbox_particles",
                                                    s.notes);
}

} // namespace

Scene parse_scene_text(const std::string& text, const std::string& origin) {
  Scene s;
  s.path = origin;
  s.text = text;
  const toml::table root = parse_toml(text, origin);
  Checker c(origin);
  std::map<std::string, Table> schema = bind_schema(c, s);
  read_keys(root, schema, c);
  c.throw_if_failed();
  check_relations(s, c);
  c.throw_if_failed();
  realise_subbox_sizes(s);
  return s;
}

Scene parse_scene_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw SceneError(path + ": cannot open the scene file");
  std::stringstream buf;
  buf << in.rdbuf();
  return parse_scene_text(buf.str(), path);
}

} // namespace dynhet
