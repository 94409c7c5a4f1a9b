// Frames travel as chunks of at most 1 MiB (UDP loses bigger messages
// whole); these pieces split a frame and put it back together, counting
// frames that never complete. No LCM here: the nodes copy message fields
// into a ChunkHeader.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <vector>

namespace dynhet {

struct ChunkRange {
  int first;
  int count;
};
// Consecutive ranges of at most `per_chunk` particles covering [0, n).
std::vector<ChunkRange> chunk_ranges(int n_particles, int per_chunk);

struct ChunkHeader {
  int frame_index;
  double time;
  int n_particles;
  int chunk_index;
  int chunk_count;
  int first_particle;
  int count;
};

struct Frame {
  int index = -1;
  double time = 0;
  std::vector<double> position; // x0 y0 x1 y1 ..., unwrapped
};

class FrameAssembler {
public:
  // Frames arrive in index order from one publisher; a frame still
  // incomplete when a chunk of frame index + `reorder_window` + 1 arrives
  // is given up as lost.
  explicit FrameAssembler(int reorder_window = 1) : window_(reorder_window) {}

  // The run the chunks belong to (from its run info): from now on a chunk
  // is taken only if it is exactly one of the run's chunks (its N, a frame
  // index below n_frames, the chunk count and the particle range
  // chunk_ranges gives) with finite positions; anything else is malformed.
  void expect(int n_particles, int n_frames, int chunk_particles);

  // Adds one chunk (positions of header.count particles). Returns the frame
  // when this chunk completes it. Malformed chunks are counted and dropped.
  std::optional<Frame> add(const ChunkHeader& h, const double* position);

  // The run has ended after `frames_expected` frames: whatever is not whole
  // now is lost.
  void finish(int frames_expected);

  // The publisher has sent every frame below `published` and no chunk has
  // come for a while: frames below it that are still incomplete are lost
  // now. (Otherwise a lost chunk of the last frame out waits for a chunk
  // of a frame `reorder_window` + 1 later, which a paced sim does not send
  // until this one is through.) Only frames of which a chunk arrived;
  // returns how many were given up.
  int give_up_before(int published);

  int frames_whole() const { return whole_; }
  int frames_lost() const { return lost_; }
  int64_t chunks_received() const { return chunks_; }
  int64_t chunks_malformed() const { return malformed_; }

  // A checkpoint (state_archive.hpp): which frames are settled and the
  // counts. Taken at a frame boundary (give_up_before first), so nothing
  // up to it is pending.
  template <class Ar> void state(Ar& ar) {
    std::vector<uint8_t> done(done_.begin(), done_.end());
    ar(done, whole_, lost_, chunks_, malformed_);
    done_.assign(done.begin(), done.end());
  }

private:
  struct Pending {
    Frame frame;
    std::vector<bool> have;
    int missing;
  };
  int window_;
  int n_ = 0, frames_ = 0, per_chunk_ = 0, chunks_per_frame_ = 0; // expect(); 0: not known
  std::map<int, Pending> pending_;
  std::vector<bool> done_; // frame index -> completed or given up
  int whole_ = 0, lost_ = 0;
  int64_t chunks_ = 0, malformed_ = 0;
  void mark_done(int index);
  bool is_done(int index) const { return index < static_cast<int>(done_.size()) && done_[index]; }
};

} // namespace dynhet
