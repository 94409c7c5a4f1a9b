#include "parameters.hpp"

#include <sstream>
#include <stdexcept>
#include <vector>

#include <toml++/toml.h>

#include "h5_util.hpp"

namespace dynhet::h5 {

namespace {

// TOML's own text for what HDF5 has no natural type for (dates, tables in
// arrays, mixed arrays).
std::string as_toml_text(const toml::node &node) {
  std::ostringstream os;
  node.visit([&os](const auto &n) { os << n; });
  return os.str();
}

// Arrays of one kind become 1-D attributes: integers int64, numbers
// double, booleans bool, strings strings. Anything else is kept as text.
void write_array(hid_t obj, const std::string &name, const toml::array &a) {
  if (a.empty()) return write_empty_attr(obj, name);
  if (a.is_homogeneous(toml::node_type::integer)) {
    std::vector<int64_t> v;
    for (const auto &x : a) v.push_back(x.as_integer()->get());
    return write_attr(obj, name, v);
  }
  bool numbers = true;
  for (const auto &x : a) numbers = numbers && (x.is_integer() || x.is_floating_point());
  if (numbers) {
    std::vector<double> v;
    for (const auto &x : a) v.push_back(x.value<double>().value());
    return write_attr(obj, name, v);
  }
  if (a.is_homogeneous(toml::node_type::boolean)) {
    std::vector<bool> v;
    for (const auto &x : a) v.push_back(x.as_boolean()->get());
    return write_bool_attr(obj, name, v, false);
  }
  if (a.is_homogeneous(toml::node_type::string)) {
    std::vector<std::string> v;
    for (const auto &x : a) v.push_back(x.as_string()->get());
    return write_attr(obj, name, v);
  }
  write_attr(obj, name, as_toml_text(a));
}

void write_table(hid_t group, const toml::table &table) {
  for (const auto &[key, node] : table) {
    const std::string name(key.str());
    if (const auto *t = node.as_table()) {
      Id sub = require_group(group, name);
      write_table(sub, *t);
    } else if (const auto *a = node.as_array()) {
      write_array(group, name, *a);
    } else if (const auto *i = node.as_integer()) {
      write_attr(group, name, static_cast<int64_t>(i->get()));
    } else if (const auto *f = node.as_floating_point()) {
      write_attr(group, name, f->get());
    } else if (const auto *b = node.as_boolean()) {
      write_bool_attr(group, name, {b->get()}, true);
    } else if (const auto *s = node.as_string()) {
      write_attr(group, name, s->get());
    } else {
      write_attr(group, name, as_toml_text(node));
    }
  }
}

} // namespace

void write_toml_attributes(hid_t group, const std::string &toml_text) {
  toml::table table;
  try {
    table = toml::parse(toml_text);
  } catch (const toml::parse_error &e) {
    std::ostringstream os;
    os << "parameters: the scene is not valid TOML: " << e.description() << " at " << e.source().begin;
    throw std::runtime_error(os.str());
  }
  write_table(group, table);
}

} // namespace dynhet::h5
