// FrameNode's side of a checkpoint cut (dynhet/cut.hpp, docs/checkpoints.md):
// the sim asks for cut c after frame k; the node saves its part once frame k
// is folded in (or at the first chunk of a later frame, k being lost) and
// answers on DYNHET_CHECKPOINT_<node>; a request it is already past is
// answered "failed". A resumed node loads its part after start().
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
  if (m.cut == saved_cut_) return answer_cut(saved_cut_, "saved", saved_bytes_, saved_seconds_, ""); // asked again
  if (m.cut < saved_cut_ || pending_cuts_.count(m.cut)) return;
  if (pending_cuts_.size() >= 64) pending_cuts_.erase(pending_cuts_.begin()); // a flood: the oldest go
  pending_cuts_[m.cut] = m;
  try_cut();
}

// The cuts asked for, in order: each is saved when this node stands at its
// boundary, and refused when it is past it.
void FrameNode::try_cut(int next_chunk_frame) {
  while (!pending_cuts_.empty() && !finished_) {
    const checkpoint_t c = pending_cuts_.begin()->second;
    if (last_frame_ > c.frame) {
      // Past the boundary already (a request that came late): this cut
      // cannot have this node's part, so it will not be whole.
      pending_cuts_.erase(pending_cuts_.begin());
      answer_cut(c.cut, "failed", 0, 0, "frame " + std::to_string(last_frame_) +
                                           " already folded in, past the cut's " + std::to_string(c.frame));
      continue;
    }
    if (!(last_frame_ == c.frame || next_chunk_frame > c.frame)) return;
    pending_cuts_.erase(pending_cuts_.begin());
    save_cut(c);
  }
}

void FrameNode::save_cut(const checkpoint_t& c) {
  const auto t0 = Clock::now();
  try {
    assembler_.give_up_before(c.frame + 1); // frames up to the cut are settled
    StateOut out;
    base_state(out);
    save_state(out);
    std::filesystem::create_directories(cut_dir(cut_dir_, c.cut));
    PartHeader h;
    h.process = name_, h.run_id = info_->run_id, h.cut = c.cut, h.frame = c.frame;
    h.scene_hash = scene_hash(info_->scene_toml);
    write_part(part_path(cut_dir_, c.cut, name_), h, out.bytes());
    saved_cut_ = c.cut;
    saved_bytes_ = static_cast<int64_t>(out.bytes().size());
    saved_seconds_ = std::chrono::duration<double>(Clock::now() - t0).count();
    std::fprintf(stderr, "%s_node: checkpoint: cut %d after frame %d saved (%.1f MB in %.2f s)\n", name_.c_str(),
                 c.cut, c.frame, saved_bytes_ / 1e6, saved_seconds_);
    answer_cut(c.cut, "saved", saved_bytes_, saved_seconds_, "");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s_node: checkpoint: cut %d NOT saved: %s\n", name_.c_str(), c.cut, e.what());
    answer_cut(c.cut, "failed", 0, 0, e.what());
    if (!signal_) return;
  }
  // After a signal: stop with the sim's last cut (its request says "stop").
  if (signal_ && c.message == "stop")
    stop_resumable("signal " + std::to_string(signal_) + ": stopped after cut " + std::to_string(c.cut));
}

void FrameNode::answer_cut(int cut, const std::string& state, int64_t bytes, double seconds,
                           const std::string& message) {
  checkpoint_t a{};
  a.utime = utime_now();
  a.run_id = info_->run_id;
  a.cut = cut;
  a.frame = last_frame_;
  a.sim_time = last_time_;
  a.process = name_;
  a.state = state;
  a.bytes = bytes;
  a.write_seconds = seconds;
  a.message = message.substr(0, 400);
  out_.publish(checkpoint_answer_channel(name_), &a);
}

void FrameNode::load_cut() {
  const std::string path = part_path(cut_dir_, resume_cut_, name_);
  try {
    PartHeader h;
    const std::vector<uint8_t> bytes =
        read_part(path, name_, info_->run_id, scene_hash(info_->scene_toml), &h);
    StateIn in(bytes.data(), bytes.size(), path);
    base_state(in);
    load_state(in);
    if (!in.at_end()) throw BadPart(path + ": " + std::to_string(bytes.size() - in.offset()) + " bytes left over");
    saved_cut_ = resume_cut_;
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

void FrameNode::publish_status() {
  status_.utime = utime_now();
  status_.frames_whole = assembler_.frames_whole();
  status_.frames_lost = assembler_.frames_lost();
  status_.chunks_received = assembler_.chunks_received();
  status_.pairs_done = pairs_done_;
  status_.origins_held = static_cast<int32_t>(origins_.size());
  out_.publish(node_status_channel(name_), &status_);
  last_status_ = Clock::now();
}

void FrameNode::tick() {
  watch_inbox();
  if (signal_ && !finished_ && std::chrono::duration<double>(Clock::now() - signalled_at_).count() > kSignalWait)
    stop_resumable("signal " + std::to_string(signal_) + ", and no last cut from the sim within " +
                   std::to_string(static_cast<int>(kSignalWait)) + " s");
  if (info_) maybe_done();
  if (finished_) return;
  if (std::chrono::duration<double>(Clock::now() - last_status_).count() >= 1.0) publish_status();
}

void FrameNode::finish(int code, const std::string& why) {
  if (info_) assembler_.finish(info_->n_frames);
  if (info_ && started_) publish_results(true);
  status_.state = code == 0 ? "done" : "failed";
  // Frames lost in a run that ended: the cause this node knows, in its
  // last status (run.h5 keeps it) and its log.
  const std::string cause = code == 0 && assembler_.frames_lost() > 0 ? loss_cause() : "";
  status_.message = cause.empty() ? why : std::to_string(assembler_.frames_lost()) + " frames lost: " + cause;
  publish_status();
  std::fprintf(stderr, "%s_node: %s: %d frames whole, %d lost%s%s\n", name_.c_str(), status_.state.c_str(),
               assembler_.frames_whole(), assembler_.frames_lost(), why.empty() ? "" : "; ", why.c_str());
  if (!cause.empty()) std::fprintf(stderr, "%s_node: frames lost: %s\n", name_.c_str(), cause.c_str());
  if (inbox_) {
    const Inbox::Stats s = inbox_->stats();
    std::fprintf(stderr, "%s_node: queue (receive thread -> computation): peak %.2f MiB of %lld MiB, %lld messages "
                 "dropped; the longest message took %.3f s\n", name_.c_str(), double(s.peak_bytes) / (1 << 20),
                 static_cast<long long>(s.bound >> 20), static_cast<long long>(s.dropped), longest_handler_);
  }
  finished_ = true;
  exit_code_ = code;
}

} // namespace dynhet
