// Writes one run's messages into its H5MD file. The first run info fixes
// the run (its run_id); messages of other runs are ignored. No bus here:
// main() hands the messages over, which keeps this testable in-process.
//
// What goes where (paths under observables/ unless absolute):
//   /parameters/scene_toml, /parameters/<table>   the scene (H5mdWriter)
//   /parameters/run_info                          attrs: run id, N, L, phi, ...
//   /particles/all/{box, species, position, image} (frames only if kept)
//   schedule/{frame_time, origin_frame, lag_time, pair_frame, cutoff_a}
//   sim/<field>            {step = collisions + kicks, time = sim time}
//   nodes/<node>/<field>   {step = frames handled, time = wall s since the first node status}
//   overlap/a<cutoff>/<field> {step = frame index, time = sim time}, lag_time
//   chi4/a<cutoff>/..., s4/a<cutoff>/..., msd/... likewise (s4: see write_s4)
//   clusters/a<cutoff>/<field> likewise, with lag_time, r and the size bins
//   msd/<field>, displacement/<field> likewise (one each per run), with
//   lag_time (msd) and x, the bin centres (displacement)
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "completion.hpp"
#include "dynhet/chunking.hpp"
#include "dynhet/frame_chunk_t.hpp"
#include "dynhet/h5md.hpp"
#include "dynhet/node_status_t.hpp"
#include "dynhet/chi4_t.hpp"
#include "dynhet/clusters_t.hpp"
#include "dynhet/displacement_t.hpp"
#include "dynhet/msd_t.hpp"
#include "dynhet/s4_t.hpp"
#include "dynhet/overlap_t.hpp"
#include "dynhet/run_info_t.hpp"
#include "dynhet/sim_status_t.hpp"

namespace dynhet {

// Thins a status stream to about one record a second by the publisher's
// clock, always keeping a change of phase or state, and holds the latest
// unwritten message back so that the stream's last word can be written.
template <class Msg> struct Thinned {
  std::optional<int64_t> last_utime;
  std::string last_state;
  std::optional<Msg> held;

  // True: write `m` now. False: it is held.
  bool take(const Msg &m, const std::string &state) {
    if (!last_utime || state != last_state || m.utime - *last_utime >= 1000000) {
      last_utime = m.utime;
      last_state = state;
      held.reset();
      return true;
    }
    held = m;
    return false;
  }
};

class RunRecorder {
public:
  RunRecorder(std::string out_path, std::string creator_version);

  // Each returns true when the message belongs to the run and was taken;
  // a node status only when the node made progress, so that the caller
  // can tell a working pipeline from a stalled one. on_run creates the
  // file on the first run info and throws if it cannot.
  bool on_run(const run_info_t &m);
  bool on_sim_status(const sim_status_t &m);
  bool on_node_status(const node_status_t &m);
  bool on_overlap(const overlap_t &m);
  bool on_chi4(const chi4_t &m);
  bool on_msd(const msd_t &m);
  bool on_s4(const s4_t &m);
  bool on_clusters(const clusters_t &m);
  bool on_displacement(const displacement_t &m);
  bool on_frame_chunk(const frame_chunk_t &m);
  // A message dropped as malformed or inconsistent (by the caller or here):
  // counted, the last reason kept, both written to the file's summary.
  void message_rejected(const std::string &channel, const std::string &why) {
    ++rejected_;
    last_rejection_ = channel + ": " + why;
  }
  int64_t messages_rejected() const { return rejected_; }

  bool has_run() const { return info_ != nullptr; }
  int64_t run_id() const { return info_ ? info_->run_id : 0; }
  bool keep_frames() const { return info_ && info_->keep_frames; }
  int n_frames() const { return info_ ? info_->n_frames : 0; }
  const Completion &completion() const { return completion_; }
  // The kept frames so far (keep_frames): reassembled and written, given up.
  int frames_whole() const { return assembler_.frames_whole(); }
  int frames_lost() const { return assembler_.frames_lost(); }
  int64_t chunks_received() const { return assembler_.chunks_received(); }

  // Writes the held statuses and the summary attributes (complete,
  // missing, frames lost per node), closes the file, and returns what is
  // missing, with `reason` (e.g. "interrupted") first when given.
  std::vector<std::string> finish(const std::string &reason = "");

private:
  struct Node {
    Thinned<node_status_t> thin;
    node_status_t latest;
  };

  std::string out_path_, creator_version_;
  std::unique_ptr<run_info_t> info_;
  std::unique_ptr<H5mdWriter> writer_;
  Completion completion_;
  FrameAssembler assembler_{1};
  Thinned<sim_status_t> sim_;
  std::map<std::string, Node> nodes_;
  std::map<std::string, bool> overlap_started_; // by cutoff label
  std::map<std::string, bool> chi4_started_;    // by cutoff label
  std::map<std::string, bool> s4_started_;      // by cutoff label
  std::map<std::string, bool> clusters_started_, clusters_r_written_, clusters_bins_written_;
  std::map<std::string, bool> overlap_t0_written_;
  bool msd_started_ = false, displacement_started_ = false;
  std::optional<int64_t> node_clock_zero_;      // utime of the first node status
  int write_errors_ = 0;
  int64_t rejected_ = 0;
  // Free space the recorder keeps on the file system of its file, so that
  // it can still mark the file incomplete and close it when the disk fills.
  static constexpr int64_t kDiskReserve = int64_t{4} << 20;
  bool stopped_ = false; // writing stopped for good (disk full)
  std::string stop_reason_;
  void stop_writing(const std::string &why);
  int frames_published_ = 0; // from the sim's last "done" or "failed"
  std::string last_rejection_;

  void write_run_info(const run_info_t &m);
  void write_sim(const sim_status_t &m);
  void write_node(const node_status_t &m);
  void write_overlap(const overlap_t &m);
  void write_chi4(const chi4_t &m);
  void write_msd(const msd_t &m);
  void write_s4(const s4_t &m);
  void write_clusters(const clusters_t &m);
  void write_displacement(const displacement_t &m);
  void write_summary(const std::vector<std::string> &missing);
  void count_frames();
  template <class F> void guarded(const char *what, F &&write);
};

} // namespace dynhet
