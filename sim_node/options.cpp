// sim_node's command line.
#include "options.hpp"

#include <CLI/CLI.hpp>

#include "dynhet/lcm_url.hpp"

namespace dynhet {

int parse_sim_options(int argc, char** argv, SimOptions& o) {
  CLI::App app{"dynhet sim_node: event-driven MD of a driven granular fluid, frames over LCM"};
  app.add_option("scene", o.scene_path, "scene file (TOML); - reads it from standard input");
  app.add_option("--checkpoint", o.checkpoint_path, "write checkpoints (HDF5) to this file");
  app.add_option("--resume", o.resume_path, "continue the run saved in this checkpoint");
  app.add_option("--checkpoint-before-frames", o.before_frames_path,
                 "also keep the last checkpoint taken before the first frame in this file (with --checkpoint): a "
                 "run interrupted in production restarts from it with every frame still to come, so fresh "
                 "analysis nodes see them all");
  app.add_option("--prepare-only", o.prepare_path,
                 "compress the scene's system, draw its velocities, write this prepared state (HDF5) and exit: "
                 "runs of any restitution or driving that start from it (system.initial_state) equal the runs "
                 "that compress themselves, bit for bit");
  app.add_flag("--equilibrate", o.equilibrate,
               "with --prepare-only: also run the scene's dynamics to the last checkpoint slot within "
               "run.equilibration_time (from the scene's initial_state if it has one) and write that state: "
               "runs of the same dynamics from it equal the runs that equilibrate themselves, bit for bit");
  app.add_option("--lcm-url", o.url, "LCM URL (default $LCM_DEFAULT_URL or " + std::string(kDefaultLcmUrl) + ")");
  app.add_option("--run-id", o.run_id, "run id (default: random)");
  add_bus_options(app, o.bus);
  app.add_flag("--pace-nodes", o.pace,
               "flow control: hold each frame until the scene's nodes, and the recorder when the scene keeps the "
               "frames (their status on DYNHET_NODE_STATUS_<node>), have caught up to within a socket "
               "buffer's worth of frames (run_scene.sh sets it)");
  app.add_flag("--check", o.check, "validate the scene, print what it needs (nodes, frames) and exit");
  app.add_flag("--resolved", o.resolved,
               "validate the scene and print it with every key, the defaults filled in (TOML), then [model]: the "
               "radii, masses, box, G_c, collision frequency, kick rate and amplitude, frames and simulated time "
               "the simulator derives from it; exit");
  app.add_flag("--scene-reference", o.scene_reference,
               "print every scene key with its default, the values allowed and its meaning (Markdown) and exit");
  app.add_option("--test-frame-delay", o.test_frame_delay,
                 "tests only: sleep this many seconds before each frame, a stand-in for a slow engine (large N)");
  app.add_option("--checkpoint-dir", o.cut_root,
                 "take checkpoint cuts of the whole pipeline in this folder (docs/checkpoints.md): at every "
                 "run.checkpoint_interval (or run.checkpoint_wall_interval), and on SIGTERM/SIGINT before exiting");
  app.add_option("--resume-cut", o.resume_cut, "resume the run from this whole cut of --checkpoint-dir (the scene's)");
  app.add_flag("--find-cut", o.find_cut,
               "print the newest whole cut of --checkpoint-dir that every part of reads back for this scene "
               "(\"cut N frame K time T run_id R\"), each cut refused and why on stderr, and exit (1: none)");
  app.add_option("--cut-wait", o.cut_wait,
                 "on SIGTERM/SIGINT, wait at most this many seconds for every process to save its part of the last cut")
      ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  return -1;
}

} // namespace dynhet
