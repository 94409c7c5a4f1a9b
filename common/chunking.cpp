#include "dynhet/chunking.hpp"

#include <cmath>

#include <algorithm>

namespace dynhet {

std::vector<ChunkRange> chunk_ranges(int n, int per_chunk) {
  std::vector<ChunkRange> r;
  for (int first = 0; first < n; first += per_chunk) r.push_back({first, std::min(per_chunk, n - first)});
  return r;
}

void FrameAssembler::mark_done(int index) {
  if (index >= static_cast<int>(done_.size())) done_.resize(index + 1, false);
  done_[index] = true;
}

void FrameAssembler::expect(int n_particles, int n_frames, int chunk_particles) {
  n_ = n_particles, frames_ = n_frames, per_chunk_ = chunk_particles;
  chunks_per_frame_ = static_cast<int>((int64_t(n_particles) + chunk_particles - 1) / chunk_particles);
}

std::optional<Frame> FrameAssembler::add(const ChunkHeader& h, const double* position) {
  ++chunks_;
  bool sane = h.frame_index >= 0 && h.n_particles > 0 && h.chunk_count > 0 && h.chunk_index >= 0 &&
              h.chunk_index < h.chunk_count && h.first_particle >= 0 && h.count > 0 &&
              int64_t(h.first_particle) + h.count <= h.n_particles; // no int overflow
  if (sane && n_ > 0) {
    // Exactly one of the run's chunks: nothing else may size a frame.
    const int64_t first = int64_t(h.chunk_index) * per_chunk_;
    sane = h.n_particles == n_ && h.frame_index < frames_ && h.chunk_count == chunks_per_frame_ &&
           h.first_particle == first && h.count == std::min<int64_t>(per_chunk_, n_ - first);
  }
  for (int i = 0; sane && i < 2 * h.count; ++i) sane = std::isfinite(position[i]);
  if (!sane) {
    ++malformed_;
    return std::nullopt;
  }
  // Frames far behind this one will not complete any more.
  for (auto it = pending_.begin(); it != pending_.end() && it->first + window_ < h.frame_index;) {
    ++lost_;
    mark_done(it->first);
    it = pending_.erase(it);
  }
  if (is_done(h.frame_index)) return std::nullopt; // duplicate, or too late

  auto [it, fresh] = pending_.try_emplace(h.frame_index);
  Pending& p = it->second;
  if (fresh) {
    p.frame.index = h.frame_index;
    p.frame.time = h.time;
    p.frame.position.assign(2 * static_cast<size_t>(h.n_particles), 0.0);
    p.have.assign(h.chunk_count, false);
    p.missing = h.chunk_count;
  } else if (static_cast<int>(p.have.size()) != h.chunk_count ||
             p.frame.position.size() != 2 * static_cast<size_t>(h.n_particles)) {
    ++malformed_;
    return std::nullopt;
  }
  if (p.have[h.chunk_index]) return std::nullopt; // duplicate chunk
  p.have[h.chunk_index] = true;
  --p.missing;
  std::copy(position, position + 2 * h.count, p.frame.position.begin() + 2 * h.first_particle);
  if (p.missing > 0) return std::nullopt;

  Frame f = std::move(p.frame);
  pending_.erase(it);
  mark_done(f.index);
  ++whole_;
  return f;
}

int FrameAssembler::give_up_before(int published) {
  int n = 0;
  for (auto it = pending_.begin(); it != pending_.end() && it->first < published; ++n) {
    ++lost_;
    mark_done(it->first);
    it = pending_.erase(it);
  }
  return n;
}

void FrameAssembler::finish(int frames_expected) {
  pending_.clear();
  lost_ = std::max(0, frames_expected - whole_);
  for (int i = 0; i < frames_expected; ++i) mark_done(i);
}

} // namespace dynhet
