// The bus options every process takes (docs/bus.md): --key-file,
// --unauthenticated and --bus-epoch, read into BusOptions, and the Bus
// they make (dynhet/bus.hpp). Header only: the processes link CLI11 and LCM.
#pragma once

#include <CLI/CLI.hpp>

#include <cstdio>
#include <optional>
#include <string>

#include "dynhet/bus.hpp"

namespace dynhet {

struct BusOptions {
  std::string key_file, epoch;
  bool unauthenticated = false;
};

inline void add_bus_options(CLI::App& app, BusOptions& o) {
  app.add_option("--key-file", o.key_file,
                 "the run's key (32 bytes, mode 0600; run_scene.sh writes DIR/bus.key): every message published is "
                 "tagged with it, every message received is checked before it is decoded (docs/bus.md); default "
                 "$DYNHET_KEY_FILE");
  app.add_flag("--unauthenticated", o.unauthenticated, "no key: an open bus, on purpose (tests, tools)");
  app.add_option("--bus-epoch", o.epoch,
                 "this launch's number (run_scene.sh draws one per start and resume): only its messages are taken; "
                 "\"any\" takes every launch's (a replay)");
}

// The bus these options make, or none after saying why on stderr (a key
// file refused, neither a key nor --unauthenticated: Bus::from_options).
inline std::optional<Bus> bus_or_say(const std::string& program, const BusOptions& o) {
  try {
    return Bus::from_options(program, o.key_file, o.unauthenticated, o.epoch);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return std::nullopt;
  }
}

} // namespace dynhet
