// sim_node's command line (options.cpp): what a run is asked to do.
#pragma once

#include <cstdint>
#include <string>

#include "dynhet/bus_cli.hpp"

namespace dynhet {

struct SimOptions {
  std::string scene_path, url;
  int64_t run_id = 0;
  std::string checkpoint_path, resume_path, before_frames_path, prepare_path;
  bool equilibrate = false; // with prepare_path
  BusOptions bus;
  bool pace = false;        // --pace-nodes
  bool check = false;       // validate the scene and exit
  bool resolved = false;    // print the scene with every default filled in and exit
  bool scene_reference = false; // print the reference of every scene key and exit
  std::string cut_root;     // --checkpoint-dir
  int resume_cut = -1;
  bool find_cut = false;
  double cut_wait = 300, test_frame_delay = 0;
};

// Parses the command line into o. Returns -1 to run, else the exit code
// (0 after --help; 2 with the problem on stderr).
int parse_sim_options(int argc, char** argv, SimOptions& o);

} // namespace dynhet
