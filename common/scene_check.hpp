#pragma once
// The scene parser's parts (scene.cpp): a checker that collects every
// problem of a scene before it throws them together, the typed key handlers
// its schema is made of, and the checks between keys (scene_relations.cpp).
// Private to dynhet_common.
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <type_traits>
#include <vector>

#include <toml++/toml.h>

#include "dynhet/scene.hpp"

namespace dynhet::scene_detail {

// A number as the shortest text that reads back as the same double.
std::string num(double v);
// The same as a TOML float: with a point or an exponent (100.0, not 100).
std::string toml_float(double v);
// A node's value as the file wrote it (tables as {...}).
std::string show(const toml::node& n);
const char* type_name(const toml::node& n);
// TOML text parsed, or SceneError naming origin:line:column and the problem.
toml::table parse_toml(const std::string& text, const std::string& origin);

// Collects every problem of a scene, then throws them together.
class Checker {
public:
  explicit Checker(std::string origin) : origin_(std::move(origin)) {}

  void fail(const std::string& key, const std::string& what);
  void bad_value(const std::string& key, const toml::node& n, const std::string& allowed);
  void bad_type(const std::string& key, const toml::node& n, const std::string& expected);
  bool ok() const { return errors_.empty(); }
  void throw_if_failed() const;

  bool get_int(const std::string& key, const toml::node& n, int64_t& out);
  // An integer beyond 2^53 has no exact double: refused, not rounded.
  bool get_double(const std::string& key, const toml::node& n, double& out);
  bool get_bool(const std::string& key, const toml::node& n, bool& out);

private:
  std::string origin_;
  std::vector<std::string> errors_;
};

using Handler = std::function<void(const std::string& key, const toml::node&)>;
using Table = std::map<std::string, Handler>;

std::string known_keys(const Table& t);

// Handlers that store a checked value in `out` (which must outlive them).
Handler positive(Checker& c, double& out);        // a number > 0
Handler non_negative(Checker& c, double& out);    // a number >= 0
Handler number_or(Checker& c, double& out, const std::string& word); // a number > 0, or `word` (stored as -1)
Handler subbox_sizes(Checker& c, std::vector<int>& out);            // a non-empty list of sizes >= 1
Handler int_list(Checker& c, std::vector<int64_t>& out, size_t size); // exactly `size` integers
Handler subset_fraction(Checker& c, double& out); // 0 < fraction <= 0.5
Handler positive_list(Checker& c, std::vector<double>& out);        // numbers > 0, may be empty

// An integer in [lo, hi].
template <class T> Handler int_in(Checker& c, T& out, int64_t lo, int64_t hi) {
  return [&c, &out, lo, hi](const std::string& key, const toml::node& n) {
    int64_t v;
    if (!c.get_int(key, n, v)) return;
    if (v < lo || v > hi)
      return c.bad_value(key, n, "allowed: " + std::to_string(lo) + " <= value <= " + std::to_string(hi));
    out = static_cast<std::remove_reference_t<T>>(v);
  };
}

// The checks between keys, after every key has been read alone.
void check_relations(Scene& s, Checker& c);

} // namespace dynhet::scene_detail
