// What the RunRecorder's source files share (recorder/run_recorder*.cpp):
// the size check of a message's flat arrays and the cage-relative note.
#pragma once

#include <cstdint>
#include <string>

#include "dynhet/h5md.hpp"

namespace dynhet::recorder_util {

inline constexpr const char *kCageRelative =
    "cage-relative: dr_i less the mean dr of i's Voronoi neighbours in the origin frame";

// "" if `n` values are the product of the dimensions, else why not.
inline std::string size_problem(const char *what, int64_t n, int64_t a, int64_t b, int64_t c = 1) {
  if (n == a * b * c) return "";
  return std::string(what) + ": " + std::to_string(n) + " values for dimensions " + std::to_string(a) +
         " x " + std::to_string(b) + (c == 1 ? "" : " x " + std::to_string(c));
}

using Shape = H5mdWriter::Shape;
inline size_t dim(int32_t n) { return static_cast<size_t>(n); }

} // namespace dynhet::recorder_util
