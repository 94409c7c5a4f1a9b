// Which LCM bus to use: --lcm-url, else $LCM_DEFAULT_URL, else the
// project's default. ttl=0 keeps every packet on this host.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "dynhet/observables.hpp" // kChan<Observable>

namespace dynhet {

inline constexpr const char* kDefaultLcmUrl = "udpm://239.255.76.67:7667?ttl=0";

inline std::string resolve_lcm_url(const std::string& flag) {
  if (!flag.empty()) return flag;
  if (const char* env = std::getenv("LCM_DEFAULT_URL"); env && *env) return env;
  return kDefaultLcmUrl;
}

// LCM's utime: microseconds since the epoch.
inline int64_t utime_now() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Channel names. One channel carries one source, so that lcm-spy (which
// charts a channel as one series) and channel filters see each source on
// its own:
//   DYNHET_RUN, DYNHET_FRAME, DYNHET_SIM_STATUS       the sim
//   DYNHET_NODE_STATUS_<node>                         each node's status (overlap,
//                                                     clusters, s4; recorder)
//   DYNHET_<OBSERVABLE>_<a>                           a per-cutoff observable's results
//                                                     (overlap, chi4, ...): <a> is
//                                                     cutoff_label (a0.6), as in run.h5
//   DYNHET_<OBSERVABLE>                               the others' (msd, ...): one for all cutoffs
//   DYNHET_<OBSERVABLE>_CR[_<a>]                       the same of the cage-relative
//                                                     displacements ([observables]
//                                                     cage_relative; groups <name>_cr)
// Which observable is which is its declaration's (lcmtypes/*.lcm,
// dynhet/observables.hpp).
// The names are also LCM subscription patterns (regular expressions): a
// channel with a cutoff holds a '.', so subscribe to the family
// (channel_family) and compare names, never subscribe to a name.
inline constexpr const char* kChanRun = "DYNHET_RUN";
inline constexpr const char* kChanFrame = "DYNHET_FRAME";
inline constexpr const char* kChanSimStatus = "DYNHET_SIM_STATUS";
inline constexpr const char* kChanNodeStatus = "DYNHET_NODE_STATUS"; // + "_<node>"
// The results' families, kChanOverlap = "DYNHET_OVERLAP" and the rest, one
// per observable, are generated from the observables' declarations
// (dynhet/observables.hpp; "+ _<a>" for a per-cutoff one).
// Checkpoint cuts (dynhet/cut.hpp): the sim's requests, and each process's
// answer on DYNHET_CHECKPOINT_<process>.
inline constexpr const char* kChanCheckpoint = "DYNHET_CHECKPOINT";
inline std::string checkpoint_answer_channel(const std::string& process) {
  return std::string(kChanCheckpoint) + "_" + process;
}

// "a0.6": how a cutoff names its results in channels and in run.h5 (six
// significant digits; a scene's cutoffs must differ in their labels).
inline std::string cutoff_label(double cutoff_a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "a%g", cutoff_a);
  return buf;
}
// The channel of results of all cutoffs: DYNHET_MSD, or DYNHET_MSD_CR for
// the cage-relative displacements.
inline std::string result_channel(const char* family, bool cage_relative = false) {
  return std::string(family) + (cage_relative ? "_CR" : "");
}
// The channel of one cutoff's results: DYNHET_OVERLAP_a0.6 (cage-relative:
// DYNHET_OVERLAP_CR_a0.6).
inline std::string cutoff_channel(const char* family, double cutoff_a, bool cage_relative = false) {
  return result_channel(family, cage_relative) + "_" + cutoff_label(cutoff_a);
}
// The run.h5 group of an observable's results: "overlap", or "overlap_cr".
inline std::string result_group(const std::string& observable, bool cage_relative) {
  return observable + (cage_relative ? "_cr" : "");
}
// The channel of one node's status: DYNHET_NODE_STATUS_overlap.
inline std::string node_status_channel(const std::string& node) {
  return std::string(kChanNodeStatus) + "_" + node;
}
// An LCM subscription pattern for every channel of a family, and for
// names outside the scheme that start like it (the bare family name of
// older builds, say), so that those are dropped and counted, not unheard.
inline std::string channel_family(const char* family) { return std::string(family) + ".*"; }

} // namespace dynhet
