// Scene files: the schema of every table and key, each key checked alone as
// it is read (scene_check.cpp), then the checks between keys
// (scene_relations.cpp); every problem is named before one error is thrown.
#include "dynhet/scene.hpp"

#include <algorithm>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include <toml++/toml.h>

#include "dynhet/lcm_url.hpp" // cutoff_label
#include "dynhet/model.hpp"
#include "dynhet/subbox.hpp"
#include "scene_check.hpp"

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

Scene parse_scene_text(const std::string& text, const std::string& origin) {
  Scene s;
  s.path = origin;
  s.text = text;
  toml::table root;
  try {
    root = toml::parse(text, origin);
  } catch (const toml::parse_error& e) {
    std::ostringstream m;
    m << origin << ":" << e.source().begin.line << ":" << e.source().begin.column
      << ": not valid TOML: " << e.description();
    throw SceneError(m.str());
  }

  Checker c(origin);
  std::map<std::string, Table> schema;
  schema["system"] = {
      {"n_particles", int_in(c, s.n_particles, 2, std::numeric_limits<int32_t>::max())},
      {"packing_fraction",
       [&](const std::string& key, const toml::node& n) {
         double v;
         if (!c.get_double(key, n, v)) return;
         if (!(v > 0 && v < 0.9))
           return c.bad_value(key, n, "allowed: 0 < phi < 0.9 (hard disks jam below 0.9)");
         s.packing_fraction = v;
       }},
      {"restitution",
       [&](const std::string& key, const toml::node& n) {
         double v;
         if (!c.get_double(key, n, v)) return;
         if (!(v > 0 && v <= 1)) return c.bad_value(key, n, "allowed: 0 < eps <= 1");
         s.restitution = v;
       }},
      {"radius_ratio",
       [&](const std::string& key, const toml::node& n) {
         double v;
         if (!c.get_double(key, n, v)) return;
         if (!(v >= 1 && v <= 10)) return c.bad_value(key, n, "allowed: 1 <= r2/r1 <= 10");
         s.radius_ratio = v;
       }},
      {"tc_time", non_negative(c, s.tc_time)},
      {"initial_state",
       [&](const std::string& key, const toml::node& n) {
         const auto v = n.value_exact<std::string>();
         if (!v) return c.bad_type(key, n, "a string (the path of a prepared state or an H5MD file)");
         if (v->empty()) return c.bad_value(key, n, "give a path, or leave the key out to compress");
         s.initial_state = *v;
       }},
      {"seed",
       [&](const std::string& key, const toml::node& n) {
         int64_t v;
         if (!c.get_int(key, n, v)) return;
         if (v < 0) return c.bad_value(key, n, "it must be >= 0");
         s.seed = static_cast<uint64_t>(v);
       }},
  };
  schema["driving"] = {
      {"enabled", [&](const std::string& key, const toml::node& n) { c.get_bool(key, n, s.driving); }},
      {"kick_rate", number_or(c, s.kick_rate, "enskog")},
      {"contact_value",
       [&](const std::string& key, const toml::node& n) {
         if (n.is_string()) {
           const std::string v = *n.value<std::string>();
           if (v != "mixture" && v != "henderson")
             return c.bad_value(key, n, "allowed: \"mixture\", \"henderson\" or a number > 0");
           s.contact_recipe = v;
           s.contact_value = -1.0;
           return;
         }
         number_or(c, s.contact_value, "mixture")(key, n);
       }},
      {"pairs",
       [&](const std::string& key, const toml::node& n) {
         const auto v = n.value_exact<std::string>();
         if (!v) return c.bad_type(key, n, "a string, \"neighbours\" or \"any\"");
         if (*v != "neighbours" && *v != "any") return c.bad_value(key, n, "allowed: \"neighbours\" or \"any\"");
         s.kick_pairs = *v;
       }},
      {"reach",
       [&](const std::string& key, const toml::node& n) {
         double v;
         if (!c.get_double(key, n, v)) return;
         if (!(v > 0 && v <= 10))
           return c.bad_value(key, n, "allowed: 0 < reach <= 10 (a gap between surfaces, in small radii)");
         s.kick_reach = v;
       }},
  };
  schema["run"] = {
      {"equilibration_time", non_negative(c, s.equilibration_time)},
      {"production_time", positive(c, s.production_time)},
      {"checkpoint_interval", positive(c, s.checkpoint_interval)},
      {"checkpoint_wall_interval", non_negative(c, s.checkpoint_wall_interval)},
  };
  schema["schedule"] = {
      {"origins", int_in(c, s.schedule.origins, 1, 1000000)},
      {"origin_spacing", positive(c, s.schedule.origin_spacing)},
      {"lag_min", positive(c, s.schedule.lag_min)},
      {"lag_max", positive(c, s.schedule.lag_max)},
      {"lags_per_decade", int_in(c, s.schedule.lags_per_decade, 1, 1000)},
      {"extra_lags",
       [&](const std::string& key, const toml::node& n) {
         const auto* arr = n.as_array();
         if (!arr) return c.bad_type(key, n, "an array of lag times > 0");
         if (arr->size() > 16) return c.bad_value(key, n, "at most 16 extra lags");
         s.schedule.extra_lags.clear();
         for (const auto& e : *arr) {
           double v;
           if (!c.get_double(key, e, v)) return;
           if (v <= 0) return c.bad_value(key, e, "every extra lag must be > 0");
           s.schedule.extra_lags.push_back(v);
         }
       }},
  };
  schema["observables"] = {
      {"compute",
       [&](const std::string& key, const toml::node& n) {
         const auto* arr = n.as_array();
         if (!arr) return c.bad_type(key, n, "an array of strings");
         s.observables.clear();
         for (const auto& e : *arr) {
           auto v = e.value_exact<std::string>();
           if (!v) return c.bad_type(key, e, "a string");
           const auto& known = known_observables();
           if (std::find(s.observables.begin(), s.observables.end(), *v) != s.observables.end())
             return c.bad_value(key, e, "each observable may be named once");
           if (std::find(known.begin(), known.end(), *v) == known.end()) {
             std::string list;
             for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
             return c.bad_value(key, e, "known observables: " + list);
           }
           s.observables.push_back(*v);
         }
       }},
      {"cutoff_a",
       [&](const std::string& key, const toml::node& n) {
         const auto* arr = n.as_array();
         if (!arr || arr->empty()) return c.bad_type(key, n, "a non-empty array of numbers");
         s.cutoff_a.clear();
         for (const auto& e : *arr) {
           double v;
           if (!c.get_double(key, e, v)) return;
           if (v <= 0) return c.bad_value(key, e, "every cutoff a must be > 0");
           // A cutoff names its results' channels and groups (a0.6, six
           // significant digits): two that print alike would share them.
           for (double w : s.cutoff_a)
             if (cutoff_label(w) == cutoff_label(v))
               return c.bad_value(key, e, "each cutoff may be listed once (and cutoffs must differ in their "
                                          "first six significant digits, which name their results: " +
                                          cutoff_label(v) + ")");
           s.cutoff_a.push_back(v);
         }
       }},
      {"keep_frames",
       [&](const std::string& key, const toml::node& n) { c.get_bool(key, n, s.keep_frames); }},
      {"cage_relative",
       [&](const std::string& key, const toml::node& n) { c.get_bool(key, n, s.cage_relative); }},
      {"cage",
       [&](const std::string& key, const toml::node& n) {
         auto v = n.value_exact<std::string>();
         if (!v) return c.bad_type(key, n, "a string: \"voronoi\" or \"g_ab\"");
         if (*v != "voronoi" && *v != "g_ab") return c.bad_value(key, n, "allowed: \"voronoi\", \"g_ab\"");
         s.cage = *v;
       }},
  };
  schema["overlap"] = {
      {"subbox_particles", int_in(c, s.overlap_subbox_particles, 1, std::numeric_limits<int32_t>::max())},
  };
  schema["chi4"] = {
      {"subbox_particles", subbox_sizes(c, s.chi4_subbox_particles)},
  };
  schema["s4"] = {
      {"lags",
       [&](const std::string& key, const toml::node& n) {
         if (n.is_string()) {
           if (*n.value<std::string>() != "all") return c.bad_value(key, n, "allowed: \"all\" or an array of lag times > 0");
           s.s4_lags.clear();
           return;
         }
         const auto* arr = n.as_array();
         if (!arr || arr->empty()) return c.bad_type(key, n, "\"all\" or a non-empty array of lag times");
         s.s4_lags.clear();
         for (const auto& e : *arr) {
           double v;
           if (!c.get_double(key, e, v)) return;
           if (v <= 0) return c.bad_value(key, e, "every lag time must be > 0");
           s.s4_lags.push_back(v);
         }
       }},
      {"q_max", positive(c, s.s4_q_max)},
      {"grid_spacing", non_negative(c, s.s4_grid_spacing)},
      {"half_width", int_in(c, s.s4_half_width, 2, 16)},
      {"subbox_particles", subbox_sizes(c, s.s4_subbox_particles)},
  };
  auto& cl = s.clusters;
  schema["clusters"] = {
      {"lag", number_or(c, cl.lag, "tau_alpha")},
      {"neighbour_cutoffs",
       [&](const std::string& key, const toml::node& n) {
         if (n.is_string()) {
           if (*n.value<std::string>() != "g_ab")
             c.bad_value(key, n, "allowed: \"g_ab\" or [r11, r12, r22], each > 0");
           cl.neighbour_cutoffs.clear();
           return;
         }
         const auto* arr = n.as_array();
         if (!arr || arr->size() != 3) return c.bad_type(key, n, "\"g_ab\" or an array [r11, r12, r22]");
         std::vector<double> v;
         for (const auto& e : *arr) {
           double x;
           if (!c.get_double(key, e, x)) return;
           if (x <= 0) return c.bad_value(key, e, "every neighbour cutoff must be > 0");
           v.push_back(x);
         }
         cl.neighbour_cutoffs = v;
       }},
      {"cutoff_frames", int_in(c, cl.cutoff_frames, 1, 1000000)},
      {"gr_r_max", positive(c, cl.gr_r_max)},
      {"gr_bin", positive(c, cl.gr_bin)},
      {"gr_smoothing", non_negative(c, cl.gr_smoothing)},
      {"bins_per_decade", int_in(c, cl.bins_per_decade, 1, 100)},
      {"power_law_sizes", int_list(c, cl.power_law_sizes, 2)},
      {"min_bin_count", int_in(c, cl.min_bin_count, 1, 1000000000)},
      {"fractal_min_size", int_in(c, cl.fractal_min_size, 1, 1000000000)},
      {"error_blocks", int_in(c, cl.error_blocks, 2, 1000)},
  };
  schema["msd"] = {
      {"fraction_all", subset_fraction(c, s.msd.fraction_all)},
      {"fraction_small", subset_fraction(c, s.msd.fraction_small)},
      {"fs", [&](const std::string& key, const toml::node& n) { c.get_bool(key, n, s.msd.fs); }},
      {"fs_q", positive_list(c, s.msd.fs_q)},
  };
  schema["bond_breaking"] = {
      {"a1", [&](const std::string& key, const toml::node& n) { c.get_double(key, n, s.bond_breaking.a1); }},
      {"a2", [&](const std::string& key, const toml::node& n) { c.get_double(key, n, s.bond_breaking.a2); }},
  };
  auto& dp = s.displacement;
  schema["displacement"] = {
      {"lags_tau_alpha", positive_list(c, dp.lags_tau_alpha)},
      {"lags", positive_list(c, dp.lags)},
      {"x_max", positive(c, dp.x_max)},
      {"bin_width", positive(c, dp.bin_width)},
      {"tail_sigmas", non_negative(c, dp.tail_sigmas)},
      {"min_bin_count", int_in(c, dp.min_bin_count, 1, 1000000000)},
      {"error_blocks", int_in(c, dp.error_blocks, 2, 1000)},
  };
  schema["transport"] = {
      {"chunk_particles", int_in(c, s.chunk_particles, 1, 65000)}, // 16 B each: < 1 MiB
  };

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
  c.throw_if_failed();
  check_relations(s, c);
  c.throw_if_failed();
  // Sub-box sizes as the grids realise them: no size twice (notes say what
  // was dropped, and which sizes lie far from what was asked).
  s.chi4_subbox_particles = realisable_subbox_sizes(s.n_particles, s.chi4_subbox_particles, "chi4.subbox_particles",
                                                    s.notes);
  if (!s.s4_subbox_particles.empty())
    s.s4_subbox_particles = realisable_subbox_sizes(s.n_particles, s.s4_subbox_particles, "s4.subbox_particles",
                                                    s.notes);
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
