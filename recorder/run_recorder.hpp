// Writes one run's messages into its H5MD file. The first run info fixes
// the run (its run_id); messages of other runs are ignored. No bus here:
// main() hands the messages over, which keeps this testable in-process.
//
// Every time series has one clock, the run's frame schedule: step f is
// frame f (0 .. n_frames - 1) and time its simulation time,
// schedule/frame_time[f]. A record at step f is based on frames up to f:
//   results (overlap, chi4, msd, displacement, clusters, s4): published
//     after frame f was folded in (the message's frame_index);
//   sim/<field>: the sim had published frames 0 .. f (frames_published - 1);
//   nodes/<node>/<field>: the node had handled frames_whole + frames_lost =
//     f + 1 frames (its last one f, when none is still pending).
// Steps strictly increase in every series: a later message of the same step
// is dropped unless it is its stream's last word (is_final, the sim's
// done/failed/interrupted, a node's done/failed), which replaces the record
// of that step; a message of an older step is dropped. Statuses before the
// first frame make no record (their last word is in the summary attributes).
//
// What goes where (paths under observables/ unless absolute):
//   /parameters/scene_toml, /parameters/<table>   the scene (H5mdWriter)
//   /parameters/run_info                          attrs: run id, N, L, phi, ...
//   /particles/all/{box, species, position, image} (frames only if kept)
//   schedule/{frame_time, origin_frame, lag_time, pair_frame [origin][lag], cutoff_a}
//   sim/<field>            the sim's status, with sim_time (its own simulation time)
//   nodes/<node>/<field>   the node's frame counts, with wall_time (s since the first node status recorded)
//   <observable>[/a<cutoff>]/<field>  each result type's group, as its
//     declaration in lcmtypes/<type>.lcm says (docs/run_h5.md): one group per
//     cutoff if per cutoff; series, fixed axes and attributes
//   <observable>_cr[/a<cutoff>]/  the same of the cage-relative
//     displacements (attribute displacements), in the same layout
#pragma once
#include <array>

#include "dynhet/bus_auth.hpp"

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "completion.hpp"
#include "dynhet/chunking.hpp"
#include "dynhet/frame_chunk_t.hpp"
#include "dynhet/h5md.hpp"
#include "dynhet/node_status_t.hpp"
#include "dynhet/lcm_url.hpp"
#include "dynhet/result_decl.hpp"
#include "dynhet/run_info_t.hpp"
#include "dynhet/sim_status_t.hpp"

namespace dynhet {

// The one channel a result may come on: its family (DYNHET_OVERLAP), _CR if
// of the cage-relative displacements, _<a> if per cutoff.
template <class T> std::string result_channel_of(const T &m) {
  using D = ResultDecl<T>;
  return D::per_cutoff ? cutoff_channel(D::channel, D::cutoff(m), D::cage_relative(m))
                       : result_channel(D::channel, D::cage_relative(m));
}

class RunRecorder {
public:
  // The file's h5md/author: an empty name means default_author()
  // ($DYNHET_AUTHOR, $USER, "unknown"); an empty email writes none.
  RunRecorder(std::string out_path, std::string creator_version, std::string author = "",
              std::string author_email = "");

  // Each returns true when the message belongs to the run and was taken;
  // a node status only when the node made progress, so that the caller
  // can tell a working pipeline from a stalled one. A result whose frame
  // index is neither one of the run's nor -1 (no frame yet: taken, not
  // written), or whose array sizes do not fit its dimensions, is rejected
  // (message_rejected). on_run creates the file on the first run info and
  // throws if it cannot.
  bool on_run(const run_info_t &m);
  // A re-analysis (dynhet/reanalysis.hpp): on_run goes by the recorded run
  // info with the analysis of this TOML text in place (throwing, before
  // the file is made, what it refuses), and the file says whose
  // re-analysis it is (H5mdWriter::write_reanalysis).
  void set_reanalysis(std::string analysis_toml, std::string analysis_file) {
    reanalysis_ = std::move(analysis_toml), reanalysis_file_ = std::move(analysis_file);
  }
  bool on_sim_status(const sim_status_t &m);
  bool on_node_status(const node_status_t &m);
  // A result of any declared type (DYNHET_RESULT_TYPES: overlap_t, ...),
  // written as its declaration says (ResultDecl<T>, run_recorder_results.cpp).
  template <class T> bool on_result(const T &m);
  bool on_frame_chunk(const frame_chunk_t &m);
  // A message dropped as malformed or inconsistent (by the caller or here):
  // counted, the last reason kept, both written to the file's summary.
  void message_rejected(const std::string &channel, const std::string &why) {
    ++rejected_;
    last_rejection_ = channel + ": " + why;
  }
  int64_t messages_rejected() const { return rejected_; }
  // A message the bus dropped (no tag, a wrong one, a replay: bus.hpp):
  // counted apart from the malformed ones, never used.
  void message_unauthenticated(const std::string &channel, const std::string &why) {
    ++unauthenticated_;
    last_unauthenticated_ = channel + ": " + why;
  }
  int64_t messages_unauthenticated() const { return unauthenticated_; }
  // The recorder's own drops by reason (BusDrop), written at finish.
  void bus_drops(const std::array<int64_t, kBusDropReasons> &d) { bus_drops_ = d; }
  // Each write is flushed (results survive a kill); a journal replayed on
  // resume is written whole first and flushed once (flush_each(true) after
  // it flushes what was written): a flush per message made a 64 MB journal
  // take most of a minute to replay.
  void flush_each(bool on);

  bool has_run() const { return info_ != nullptr; }
  const run_info_t *run_info() const { return info_.get(); }
  int64_t run_id() const { return info_ ? info_->run_id : 0; }
  bool keep_frames() const { return info_ && info_->keep_frames; }
  int n_frames() const { return info_ ? info_->n_frames : 0; }
  const Completion &completion() const { return completion_; }
  // The kept frames so far (keep_frames): reassembled and written, given up.
  int frames_whole() const { return assembler_.frames_whole(); }
  int frames_lost() const { return assembler_.frames_lost(); }
  int64_t chunks_received() const { return assembler_.chunks_received(); }

  // Writes the summary attributes (complete, missing, frames lost per
  // node), closes the file, and returns what is missing, with `reason`
  // (e.g. "interrupted") first when given.
  std::vector<std::string> finish(const std::string &reason = "");

private:
  struct Node {
    node_status_t latest;
  };
  using Stamp = H5mdWriter::Stamp;

  std::string out_path_, creator_version_, author_, author_email_;
  std::unique_ptr<run_info_t> info_;
  std::string reanalysis_, reanalysis_file_, recorded_scene_;
  std::unique_ptr<H5mdWriter> writer_;
  Completion completion_;
  FrameAssembler assembler_{1};
  std::map<std::string, Node> nodes_;
  // The groups (and fixed datasets) written once: "msd", "overlap_cr/a0.6/", ...
  std::set<std::string> started_;
  std::optional<int64_t> node_clock_zero_;      // utime of the first node status recorded
  int write_errors_ = 0;
  int64_t rejected_ = 0, unauthenticated_ = 0;
  std::string last_unauthenticated_;
  int32_t sim_unauthenticated_ = 0; // the sim's own count, from its last status
  std::array<int64_t, kBusDropReasons> bus_drops_{}, sim_bus_drops_{};
  void write_bus_drops(const std::string &group, const std::string &suffix, const int64_t *drops);
  // Free space the recorder keeps on the file system of its file, so that
  // it can still mark the file incomplete and close it when the disk fills.
  static constexpr int64_t kDiskReserve = int64_t{4} << 20;
  bool stopped_ = false; // writing stopped for good (disk full)
  bool flush_each_ = true;
  std::string stop_reason_;
  void stop_writing(const std::string &why);
  int frames_published_ = 0; // from the sim's last "done" or "failed"
  std::string last_rejection_;

  // The record of frame `frame` (replacing one of the same step if `last_word`);
  // none if the run has no such frame.
  std::optional<Stamp> at_frame(int64_t frame, bool last_word) const;
  // "" if the result's frame index is one of the run's or -1 (none yet), else why not.
  std::string frame_problem(int32_t frame_index) const;
  bool rejected(const std::string &channel, const std::string &why);
  void write_run_info(const run_info_t &m);
  void write_sim(const sim_status_t &m);
  void write_node(const node_status_t &m);
  template <class T> void write_result(const T &m);
  void write_summary(const std::vector<std::string> &missing);
  void count_frames();
  void guarded(const char *what, const std::function<void()> &write);
};

} // namespace dynhet
