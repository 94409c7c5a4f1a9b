// What the RunRecorder's source files share (recorder/run_recorder*.cpp):
// array dimensions and the cage-relative note.
#pragma once

#include <cstdint>
#include <string>

#include "dynhet/h5md.hpp"

namespace dynhet::recorder_util {

inline constexpr const char *kCageRelative =
    "cage-relative: dr_i less the mean dr of i's Voronoi neighbours in the origin frame";

using Shape = H5mdWriter::Shape;
inline size_t dim(int32_t n) { return static_cast<size_t>(n); }

} // namespace dynhet::recorder_util
