// Checkpoints of a run (HDF5): the engine state at a synchronised time plus
// what sim_node needs to go on (scene, run id, next frame). Written to a
// temporary file and renamed, so a checkpoint on disk is always whole.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "dynhet/engine/engine.hpp"

namespace dynhet {

struct Checkpoint {
  std::string scene_toml;
  int64_t run_id = 0;
  int32_t next_frame = 0; // first frame not yet published
  // The kick-pair rule the run used ("any" in checkpoints from before the
  // rule was a choice); a resume under another rule is refused.
  std::string kick_pairs = "any";
  engine::State state;
};

void write_checkpoint(const std::string& path, const Checkpoint& c);

// Whether the file is a dynhet checkpoint (a prepared state is one, at time
// 0, written by sim_node --prepare-only).
bool is_checkpoint(const std::string& path);

// Positions of n particles from an H5MD file: the last frame of
// particles/all/position/value ([frame][n][2], [frame][2n] or [n][2]),
// folded into the box of side `box`; particles/all/box/edges, if there,
// must be that box. Throws std::runtime_error naming the file and what is
// wrong.
void read_h5md_positions(const std::string& path, long n, double box, std::vector<double>& x,
                         std::vector<double>& y);
// Throws std::runtime_error naming the file and what is wrong with it.
Checkpoint read_checkpoint(const std::string& path);

} // namespace dynhet
