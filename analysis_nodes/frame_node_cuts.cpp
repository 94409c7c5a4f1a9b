// FrameNode's side of a checkpoint cut (dynhet/cut.hpp, docs/checkpoints.md):
// the sim asks for cut c after frame k; the node saves its part once frame k
// is folded in (or at the first chunk of a later frame, k being lost) and
// answers on DYNHET_CHECKPOINT_<node>. A request for a boundary it saved
// (the sim repeats requests until the cut is whole) is answered "saved"
// again; one for a boundary it is past without having saved it, "failed".
// A resumed node loads its part after start().
#include <algorithm>
#include <climits>
#include <cstdio>
#include <filesystem>

#include "dynhet/cut.hpp"
#include "dynhet/message_checks.hpp"
#include "frame_node.hpp"

namespace dynhet {

void FrameNode::on_checkpoint(const checkpoint_t& m) {
  if (!info_ || !started_ || finished_ || !checkpointing() || m.run_id != info_->run_id) return;
  if (const std::string bad = checkpoint_problem(m, info_->n_frames); !bad.empty())
    return reject(kChanCheckpoint, "checkpoint: " + bad);
  if (m.process == "sim" && m.state == "whole") return; // news of a cut: nothing to do here
  if (m.process != "sim" || m.state != "save") return reject(kChanCheckpoint, "checkpoint: not a request of the sim");
  // Requests are untrusted. The node's state at a frame boundary is one
  // part, whichever cut asks for it: requests for a boundary already saved
  // are answered from it, and a flood of requests for one boundary costs
  // one part. The 64 nearest boundaries are kept (a flood of far ones goes).
  if (const auto s = saved_parts_.find(m.frame); s != saved_parts_.end())
    return answer_cut(m.cut, m.frame, "saved", s->second.bytes, s->second.seconds, "");
  Boundary& b = pending_cuts_[m.frame];
  if (std::find(b.cuts.begin(), b.cuts.end(), m.cut) == b.cuts.end() && b.cuts.size() < 16) b.cuts.push_back(m.cut);
  b.stop = b.stop || m.message == "stop";
  if (pending_cuts_.size() > 64) pending_cuts_.erase(std::prev(pending_cuts_.end()));
  try_cut();
}

// Each boundary asked for is saved when this node stands at it, and refused
// when it is past it.
void FrameNode::try_cut(int next_chunk_frame) {
  while (!pending_cuts_.empty() && !finished_) {
    const int frame = pending_cuts_.begin()->first;
    const Boundary b = pending_cuts_.begin()->second;
    if (last_frame_ > frame) {
      // Past the boundary already (a request that came late): these cuts
      // cannot have this node's part, so they will not be whole.
      pending_cuts_.erase(pending_cuts_.begin());
      for (int cut : b.cuts)
        answer_cut(cut, frame, "failed", 0, 0, "frame " + std::to_string(last_frame_) +
                                                  " already folded in, past the cut's " + std::to_string(frame));
      continue;
    }
    if (!(last_frame_ == frame || next_chunk_frame > frame)) return;
    pending_cuts_.erase(pending_cuts_.begin());
    save_cut(frame, b);
  }
}

int FrameNode::first_pending_frame() const { return pending_cuts_.empty() ? INT32_MAX : pending_cuts_.begin()->first; }

void FrameNode::save_cut(int frame, const Boundary& b) {
  const auto t0 = Clock::now();
  try {
    assembler_.give_up_before(frame + 1); // frames up to the boundary are settled
    drain_unauthenticated();
    StateOut out;
    base_state(out);
    save_state(out);
    const std::string path = part_path(cut_dir_, b.cuts.front(), name_, frame);
    std::filesystem::create_directories(std::filesystem::path(path).parent_path());
    PartHeader h;
    h.process = name_, h.run_id = info_->run_id, h.cut = b.cuts.front(), h.frame = frame;
    h.scene_hash = scene_hash(info_->scene_toml);
    write_part(path, h, out.bytes());
    saved_frame_ = frame;
    const SavedPart part{static_cast<int64_t>(out.bytes().size()),
                         std::chrono::duration<double>(Clock::now() - t0).count()};
    saved_parts_[frame] = part;
    if (saved_parts_.size() > 64) saved_parts_.erase(saved_parts_.begin());
    std::fprintf(stderr, "%s_node: checkpoint: cut %d after frame %d saved (%.1f MB in %.2f s)\n", name_.c_str(),
                 b.cuts.front(), frame, part.bytes / 1e6, part.seconds);
    for (int cut : b.cuts) answer_cut(cut, frame, "saved", part.bytes, part.seconds, "");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s_node: checkpoint: cut %d NOT saved: %s\n", name_.c_str(), b.cuts.front(), e.what());
    for (int cut : b.cuts) answer_cut(cut, frame, "failed", 0, 0, e.what());
    if (!signal_) return;
  }
  // After a signal: stop with the sim's last cut (its request says "stop").
  if (signal_ && b.stop)
    stop_resumable("signal " + std::to_string(signal_) + ": stopped after cut " + std::to_string(b.cuts.back()));
}

void FrameNode::answer_cut(int cut, int frame, const std::string& state, int64_t bytes, double seconds,
                           const std::string& message) {
  checkpoint_t a{};
  a.utime = utime_now();
  a.run_id = info_->run_id;
  a.cut = cut;
  a.frame = frame;
  a.sim_time = last_time_;
  a.process = name_;
  a.state = state;
  a.bytes = bytes;
  a.write_seconds = seconds;
  a.message = message.substr(0, 400);
  publish(checkpoint_answer_channel(name_), a);
}

void FrameNode::load_cut() {
  std::string path = cut_dir(cut_dir_, resume_cut_) + "/WHOLE";
  try {
    const std::optional<CutInfo> whole = read_cut_marker(cut_dir_, resume_cut_);
    if (!whole) throw BadPart(path + ": missing or unreadable: cut " + std::to_string(resume_cut_) + " is not whole");
    path = part_path(cut_dir_, resume_cut_, name_, whole->frame);
    PartHeader h;
    const std::vector<uint8_t> bytes =
        read_part(path, name_, info_->run_id, scene_hash(info_->scene_toml), &h);
    StateIn in(bytes.data(), bytes.size(), path);
    base_state(in);
    load_state(in);
    if (!in.at_end()) throw BadPart(path + ": " + std::to_string(bytes.size() - in.offset()) + " bytes left over");
    saved_frame_ = h.frame;
    saved_parts_[h.frame] = SavedPart{static_cast<int64_t>(bytes.size()), 0};
    std::fprintf(stderr, "%s_node: resumed from cut %d after frame %d (t = %.10g): %d frames whole, %d lost, %d "
                 "pairs done, %zu origins held\n", name_.c_str(), h.cut, h.frame, last_time_,
                 assembler_.frames_whole(), assembler_.frames_lost(), pairs_done_, origins_.size());
  } catch (const std::exception& e) {
    finish(1, std::string("cannot resume: ") + e.what());
  }
  resume_cut_ = -1;
}

// Stopped with nothing final: the results stay open, to be resumed.
void FrameNode::stop_resumable(const std::string& why) {
  if (finished_) return;
  status_.state = "interrupted";
  status_.message = why;
  publish_status();
  std::fprintf(stderr, "%s_node: interrupted, resumable: %s\n", name_.c_str(), why.c_str());
  finished_ = true;
  exit_code_ = kInterrupted;
}

} // namespace dynhet
