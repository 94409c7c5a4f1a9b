// The checkpoint cuts of a run, on disk (docs/checkpoints.md). A cut is a
// consistent snapshot of every process of the pipeline at one frame
// boundary: the sim's state after frame k, each node's accumulators with
// frame k folded in, the recorder's results up to the point where every
// node had saved. Layout of a run's checkpoint folder:
//
//   DIR/cut-000012/sim.part    the sim's part (two cuts between the same
//                              frames hold two engine states)
//   DIR/frames/overlap-18.part, s4-18.part, ..., recorder-18.part
//                              every other process's part at the boundary
//                              after frame 17 (18 frames in): its state
//                              there is one, whichever cut asked for it, so
//                              requests for one boundary (forged or not)
//                              cost one part
//   DIR/cut-000012/WHOLE       written (atomically) last, by the sim, once
//                              it has read back every part of the cut
//   DIR/recorder.journal       the recorder's messages; its part holds a
//                              prefix length and CRC
//
// A cut without WHOLE is not a cut. Resuming takes the newest cut whose
// WHOLE exists and whose every part reads back (CRC, build, run, scene);
// a part that does not is named and the cut before is tried.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace dynhet {

std::string cut_dir(const std::string& root, int cut);
// The part of `process` in cut `cut`, taken after frame `frame` (-1: before any).
std::string part_path(const std::string& root, int cut, const std::string& process, int frame);
// The cuts in the folder (numbers of cut-* folders), ascending.
std::vector<int> list_cuts(const std::string& root);

struct CutInfo {
  int cut = -1;
  int frame = -1;       // last frame in the cut
  double sim_time = 0;  // the sim's time at the cut
  int64_t run_id = 0;
  std::vector<std::string> parts; // processes
};
// Marks a cut whole if every part listed reads back (read_part: whole, CRC,
// build, run, scene, this cut and frame). Returns the parts that do not,
// each with why (the cut is then not marked); empty: marked whole.
std::vector<std::string> mark_cut_whole(const std::string& root, const CutInfo& c, uint64_t scene);
// The WHOLE marker of a cut, if it has one that parses.
std::optional<CutInfo> read_cut_marker(const std::string& root, int cut);

// The newest usable cut: whole and every part good. `refused` gets one line
// per cut passed over and why (a part named by its file).
std::optional<CutInfo> latest_whole_cut(const std::string& root, uint64_t scene, std::vector<std::string>& refused);

// Removes the cuts older than `keep_from` (the older of the two newest whole
// cuts stays as the fallback), and the frame parts before its frame.
void prune_cuts(const std::string& root, int keep_from, int keep_frame);

} // namespace dynhet
