// Which LCM bus to use: --lcm-url, else $LCM_DEFAULT_URL, else the
// project's default. ttl=0 keeps every packet on this host.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <string>

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

// Channel names.
inline constexpr const char* kChanRun = "DYNHET_RUN";
inline constexpr const char* kChanFrame = "DYNHET_FRAME";
inline constexpr const char* kChanSimStatus = "DYNHET_SIM_STATUS";
inline constexpr const char* kChanNodeStatus = "DYNHET_NODE_STATUS";
inline constexpr const char* kChanOverlap = "DYNHET_OVERLAP";
inline constexpr const char* kChanChi4 = "DYNHET_CHI4";
inline constexpr const char* kChanMsd = "DYNHET_MSD";
inline constexpr const char* kChanS4 = "DYNHET_S4";
inline constexpr const char* kChanClusters = "DYNHET_CLUSTERS";
inline constexpr const char* kChanDisplacement = "DYNHET_DISPLACEMENT";

} // namespace dynhet
