// The recorder's writer of one result group, observables/<name>[_cr][/a<cutoff>]/:
// what a ResultDecl<T> (dynhet/result_decl.hpp, generated from the type's
// declaration) writes through. Attributes, fixed axes written once, and
// one record of each series at the frame the message is based on.
#pragma once

#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "dynhet/h5md.hpp"

namespace dynhet {

class ResultGroup {
public:
  using Stamp = H5mdWriter::Stamp;
  using Shape = H5mdWriter::Shape;

  // `base`: the group's path under observables/ with a trailing '/'
  // ("chi4/a0.6/"); `written`: the fixed axes already written, by path.
  ResultGroup(H5mdWriter &w, std::set<std::string> &written, std::string base)
      : w_(w), written_(written), base_(std::move(base)) {}

  void at(const Stamp &stamp) { at_ = stamp; }

  template <class T> void attr(const char *name, const T &v) {
    w_.set_attribute("observables/" + base_.substr(0, base_.size() - 1), name, v);
  }
  template <class T> void fixed(const char *name, const std::vector<T> &v) {
    if (written_.insert(base_ + name).second) w_.write_fixed(base_ + name, v);
  }
  template <class T> void scalar(const char *name, const T &v) { w_.append_scalar(base_ + name, at_, v); }
  void array(const char *name, const double *v, const Shape &shape) { w_.append_observable(base_ + name, at_, v, shape); }
  void array(const char *name, const int32_t *v, const Shape &shape) { w_.append_observable(base_ + name, at_, v, shape); }
  void array(const char *name, const int64_t *v, const Shape &shape) { w_.append_observable(base_ + name, at_, v, shape); }
  // Flags travel as int8_t and are stored as int32.
  void array(const char *name, const int8_t *v, const Shape &shape) {
    size_t n = 1;
    for (size_t d : shape) n *= d;
    const std::vector<int32_t> wide(v, v + n);
    w_.append_observable(base_ + name, at_, wide.data(), shape);
  }

private:
  H5mdWriter &w_;
  std::set<std::string> &written_;
  std::string base_;
  Stamp at_{};
};

} // namespace dynhet
