// The scene parser's checker and typed key handlers (scene_check.hpp).
#include "scene_check.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>

namespace dynhet::scene_detail {

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

// The shortest text that reads back as the same double (0.9,
// 1.0000000000000002, 1e+300): what the file says, never rounded away.
toml::table parse_toml(const std::string& text, const std::string& origin) {
  try {
    return toml::parse(text, origin);
  } catch (const toml::parse_error& e) {
    std::ostringstream m;
    m << origin << ":" << e.source().begin.line << ":" << e.source().begin.column
      << ": not valid TOML: " << e.description();
    throw SceneError(m.str());
  }
}

std::string num(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::string toml_float(double v) {
  std::string t = num(v);
  if (t.find_first_of(".en") == std::string::npos) t += ".0";
  return t;
}

std::string show(const toml::node& n) {
  std::ostringstream s;
  if (n.is_table()) return "{...}";
  if (auto d = n.value_exact<double>()) return num(*d);
  n.visit([&](auto&& v) { s << v; });
  return s.str();
}

void Checker::fail(const std::string& key, const std::string& what) {
  errors_.push_back(origin_ + ": " + key + ": " + what);
}

void Checker::bad_value(const std::string& key, const toml::node& n, const std::string& allowed) {
  fail(key, "value " + show(n) + " is not allowed; " + allowed);
}

void Checker::bad_type(const std::string& key, const toml::node& n, const std::string& expected) {
  fail(key, "value " + show(n) + " is " + type_name(n) + ", expected " + expected);
}

void Checker::throw_if_failed() const {
  if (errors_.empty()) return;
  std::string msg = "invalid scene (" + std::to_string(errors_.size()) + " problem" +
                    (errors_.size() > 1 ? "s" : "") + "):";
  for (const auto& e : errors_) msg += "\n  " + e;
  throw SceneError(msg);
}

bool Checker::get_int(const std::string& key, const toml::node& n, int64_t& out) {
  if (auto v = n.value_exact<int64_t>()) { out = *v; return true; }
  bad_type(key, n, "an integer");
  return false;
}

bool Checker::get_double(const std::string& key, const toml::node& n, double& out) {
  if (n.is_integer()) {
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

bool Checker::get_bool(const std::string& key, const toml::node& n, bool& out) {
  if (auto v = n.value_exact<bool>()) { out = *v; return true; }
  bad_type(key, n, "a boolean (true or false)");
  return false;
}

std::string known_keys(const Table& t) {
  std::string s;
  for (const auto& [k, h] : t) s += (s.empty() ? "" : ", ") + k;
  return s;
}

Handler positive(Checker& c, double& out) {
  return [&c, &out](const std::string& key, const toml::node& n) {
    double v;
    if (!c.get_double(key, n, v)) return;
    if (v <= 0) return c.bad_value(key, n, "it must be > 0");
    out = v;
  };
}

Handler non_negative(Checker& c, double& out) {
  return [&c, &out](const std::string& key, const toml::node& n) {
    double v;
    if (!c.get_double(key, n, v)) return;
    if (v < 0) return c.bad_value(key, n, "it must be >= 0");
    out = v;
  };
}

Handler number_or(Checker& c, double& out, const std::string& word) {
  return [&c, &out, word](const std::string& key, const toml::node& n) {
    if (n.is_string()) {
      if (*n.value<std::string>() != word) return c.bad_value(key, n, "allowed: \"" + word + "\" or a number > 0");
      out = -1.0;
      return;
    }
    double v;
    if (!c.get_double(key, n, v)) return;
    if (v <= 0) return c.bad_value(key, n, "allowed: \"" + word + "\" or a number > 0");
    out = v;
  };
}

Handler subbox_sizes(Checker& c, std::vector<int>& out) {
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
}

Handler int_list(Checker& c, std::vector<int64_t>& out, size_t size) {
  return [&c, &out, size](const std::string& key, const toml::node& n) {
    const auto* arr = n.as_array();
    if (!arr || arr->size() != size) return c.bad_type(key, n, "an array of " + std::to_string(size) + " integers");
    std::vector<int64_t> v;
    for (const auto& e : *arr) {
      int64_t x;
      if (!c.get_int(key, e, x)) return;
      v.push_back(x);
    }
    out = v;
  };
}

Handler subset_fraction(Checker& c, double& out) {
  return [&c, &out](const std::string& key, const toml::node& n) {
    double v;
    if (!c.get_double(key, n, v)) return;
    if (!(v > 0 && v <= 0.5)) return c.bad_value(key, n, "allowed: 0 < fraction <= 0.5");
    out = v;
  };
}

Handler positive_list(Checker& c, std::vector<double>& out) {
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
}

} // namespace dynhet::scene_detail
