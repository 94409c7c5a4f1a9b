// The bus options every process takes (docs/bus.md): --key-file,
// --unauthenticated and --bus-epoch, read into BusOptions, and the Bus
// they make (dynhet/bus.hpp). Header only: the processes link CLI11 and LCM.
#pragma once

#include <CLI/CLI.hpp>

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

// Throws std::runtime_error with a message for the user (Bus::from_options).
inline Bus bus_from(const std::string& program, const BusOptions& o) {
  return Bus::from_options(program, o.key_file, o.unauthenticated, o.epoch);
}

} // namespace dynhet
