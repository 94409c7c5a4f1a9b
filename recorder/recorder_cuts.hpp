// The recorder's side of a checkpoint cut (dynhet/cut.hpp,
// docs/checkpoints.md). The sim asks for cut c after frame k; each node
// saves its part once it has folded frame k in and published its results
// up to k, then says "saved". The recorder saves last: once the sim's
// request and every node's "saved" are here, every result up to frame k
// is in its journal, so its part is the journal's length and CRC at that
// moment (synced to disk first). Then it says "saved" and the sim marks
// the cut whole. Every checkpoint message is untrusted: a wrong run,
// channel or shape is dropped and counted by the caller.
#pragma once

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "dynhet/bus.hpp"
#include "dynhet/checkpoint_t.hpp"
#include "dynhet/run_info_t.hpp"
#include "journal.hpp"

namespace dynhet {

class RecorderCuts {
public:
  RecorderCuts(lcm::LCM& lcm, Bus bus, std::string dir) : lcm_(lcm), bus_(std::move(bus)), dir_(std::move(dir)) {}
  const std::string& dir() const { return dir_; }
  std::string journal_path() const { return dir_ + "/recorder.journal"; }
  Journal& journal() { return journal_; }

  // The run is known: its nodes are those whose parts must come first.
  void set_run(const run_info_t& run);
  // A checkpoint message (decoded and checked by the caller). Returns ""
  // or why it was dropped.
  std::string on_message(const checkpoint_t& m, const std::string& channel);
  // Saves every cut that is ready. Returns the cuts saved now.
  std::vector<int> save_ready();
  int saved_cut() const { return saved_cut_; }
  // Whether a cut the sim said it stops after ("stop") has been saved.
  bool stop_cut_saved() const { return stop_saved_; }

  // Resuming from cut `cut`: reads this recorder's part (every check of
  // read_part but the scene, which only the replayed run info tells) and
  // replays the journal's prefix through `replay`. Returns the part's
  // header for the caller to check run and scene against what was replayed.
  struct Resumed {
    int64_t run_id;
    uint64_t scene_hash;
    int frame;
    uint64_t journal_bytes;
    std::string part; // its file
  };
  template <class Replay> Resumed resume(int cut, Replay&& replay);

private:
  struct Boundary { // the cuts asked for at one frame boundary
    bool requested = false; // by the sim (else only answers so far)
    bool stop = false;      // one is the sim's last before it stops
    std::vector<int> cuts;
    std::set<std::string> saved; // nodes that said "saved"
  };
  void answer(int cut, int frame, const std::string& state, int64_t bytes, double seconds, const std::string& message);
  Boundary& entry(int frame);
  bool parts_on_disk(int cut, int frame) const;
  Resumed read_and_replay(int cut, const std::function<void(const std::string&, const uint8_t*, uint32_t)>& replay);

  lcm::LCM& lcm_;
  Bus bus_;
  std::string dir_;
  Journal journal_;
  int64_t run_id_ = 0;
  uint64_t scene_hash_ = 0;
  std::set<std::string> nodes_;
  std::map<int, Boundary> pending_; // frame -> cuts asked for there
  std::map<int, int64_t> saved_;    // frame boundaries saved -> journal bytes
  int saved_cut_ = -1;
  bool stop_saved_ = false;
};

template <class Replay> RecorderCuts::Resumed RecorderCuts::resume(int cut, Replay&& replay) {
  return read_and_replay(cut, replay);
}

} // namespace dynhet
