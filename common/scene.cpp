#include "dynhet/scene.hpp"

#include <charconv>
#include "dynhet/subbox.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <iomanip>
#include <limits>
#include <sstream>

#include <toml++/toml.h>

#include "dynhet/lcm_url.hpp" // cutoff_label
#include "dynhet/model.hpp"

namespace dynhet {
namespace {

const char* type_name(const toml::node& n) {
  switch (n.type()) {
  case toml::node_type::string: return "a string";
  case toml::node_type::integer: return "an integer";
  case toml::node_type::floating_point: return "a float";
  case toml::node_type::boolean: return "a boolean";
  case toml::node_type::array: return "an array";
  case toml::node_type::table: return "a table";
  default: return "a date/time";
  }
}

// A number as the shortest text that reads back as the same double (0.9,
// 1.0000000000000002, 1e+300): what the file says, never rounded away.
std::string num(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::string show(const toml::node& n) {
  std::ostringstream s;
  if (n.is_table()) return "{...}";
  if (auto d = n.value_exact<double>()) return num(*d);
  n.visit([&](auto&& v) { s << v; });
  return s.str();
}

// Collects every problem of a scene, then throws them together.
class Checker {
public:
  explicit Checker(std::string origin) : origin_(std::move(origin)) {}

  void fail(const std::string& key, const std::string& what) {
    errors_.push_back(origin_ + ": " + key + ": " + what);
  }
  void bad_value(const std::string& key, const toml::node& n, const std::string& allowed) {
    fail(key, "value " + show(n) + " is not allowed; " + allowed);
  }
  void bad_type(const std::string& key, const toml::node& n, const std::string& expected) {
    fail(key, "value " + show(n) + " is " + type_name(n) + ", expected " + expected);
  }
  bool ok() const { return errors_.empty(); }
  void throw_if_failed() const {
    if (errors_.empty()) return;
    std::string msg = "invalid scene (" + std::to_string(errors_.size()) + " problem" +
                      (errors_.size() > 1 ? "s" : "") + "):";
    for (const auto& e : errors_) msg += "\n  " + e;
    throw SceneError(msg);
  }

  bool get_int(const std::string& key, const toml::node& n, int64_t& out) {
    if (auto v = n.value_exact<int64_t>()) { out = *v; return true; }
    bad_type(key, n, "an integer");
    return false;
  }
  bool get_double(const std::string& key, const toml::node& n, double& out) {
    if (n.is_integer()) {
      // An integer beyond 2^53 has no exact double: refused, not rounded.
      const int64_t i = *n.value_exact<int64_t>();
      if (i > (int64_t{1} << 53) || i < -(int64_t{1} << 53)) {
        bad_value(key, n, "an integer beyond 2^53 is not exactly a number here; write it as a float (1e18)");
        return false;
      }
      out = static_cast<double>(i);
      return true;
    }
    if (n.is_floating_point()) {
      out = *n.value_exact<double>();
      if (std::isfinite(out)) return true;
      bad_value(key, n, "it must be a finite number");
      return false;
    }
    bad_type(key, n, "a number");
    return false;
  }
  bool get_bool(const std::string& key, const toml::node& n, bool& out) {
    if (auto v = n.value_exact<bool>()) { out = *v; return true; }
    bad_type(key, n, "a boolean (true or false)");
    return false;
  }

private:
  std::string origin_;
  std::vector<std::string> errors_;
};

using Handler = std::function<void(const std::string& key, const toml::node&)>;
using Table = std::map<std::string, Handler>;

std::string known_keys(const Table& t) {
  std::string s;
  for (const auto& [k, h] : t) s += (s.empty() ? "" : ", ") + k;
  return s;
}

} // namespace

const std::vector<std::string>& known_observables() {
  static const std::vector<std::string> v{"overlap", "chi4", "msd", "displacement", "clusters", "s4", "bond_breaking"};
  return v;
}

bool has_cage_relative(const std::string& o) {
  return o == "overlap" || o == "chi4" || o == "msd" || o == "displacement" || o == "s4" || o == "clusters";
}

std::string node_of(const std::string& observable) {
  std::string o = observable;
  if (o.size() > 3 && o.compare(o.size() - 3, 3, "_cr") == 0) o.resize(o.size() - 3);
  return o == "chi4" || o == "msd" || o == "displacement" || o == "bond_breaking" ? "overlap" : o;
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
  // A positive number (time or length) under `key`.
  auto positive = [&](double& out) {
    return [&c, &out](const std::string& key, const toml::node& n) {
      double v;
      if (!c.get_double(key, n, v)) return;
      if (v <= 0) return c.bad_value(key, n, "it must be > 0");
      out = v;
    };
  };
  auto non_negative = [&](double& out) {
    return [&c, &out](const std::string& key, const toml::node& n) {
      double v;
      if (!c.get_double(key, n, v)) return;
      if (v < 0) return c.bad_value(key, n, "it must be >= 0");
      out = v;
    };
  };
  auto int_in = [&](auto& out, int64_t lo, int64_t hi) {
    return [&c, &out, lo, hi](const std::string& key, const toml::node& n) {
      int64_t v;
      if (!c.get_int(key, n, v)) return;
      if (v < lo || v > hi)
        return c.bad_value(key, n,
                           "allowed: " + std::to_string(lo) + " <= value <= " + std::to_string(hi));
      out = static_cast<std::remove_reference_t<decltype(out)>>(v);
    };
  };
  // A number, or a string naming the default recipe (stored as -1).
  auto number_or = [&](double& out, const std::string& word) {
    return [&c, &out, word](const std::string& key, const toml::node& n) {
      if (n.is_string()) {
        if (*n.value<std::string>() != word)
          return c.bad_value(key, n, "allowed: \"" + word + "\" or a number > 0");
        out = -1.0;
        return;
      }
      double v;
      if (!c.get_double(key, n, v)) return;
      if (v <= 0) return c.bad_value(key, n, "allowed: \"" + word + "\" or a number > 0");
      out = v;
    };
  };

  std::map<std::string, Table> schema;
  schema["system"] = {
      {"n_particles", int_in(s.n_particles, 2, std::numeric_limits<int32_t>::max())},
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
      {"tc_time", non_negative(s.tc_time)},
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
      {"kick_rate", number_or(s.kick_rate, "enskog")},
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
         number_or(s.contact_value, "mixture")(key, n);
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
      {"equilibration_time", non_negative(s.equilibration_time)},
      {"production_time", positive(s.production_time)},
      {"checkpoint_interval", positive(s.checkpoint_interval)},
      {"checkpoint_wall_interval", non_negative(s.checkpoint_wall_interval)},
  };
  schema["schedule"] = {
      {"origins", int_in(s.schedule.origins, 1, 1000000)},
      {"origin_spacing", positive(s.schedule.origin_spacing)},
      {"lag_min", positive(s.schedule.lag_min)},
      {"lag_max", positive(s.schedule.lag_max)},
      {"lags_per_decade", int_in(s.schedule.lags_per_decade, 1, 1000)},
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
      {"subbox_particles", int_in(s.overlap_subbox_particles, 1, std::numeric_limits<int32_t>::max())},
  };
  // A non-empty list of sub-box sizes (target particles per sub-box).
  auto subbox_sizes = [&](std::vector<int>& out) {
    return [&c, &out](const std::string& key, const toml::node& n) {
      const auto* arr = n.as_array();
      if (!arr || arr->empty()) return c.bad_type(key, n, "a non-empty array of integers");
      out.clear();
      for (const auto& e : *arr) {
        int64_t v;
        if (!c.get_int(key, e, v)) return;
        if (v < 1) return c.bad_value(key, e, "every size must be >= 1 particle per sub-box");
        out.push_back(static_cast<int>(std::min<int64_t>(v, 1 << 30)));
      }
    };
  };
  schema["chi4"] = {
      {"subbox_particles", subbox_sizes(s.chi4_subbox_particles)},
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
      {"q_max", positive(s.s4_q_max)},
      {"grid_spacing", non_negative(s.s4_grid_spacing)},
      {"half_width", int_in(s.s4_half_width, 2, 16)},
      {"subbox_particles", subbox_sizes(s.s4_subbox_particles)},
  };
  auto& cl = s.clusters;
  auto int_list = [&](std::vector<int64_t>& out, size_t size) {
    return [&c, &out, size](const std::string& key, const toml::node& n) {
      const auto* arr = n.as_array();
      if (!arr || arr->size() != size)
        return c.bad_type(key, n, "an array of " + std::to_string(size) + " integers");
      std::vector<int64_t> v;
      for (const auto& e : *arr) {
        int64_t x;
        if (!c.get_int(key, e, x)) return;
        v.push_back(x);
      }
      out = v;
    };
  };
  schema["clusters"] = {
      {"lag", number_or(cl.lag, "tau_alpha")},
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
      {"cutoff_frames", int_in(cl.cutoff_frames, 1, 1000000)},
      {"gr_r_max", positive(cl.gr_r_max)},
      {"gr_bin", positive(cl.gr_bin)},
      {"gr_smoothing", non_negative(cl.gr_smoothing)},
      {"bins_per_decade", int_in(cl.bins_per_decade, 1, 100)},
      {"power_law_sizes", int_list(cl.power_law_sizes, 2)},
      {"min_bin_count", int_in(cl.min_bin_count, 1, 1000000000)},
      {"fractal_min_size", int_in(cl.fractal_min_size, 1, 1000000000)},
      {"error_blocks", int_in(cl.error_blocks, 2, 1000)},
  };
  // A fraction of a set of particles for the fastest and slowest subsets.
  auto subset_fraction = [&](double& out) {
    return [&c, &out](const std::string& key, const toml::node& n) {
      double v;
      if (!c.get_double(key, n, v)) return;
      if (!(v > 0 && v <= 0.5)) return c.bad_value(key, n, "allowed: 0 < fraction <= 0.5");
      out = v;
    };
  };
  auto positive_list = [&](std::vector<double>& out) {
    return [&c, &out](const std::string& key, const toml::node& n) {
      const auto* arr = n.as_array();
      if (!arr) return c.bad_type(key, n, "an array of numbers > 0 (may be empty)");
      std::vector<double> v;
      for (const auto& e : *arr) {
        double x;
        if (!c.get_double(key, e, x)) return;
        if (x <= 0) return c.bad_value(key, e, "every entry must be > 0");
        v.push_back(x);
      }
      out = v;
    };
  };
  schema["msd"] = {
      {"fraction_all", subset_fraction(s.msd.fraction_all)},
      {"fraction_small", subset_fraction(s.msd.fraction_small)},
      {"fs", [&](const std::string& key, const toml::node& n) { c.get_bool(key, n, s.msd.fs); }},
      {"fs_q", positive_list(s.msd.fs_q)},
  };
  schema["bond_breaking"] = {
      {"a1", [&](const std::string& key, const toml::node& n) { c.get_double(key, n, s.bond_breaking.a1); }},
      {"a2", [&](const std::string& key, const toml::node& n) { c.get_double(key, n, s.bond_breaking.a2); }},
  };
  auto& dp = s.displacement;
  schema["displacement"] = {
      {"lags_tau_alpha", positive_list(dp.lags_tau_alpha)},
      {"lags", positive_list(dp.lags)},
      {"x_max", positive(dp.x_max)},
      {"bin_width", positive(dp.bin_width)},
      {"tail_sigmas", non_negative(dp.tail_sigmas)},
      {"min_bin_count", int_in(dp.min_bin_count, 1, 1000000000)},
      {"error_blocks", int_in(dp.error_blocks, 2, 1000)},
  };
  schema["transport"] = {
      {"chunk_particles", int_in(s.chunk_particles, 1, 65000)}, // 16 B each: < 1 MiB
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

  // Relations between keys.
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
