// The one description of a scene's tables and keys (scene_keys.hpp).
#include "scene_keys.hpp"

#include <algorithm>
#include <limits>
#include <type_traits>

#include "dynhet/lcm_url.hpp" // cutoff_label

namespace dynhet::scene_detail {
namespace {

// TOML text of a value: floats always with a point or an exponent (so that a
// reader takes 100.0 for the float it is), strings quoted, arrays inline.
std::string toml(double v) { return toml_float(v); }
std::string toml(const std::string& s) {
  std::string t = "\"";
  for (char ch : s) {
    if (ch == '"' || ch == '\\') t += '\\';
    t += ch;
  }
  return t + "\"";
}
template <class T> std::string toml(const T& v) {
  if constexpr (std::is_same_v<T, bool>) {
    return v ? "true" : "false";
  } else if constexpr (std::is_integral_v<T>) {
    return std::to_string(v);
  } else { // a std::vector
    std::string t = "[";
    for (size_t i = 0; i < v.size(); ++i) t += (i ? ", " : "") + toml(v[i]);
    return t + "]";
  }
}

// A scene's member, for reading (Scene&) and writing (const Scene&) alike.
#define MEMBER(m) [](auto& s) -> auto& { return s.m; }

// A key stored in one member by a handler factory make(Checker&, member&),
// written back as the member's TOML text.
template <class Get, class Make>
SceneKey key(const char* table, const char* name, std::string allowed, std::string meaning, Get get, Make make) {
  return {table, name, std::move(allowed), std::move(meaning),
          [get, make](Checker& c, Scene& s) { return make(c, get(s)); },
          [get](const Scene& s) { return toml(get(s)); }, ""};
}

auto int_range(int64_t lo, int64_t hi) {
  return [lo, hi](Checker& c, auto& out) { return int_in(c, out, lo, hi); };
}
std::string int_allowed(int64_t lo, int64_t hi) {
  return "an integer, " + std::to_string(lo) + " <= value <= " + std::to_string(hi);
}
Handler any_number(Checker& c, double& out) {
  return [&c, &out](const std::string& key, const toml::node& n) { c.get_double(key, n, out); };
}
Handler boolean(Checker& c, bool& out) {
  return [&c, &out](const std::string& key, const toml::node& n) { c.get_bool(key, n, out); };
}
// A number in (lo, hi] or [lo, hi] (closed_lo), refused with `allowed`.
auto number_in(double lo, double hi, bool closed_lo, bool closed_hi, std::string allowed) {
  return [=](Checker& c, double& out) -> Handler {
    return [=, &c, &out](const std::string& key, const toml::node& n) {
      double v;
      if (!c.get_double(key, n, v)) return;
      const bool ok = (closed_lo ? v >= lo : v > lo) && (closed_hi ? v <= hi : v < hi);
      if (!ok) return c.bad_value(key, n, allowed);
      out = v;
    };
  };
}
// A string among `words`, refused with the type `expected` or `allowed`.
auto one_of(std::vector<std::string> words, std::string expected, std::string allowed) {
  return [=](Checker& c, std::string& out) -> Handler {
    return [=, &c, &out](const std::string& key, const toml::node& n) {
      const auto v = n.value_exact<std::string>();
      if (!v) return c.bad_type(key, n, expected);
      if (std::find(words.begin(), words.end(), *v) == words.end()) return c.bad_value(key, n, allowed);
      out = *v;
    };
  };
}

std::string known_list() {
  std::string list;
  for (const auto& k : known_observables()) list += (list.empty() ? "" : ", ") + k;
  return list;
}

Handler read_compute(Checker& c, std::vector<std::string>& out) {
  return [&c, &out](const std::string& key, const toml::node& n) {
    const auto* arr = n.as_array();
    if (!arr) return c.bad_type(key, n, "an array of strings");
    out.clear();
    for (const auto& e : *arr) {
      auto v = e.value_exact<std::string>();
      if (!v) return c.bad_type(key, e, "a string");
      const auto& known = known_observables();
      if (std::find(out.begin(), out.end(), *v) != out.end())
        return c.bad_value(key, e, "each observable may be named once");
      if (std::find(known.begin(), known.end(), *v) == known.end())
        return c.bad_value(key, e, "known observables: " + known_list());
      out.push_back(*v);
    }
  };
}

Handler read_cutoffs(Checker& c, std::vector<double>& out) {
  return [&c, &out](const std::string& key, const toml::node& n) {
    const auto* arr = n.as_array();
    if (!arr || arr->empty()) return c.bad_type(key, n, "a non-empty array of numbers");
    out.clear();
    for (const auto& e : *arr) {
      double v;
      if (!c.get_double(key, e, v)) return;
      if (v <= 0) return c.bad_value(key, e, "every cutoff a must be > 0");
      // A cutoff names its results' channels and groups (a0.6, six
      // significant digits): two that print alike would share them.
      for (double w : out)
        if (cutoff_label(w) == cutoff_label(v))
          return c.bad_value(key, e, "each cutoff may be listed once (and cutoffs must differ in their "
                                     "first six significant digits, which name their results: " +
                                         cutoff_label(v) + ")");
      out.push_back(v);
    }
  };
}

Handler read_extra_lags(Checker& c, std::vector<double>& out) {
  return [&c, &out](const std::string& key, const toml::node& n) {
    const auto* arr = n.as_array();
    if (!arr) return c.bad_type(key, n, "an array of lag times > 0");
    if (arr->size() > 16) return c.bad_value(key, n, "at most 16 extra lags");
    out.clear();
    for (const auto& e : *arr) {
      double v;
      if (!c.get_double(key, e, v)) return;
      if (v <= 0) return c.bad_value(key, e, "every extra lag must be > 0");
      out.push_back(v);
    }
  };
}

Handler read_s4_lags(Checker& c, std::vector<double>& out) {
  return [&c, &out](const std::string& key, const toml::node& n) {
    if (n.is_string()) {
      if (*n.value<std::string>() != "all") return c.bad_value(key, n, "allowed: \"all\" or an array of lag times > 0");
      out.clear();
      return;
    }
    const auto* arr = n.as_array();
    if (!arr || arr->empty()) return c.bad_type(key, n, "\"all\" or a non-empty array of lag times");
    out.clear();
    for (const auto& e : *arr) {
      double v;
      if (!c.get_double(key, e, v)) return;
      if (v <= 0) return c.bad_value(key, e, "every lag time must be > 0");
      out.push_back(v);
    }
  };
}

Handler read_neighbour_cutoffs(Checker& c, std::vector<double>& out) {
  return [&c, &out](const std::string& key, const toml::node& n) {
    if (n.is_string()) {
      if (*n.value<std::string>() != "g_ab") c.bad_value(key, n, "allowed: \"g_ab\" or [r11, r12, r22], each > 0");
      out.clear();
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
    out = v;
  };
}

Handler read_initial_state(Checker& c, std::string& out) {
  return [&c, &out](const std::string& key, const toml::node& n) {
    const auto v = n.value_exact<std::string>();
    if (!v) return c.bad_type(key, n, "a string (the path of a prepared state or an H5MD file)");
    if (v->empty()) return c.bad_value(key, n, "give a path, or leave the key out to compress");
    out = *v;
  };
}

Handler read_seed(Checker& c, uint64_t& out) {
  return [&c, &out](const std::string& key, const toml::node& n) {
    int64_t v;
    if (!c.get_int(key, n, v)) return;
    if (v < 0) return c.bad_value(key, n, "it must be >= 0");
    out = static_cast<uint64_t>(v);
  };
}

// driving.contact_value: a recipe's name or a number, in two members.
SceneKey contact_value_key() {
  return {"driving", "contact_value", "\"mixture\", \"henderson\" or a number > 0",
          "G_c in omega: the binary mixture's Jenkins-Mancini g_ij weighted by collisions (\"mixture\"), "
          "Henderson's monodisperse (1 - 7 phi/16)/(1 - phi)^2, or this number",
          [](Checker& c, Scene& s) -> Handler {
            return [&c, &s](const std::string& key, const toml::node& n) {
              if (n.is_string()) {
                const std::string v = *n.value<std::string>();
                if (v != "mixture" && v != "henderson")
                  return c.bad_value(key, n, "allowed: \"mixture\", \"henderson\" or a number > 0");
                s.contact_recipe = v;
                s.contact_value = -1.0;
                return;
              }
              number_or(c, s.contact_value, "mixture")(key, n);
            };
          },
          [](const Scene& s) { return s.contact_value > 0 ? toml(s.contact_value) : toml(s.contact_recipe); }, ""};
}

// A key whose default is a word (stored as -1 or as an empty list) and
// whose other values are numbers: written as the word where it holds.
template <class Get, class Make>
SceneKey word_or(const char* table, const char* name, const char* word, std::string allowed, std::string meaning,
                 Get get, Make make) {
  SceneKey k = key(table, name, std::move(allowed), std::move(meaning), get, make);
  k.write = [get, word](const Scene& s) {
    const auto& v = get(s);
    bool is_word;
    if constexpr (std::is_same_v<std::decay_t<decltype(v)>, double>) is_word = v < 0;
    else is_word = v.empty();
    return is_word ? toml(std::string(word)) : toml(v);
  };
  return k;
}

std::vector<SceneKey> describe() {
  const int64_t int32_max = std::numeric_limits<int32_t>::max();
  std::vector<SceneKey> k;
  // [system]
  k.push_back(key("system", "n_particles", int_allowed(2, int32_max),
                  "number of disks, half small and half large (the odd one small)", MEMBER(n_particles),
                  int_range(2, int32_max)));
  k.push_back(key("system", "packing_fraction", "0 < phi < 0.9 (hard disks jam below 0.9)", "packing fraction phi",
                  MEMBER(packing_fraction),
                  number_in(0, 0.9, false, false, "allowed: 0 < phi < 0.9 (hard disks jam below 0.9)")));
  k.push_back(key("system", "restitution", "0 < eps <= 1", "coefficient of normal restitution eps",
                  MEMBER(restitution), number_in(0, 1, false, true, "allowed: 0 < eps <= 1")));
  k.push_back(key("system", "radius_ratio", "1 <= r2/r1 <= 10",
                  "r2/r1, the large disks' radius in small radii (m2/m1 its square); 1 is monodisperse",
                  MEMBER(radius_ratio), number_in(1, 10, true, true, "allowed: 1 <= r2/r1 <= 10")));
  k.push_back(key("system", "seed", "an integer >= 0", "the random stream: same seed, same build, same trajectory",
                  MEMBER(seed), read_seed));
  k.push_back(key("system", "tc_time", "a number >= 0",
                  "TC model: a collision within this time of either particle's previous one is elastic; 0 is off",
                  MEMBER(tc_time), non_negative));
  SceneKey initial = key("system", "initial_state", "a path, relative to the scene file",
                         "start from this prepared or equilibrated state (sim_node --prepare-only) or from an H5MD "
                         "file's positions instead of compressing",
                         MEMBER(initial_state), read_initial_state);
  initial.write = [](const Scene& s) { return s.initial_state.empty() ? std::string() : toml(s.initial_state); };
  initial.default_text = "none: compress";
  k.push_back(initial);
  // [driving]
  k.push_back(key("driving", "enabled", "true or false", "pair kicks of opposite momenta (none if eps = 1)",
                  MEMBER(driving), boolean));
  k.push_back(word_or("driving", "kick_rate", "enskog", "\"enskog\" or a number > 0",
                      "kicks per particle per unit time: the Enskog collision frequency omega = 2.59 phi G_c / "
                      "sqrt(pi), or this number",
                      MEMBER(kick_rate), [](Checker& c, double& out) { return number_or(c, out, "enskog"); }));
  k.push_back(contact_value_key());
  k.push_back(key("driving", "pairs", "\"neighbours\" or \"any\"",
                  "kick pairs: the second within `reach` of the first's surface, or any two particles",
                  MEMBER(kick_pairs),
                  one_of({"neighbours", "any"}, "a string, \"neighbours\" or \"any\"",
                         "allowed: \"neighbours\" or \"any\"")));
  k.push_back(key("driving", "reach", "0 < reach <= 10",
                  "neighbour pairs: the largest gap between the two surfaces, in small radii", MEMBER(kick_reach),
                  number_in(0, 10, false, true,
                            "allowed: 0 < reach <= 10 (a gap between surfaces, in small radii)")));
  // [run]
  k.push_back(key("run", "equilibration_time", "a number >= 0", "time before the production; t = 0 at its start",
                  MEMBER(equilibration_time), non_negative));
  SceneKey production = key("run", "production_time", "a number > 0, at least what the schedule needs",
                            "the production's length", MEMBER(production_time), positive);
  production.write = [](const Scene& s) { return s.production_time < 0 ? std::string() : toml(s.production_time); };
  production.default_text = "what the schedule needs: (origins - 1) origin_spacing + lag_max";
  k.push_back(production);
  k.push_back(key("run", "checkpoint_interval", "a number > 0",
                  "every particle is synchronised (and a checkpoint written when asked) at multiples of this time",
                  MEMBER(checkpoint_interval), positive));
  k.push_back(key("run", "checkpoint_wall_interval", "a number >= 0",
                  "wall-clock seconds between checkpoint cuts; 0: one at every checkpoint_interval",
                  MEMBER(checkpoint_wall_interval), non_negative));
  // [schedule]
  k.push_back(key("schedule", "origins", int_allowed(1, 1000000), "number of time origins t0",
                  MEMBER(schedule.origins), int_range(1, 1000000)));
  k.push_back(key("schedule", "origin_spacing", "a number > 0", "dt0 between origins, from the end of equilibration",
                  MEMBER(schedule.origin_spacing), positive));
  k.push_back(key("schedule", "lag_min", "a number > 0, < lag_max", "the smallest lag tau",
                  MEMBER(schedule.lag_min), positive));
  k.push_back(key("schedule", "lag_max", "a number > 0", "the largest lag tau", MEMBER(schedule.lag_max), positive));
  k.push_back(key("schedule", "lags_per_decade", int_allowed(1, 1000), "log spacing of the lags",
                  MEMBER(schedule.lags_per_decade), int_range(1, 1000)));
  k.push_back(key("schedule", "extra_lags", "at most 16 times within [lag_min, lag_max]",
                  "lags added to the log-spaced ones", MEMBER(schedule.extra_lags), read_extra_lags));
  // [observables]
  k.push_back(key("observables", "compute", "an array of: " + known_list(),
                  "the observables to compute; their nodes are started", MEMBER(observables), read_compute));
  k.push_back(key("observables", "cutoff_a", "a non-empty array of numbers > 0, each once",
                  "cutoffs a: slow |dr| < a, fast |dr| > 3a; all from the same frames", MEMBER(cutoff_a),
                  read_cutoffs));
  k.push_back(key("observables", "keep_frames", "true or false", "the recorder also stores the trajectory",
                  MEMBER(keep_frames), boolean));
  k.push_back(key("observables", "cage_relative", "true or false",
                  "every observable that has one also of cage-relative displacements, in groups <name>_cr",
                  MEMBER(cage_relative), boolean));
  k.push_back(key("observables", "cage", "\"voronoi\" or \"g_ab\"",
                  "the cages: Voronoi neighbours, or neighbours within the first minima of g_ab", MEMBER(cage),
                  one_of({"voronoi", "g_ab"}, "a string: \"voronoi\" or \"g_ab\"", "allowed: \"voronoi\", \"g_ab\"")));
  // [overlap], [chi4]
  k.push_back(key("overlap", "subbox_particles", int_allowed(1, int32_max), "N = <N_r> per sub-box of Q_r(t)",
                  MEMBER(overlap_subbox_particles), int_range(1, int32_max)));
  k.push_back(key("chi4", "subbox_particles", "a non-empty array of integers >= 1",
                  "N = <N_r> of each sub-box grid; >= n_particles: the whole box", MEMBER(chi4_subbox_particles),
                  subbox_sizes));
  // [msd]
  k.push_back(key("msd", "fraction_all", "0 < fraction <= 0.5",
                  "MSD of the instantaneous fastest and slowest this fraction of all particles",
                  MEMBER(msd.fraction_all), subset_fraction));
  k.push_back(key("msd", "fraction_small", "0 < fraction <= 0.5", "... and this fraction of the small ones",
                  MEMBER(msd.fraction_small), subset_fraction));
  k.push_back(key("msd", "fs", "true or false", "F_s(q, t) at q = 2 pi / sigma_11, sigma_12, sigma_22",
                  MEMBER(msd.fs), boolean));
  k.push_back(key("msd", "fs_q", "an array of at most 16 numbers > 0", "F_s at these wave numbers too (1/r1)",
                  MEMBER(msd.fs_q), positive_list));
  // [displacement]
  k.push_back(key("displacement", "lags_tau_alpha", "an array of numbers > 0",
                  "P(dx, t) at the scheduled lags nearest these multiples of tau_alpha",
                  MEMBER(displacement.lags_tau_alpha), positive_list));
  k.push_back(key("displacement", "lags", "an array of numbers > 0", "... and nearest these times",
                  MEMBER(displacement.lags), positive_list));
  k.push_back(key("displacement", "x_max", "a number > 0", "histogram over -x_max <= dx < x_max ...",
                  MEMBER(displacement.x_max), positive));
  k.push_back(key("displacement", "bin_width", "a number > 0, 10 to 4000 bins", "... in bins of this width",
                  MEMBER(displacement.bin_width), positive));
  k.push_back(key("displacement", "tail_sigmas", "a number >= 0",
                  "exponential tail fitted over |dx| >= tail_sigmas sqrt(<dx^2>)", MEMBER(displacement.tail_sigmas),
                  non_negative));
  k.push_back(key("displacement", "min_bin_count", int_allowed(1, 1000000000),
                  "bins with fewer displacements stay out of the fits", MEMBER(displacement.min_bin_count),
                  int_range(1, 1000000000)));
  k.push_back(key("displacement", "error_blocks", int_allowed(2, 1000),
                  "errors: jackknife over at most this many blocks of consecutive origins",
                  MEMBER(displacement.error_blocks), int_range(2, 1000)));
  // [s4]
  k.push_back(word_or("s4", "lags", "all", "\"all\" or a non-empty array of times within the lags",
                      "lags S4(q,t) is computed at: every scheduled lag, or the ones nearest these times",
                      MEMBER(s4_lags), read_s4_lags));
  k.push_back(key("s4", "q_max", "a number > 0", "the largest |q| (1/r1)", MEMBER(s4_q_max), positive));
  k.push_back(key("s4", "grid_spacing", "0 or a number < pi / q_max",
                  "NUFFT grid spacing h; 0: pi / (2 q_max) (oversampling 2)", MEMBER(s4_grid_spacing),
                  non_negative));
  k.push_back(key("s4", "half_width", int_allowed(2, 16), "Gaussian half-width in grid points",
                  MEMBER(s4_half_width), int_range(2, 16)));
  SceneKey s4_sizes = key("s4", "subbox_particles", "a non-empty array of integers >= 1",
                          "sub-box sizes (the whole box is always added)", MEMBER(s4_subbox_particles), subbox_sizes);
  s4_sizes.write = [](const Scene& s) {
    return toml(s.s4_subbox_particles.empty() ? s.chi4_subbox_particles : s.s4_subbox_particles);
  };
  s4_sizes.default_text = "[chi4]'s";
  k.push_back(s4_sizes);
  // [clusters]
  k.push_back(word_or("clusters", "lag", "tau_alpha", "\"tau_alpha\" or a number > 0",
                      "the lag of the clusters: the scheduled lag nearest the running tau_alpha, or nearest this time",
                      MEMBER(clusters.lag),
                      [](Checker& c, double& out) { return number_or(c, out, "tau_alpha"); }));
  k.push_back(word_or("clusters", "neighbour_cutoffs", "g_ab", "\"g_ab\" or [r11, r12, r22], each > 0",
                      "neighbour cutoffs: the first minima of the smoothed g_ab(r), or these",
                      MEMBER(clusters.neighbour_cutoffs), read_neighbour_cutoffs));
  k.push_back(key("clusters", "cutoff_frames", int_allowed(1, 1000000) + ", at most the origins",
                  "origin frames in g_ab before the cutoffs are fixed", MEMBER(clusters.cutoff_frames),
                  int_range(1, 1000000)));
  k.push_back(key("clusters", "gr_r_max", "a number > 0, at most half the box side",
                  "g_ab(r) for r < gr_r_max ...", MEMBER(clusters.gr_r_max), positive));
  k.push_back(key("clusters", "gr_bin", "a number > 0, 10 to 10^5 bins", "... in bins of this width",
                  MEMBER(clusters.gr_bin), positive));
  k.push_back(key("clusters", "gr_smoothing", "a number >= 0",
                  "Gaussian width of the smoothing before the first minimum is sought", MEMBER(clusters.gr_smoothing),
                  non_negative));
  k.push_back(key("clusters", "bins_per_decade", int_allowed(1, 100), "log bins of N_c",
                  MEMBER(clusters.bins_per_decade), int_range(1, 100)));
  k.push_back(key("clusters", "power_law_sizes", "[lo, hi], integers, 1 <= lo < hi",
                  "N_c range of the kappa fit (slow clusters)", MEMBER(clusters.power_law_sizes),
                  [](Checker& c, std::vector<int64_t>& out) { return int_list(c, out, 2); }));
  k.push_back(key("clusters", "min_bin_count", int_allowed(1, 1000000000), "bins with fewer clusters stay out of the fits",
                  MEMBER(clusters.min_bin_count), int_range(1, 1000000000)));
  k.push_back(key("clusters", "fractal_min_size", int_allowed(1, 1000000000), "the smallest N_c in the d_f fit",
                  MEMBER(clusters.fractal_min_size), int_range(1, 1000000000)));
  k.push_back(key("clusters", "error_blocks", int_allowed(2, 1000),
                  "errors: jackknife over at most this many blocks of consecutive origins",
                  MEMBER(clusters.error_blocks), int_range(2, 1000)));
  // [bond_breaking]
  k.push_back(key("bond_breaking", "a1", "0 < a1 < a2", "a bond joins i, j closer than a1 sigma_ij at the origin ...",
                  MEMBER(bond_breaking.a1), any_number));
  k.push_back(key("bond_breaking", "a2", "a1 < a2 < 10", "... and is broken once they are farther than a2 sigma_ij",
                  MEMBER(bond_breaking.a2), any_number));
  // [transport]
  k.push_back(key("transport", "chunk_particles", int_allowed(1, 65000),
                  "particles per frame chunk (16 B each: under 1 MiB)", MEMBER(chunk_particles), int_range(1, 65000)));
  return k;
}

#undef MEMBER

} // namespace

const std::vector<SceneKey>& scene_keys() {
  static const std::vector<SceneKey> keys = describe();
  return keys;
}

} // namespace dynhet::scene_detail
