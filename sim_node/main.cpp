// sim_node: runs a scene's EDMD simulation and publishes, over LCM, the run
// info, a status at least once a second, and the frames the scene's
// observables need (in chunks).
// Usage: sim_node SCENE.toml [--lcm-url URL] [--checkpoint FILE.h5]
//        sim_node --resume FILE.h5 [--checkpoint FILE.h5]
// With --checkpoint, a checkpoint is written at every multiple of the
// scene's run.checkpoint_interval and at the end. SIGINT/SIGTERM: with
// checkpoint cuts (--checkpoint-dir), a cut of the whole engine as it is
// (at most one slice of events later) and exit; without them, run on to
// the next synchronised time, write the checkpoint and exit (status 128 +
// signal).
//
// main() reads the command line and the scene, answers what needs no run
// (--scene-reference, --find-cut, --check, --resolved, --prepare-only),
// opens the bus and hands the run to run_on_bus (sim_run.cpp).
#include <atomic>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <unistd.h>

#include <lcm/lcm-cpp.hpp>

#include "checkpoint.hpp"
#include "dynhet/bus.hpp"
#include "dynhet/bus_cli.hpp"
#include "dynhet/cut.hpp"
#include "dynhet/lcm_exit.hpp"
#include "dynhet/lcm_url.hpp"
#include "dynhet/scene.hpp"
#include "dynhet/state_archive.hpp"
#include "initial_state.hpp"
#include "options.hpp"
#include "scene_report.hpp"
#include "sim_run.hpp"

namespace {

std::atomic<int> g_signal{0};
void on_signal(int s) { g_signal = s; }
void stop_on_signals() {
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
}

// The scene: from its file (- reads standard input), or from the checkpoint
// --resume names (which then names the run). Returns -1, or the exit code.
int read_scene(dynhet::SimOptions& o, dynhet::RunStart& start) {
  if (o.scene_path.empty() == o.resume_path.empty()) {
    std::fprintf(stderr, "sim_node: give either a scene file or --resume CHECKPOINT\n");
    return 2;
  }
  try {
    if (!o.resume_path.empty()) {
      start.resumed = dynhet::read_checkpoint(o.resume_path);
      start.scene = dynhet::parse_scene_text(start.resumed.scene_toml, o.resume_path + " (its scene)");
      o.run_id = start.resumed.run_id;
      o.scene_path = o.resume_path;
      if (start.resumed.kick_pairs != start.scene.kick_pairs)
        throw std::runtime_error(o.resume_path + ": the run drew kick pairs by the rule \"" +
                                 start.resumed.kick_pairs + "\", its scene now means \"" + start.scene.kick_pairs +
                                 "\" (a checkpoint from before driving.pairs): it cannot be resumed bit for bit; "
                                 "start the run again");
    } else if (o.scene_path == "-") {
      std::stringstream text;
      text << std::cin.rdbuf();
      start.scene = dynhet::parse_scene_text(text.str(), "<stdin>");
    } else {
      start.scene = dynhet::parse_scene_file(o.scene_path);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sim_node: %s\n", e.what());
    return 2;
  }
  return -1;
}

// --find-cut: the newest whole cut of --checkpoint-dir for this scene.
int print_latest_cut(const dynhet::SimOptions& o, const dynhet::Scene& scene) {
  if (o.cut_root.empty()) {
    std::fprintf(stderr, "sim_node: --find-cut needs --checkpoint-dir\n");
    return 2;
  }
  std::vector<std::string> refused;
  const auto c = dynhet::latest_whole_cut(o.cut_root, dynhet::scene_hash(scene.text), refused);
  for (const std::string& r : refused) std::fprintf(stderr, "sim_node: %s\n", r.c_str());
  if (!c) return 1;
  std::printf("cut %d frame %d time %.17g run_id %lld\n", c->cut, c->frame, c->sim_time,
              static_cast<long long>(c->run_id));
  return 0;
}

// --resume-cut: the sim's part of that cut, which names the run. Returns
// -1, or the exit code.
int read_cut_part(dynhet::SimOptions& o, dynhet::RunStart& start) {
  if (o.resume_cut < 0) return -1;
  try {
    if (o.cut_root.empty()) throw std::runtime_error("--resume-cut needs --checkpoint-dir");
    dynhet::PartHeader h;
    start.cut_part = dynhet::read_part(dynhet::part_path(o.cut_root, o.resume_cut, "sim", 0), "sim", 0,
                                       dynhet::scene_hash(start.scene.text), &h);
    if (o.run_id != 0 && o.run_id != h.run_id)
      throw std::runtime_error("cut " + std::to_string(o.resume_cut) + " is of run " + std::to_string(h.run_id) +
                               ", not --run-id " + std::to_string(o.run_id));
    o.run_id = h.run_id;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sim_node: cannot resume: %s\n", e.what());
    return 2;
  }
  return -1;
}

// A scene's initial_state is relative to the scene file.
void place_initial_state(const dynhet::SimOptions& o, dynhet::Scene& scene) {
  if (scene.initial_state.empty() || scene.initial_state[0] == '/' || !o.resume_path.empty()) return;
  const auto slash = o.scene_path.find_last_of('/');
  if (slash != std::string::npos) scene.initial_state = o.scene_path.substr(0, slash + 1) + scene.initial_state;
}

// --prepare-only FILE (--equilibrate): the state alone, no bus.
int prepare(const dynhet::SimOptions& o, const dynhet::Scene& scene) {
  stop_on_signals();
  return dynhet::prepare_only(scene, o.prepare_path, o.equilibrate, g_signal);
}

// Opens the bus and runs the scene on it.
int run(const dynhet::SimOptions& o, dynhet::RunStart& start) {
  const int64_t run_id =
      o.run_id != 0 ? o.run_id : static_cast<int64_t>(std::random_device{}() & 0x7fffffff) << 20 ^ getpid();
  const std::optional<dynhet::Bus> bus = dynhet::bus_or_say("sim_node", o.bus);
  if (!bus) return 2;
  const std::string bus_url = dynhet::resolve_lcm_url(o.url);
  lcm::LCM lcm(bus_url);
  if (dynhet::bus_unreachable(lcm, bus_url)) {
    std::fprintf(stderr, "sim_node: cannot open LCM at %s\n", bus_url.c_str());
    return 3;
  }
  stop_on_signals();
  return dynhet::run_on_bus(o, start, run_id, lcm, *bus, bus_url, g_signal);
}

} // namespace

int main(int argc, char** argv) {
  dynhet::SimOptions o;
  if (const int rc = dynhet::parse_sim_options(argc, argv, o); rc >= 0) return rc;
  if (o.scene_reference) {
    std::fputs(dynhet::scene_reference_markdown().c_str(), stdout);
    return 0;
  }
  dynhet::RunStart start;
  if (const int rc = read_scene(o, start); rc >= 0) return rc;
  if (o.find_cut) return print_latest_cut(o, start.scene);
  if (const int rc = read_cut_part(o, start); rc >= 0) return rc;
  if (o.check) return dynhet::report_check(start.scene, o.scene_path);
  if (o.resolved) return dynhet::report_resolved(start.scene);
  for (const auto& note : start.scene.notes) std::fprintf(stderr, "sim_node: note: %s\n", note.c_str());
  place_initial_state(o, start.scene);
  if (o.equilibrate && o.prepare_path.empty()) {
    std::fprintf(stderr, "sim_node: --equilibrate goes with --prepare-only FILE\n");
    return 2;
  }
  if (!o.prepare_path.empty()) return prepare(o, start.scene);
  return run(o, start);
}
