#include "recorder_cuts.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "dynhet/cut.hpp"
#include "dynhet/flow_control.hpp"
#include "dynhet/lcm_url.hpp"
#include "dynhet/scene.hpp"
#include "dynhet/state_archive.hpp"

namespace dynhet {

void RecorderCuts::set_run(const run_info_t& run) {
  run_id_ = run.run_id;
  scene_hash_ = scene_hash(run.scene_toml);
  nodes_.clear();
  for (const std::string& n : nodes_for(run.observables)) nodes_.insert(n.substr(0, n.size() - 5)); // "_node"
}

std::string RecorderCuts::on_message(const checkpoint_t& m, const std::string& channel) {
  if (run_id_ == 0 || m.run_id != run_id_) return ""; // another run's, or before ours: not ours to judge
  if (m.process == "sim") {
    if (channel != kChanCheckpoint) return "a request of the sim on another channel";
    if (m.state == "whole") return "";
    if (m.state != "save") return "the sim's state \"" + m.state + "\"";
    if (auto s = saved_.find(m.frame); s != saved_.end()) {
      answer(m.cut, m.frame, "saved", s->second, 0, ""); // this boundary is saved: whichever cut asks
      return "";
    }
    Boundary& b = entry(m.frame);
    b.requested = true;
    if (std::find(b.cuts.begin(), b.cuts.end(), m.cut) == b.cuts.end() && b.cuts.size() < 16) b.cuts.push_back(m.cut);
    b.stop = b.stop || m.message == "stop";
  } else {
    if (channel != checkpoint_answer_channel(m.process)) return "not this process's channel";
    if (!nodes_.count(m.process) || m.state != "saved" || saved_.count(m.frame)) return "";
    entry(m.frame).saved.insert(m.process);
  }
  return "";
}

// Requests and answers are untrusted: one entry per frame boundary, and a
// flood of them keeps the 64 nearest boundaries.
RecorderCuts::Boundary& RecorderCuts::entry(int frame) {
  pending_[frame];
  if (pending_.size() > 64) pending_.erase(std::prev(pending_.end()));
  return pending_[frame];
}

// Every node's part of the boundary is on disk: an answer alone could be
// anyone's.
bool RecorderCuts::parts_on_disk(int cut, int frame) const {
  for (const std::string& n : nodes_) {
    try {
      const PartHeader h = read_part_header(part_path(dir_, cut, n, frame));
      if (h.process != n || h.frame != frame || h.run_id != run_id_) return false;
    } catch (const std::exception&) {
      return false;
    }
  }
  return true;
}

std::vector<int> RecorderCuts::save_ready() {
  std::vector<int> saved;
  for (auto it = pending_.begin(); it != pending_.end();) {
    const int frame = it->first;
    const Boundary& b = it->second;
    bool ready = b.requested;
    for (const std::string& n : nodes_) ready = ready && b.saved.count(n);
    ready = ready && parts_on_disk(b.cuts.front(), frame);
    if (!ready) {
      ++it;
      continue;
    }
    const auto t0 = std::chrono::steady_clock::now();
    try {
      journal_.sync();
      StateOut out;
      uint64_t length = journal_.length();
      uint32_t crc = journal_.crc();
      out(length, crc);
      const std::string path = part_path(dir_, b.cuts.front(), kRecorderNode, frame);
      std::filesystem::create_directories(std::filesystem::path(path).parent_path());
      PartHeader h;
      h.process = kRecorderNode, h.run_id = run_id_, h.cut = b.cuts.front(), h.frame = frame;
      h.scene_hash = scene_hash_;
      write_part(path, h, out.bytes());
      saved_[frame] = static_cast<int64_t>(length);
      if (saved_.size() > 64) saved_.erase(saved_.begin());
      saved_cut_ = std::max(saved_cut_, b.cuts.back());
      stop_saved_ = stop_saved_ || b.stop;
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      for (int cut : b.cuts) answer(cut, frame, "saved", static_cast<int64_t>(length), s, "");
      saved.push_back(b.cuts.front());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "recorder: checkpoint: cut %d NOT saved: %s\n", b.cuts.front(), e.what());
      for (int cut : b.cuts) answer(cut, frame, "failed", 0, 0, e.what());
    }
    it = pending_.erase(it);
  }
  return saved;
}

void RecorderCuts::answer(int cut, int frame, const std::string& state, int64_t bytes, double seconds,
                          const std::string& message) {
  checkpoint_t a{};
  a.utime = utime_now();
  a.run_id = run_id_;
  a.cut = cut;
  a.frame = frame;
  a.process = kRecorderNode;
  a.state = state;
  a.bytes = bytes;
  a.write_seconds = seconds;
  a.message = message.substr(0, 400);
  bus_.publish(lcm_, checkpoint_answer_channel(kRecorderNode), a);
}

RecorderCuts::Resumed RecorderCuts::read_and_replay(
    int cut, const std::function<void(const std::string&, const uint8_t*, uint32_t)>& replay) {
  const std::optional<CutInfo> whole = read_cut_marker(dir_, cut);
  if (!whole) throw BadPart(cut_dir(dir_, cut) + "/WHOLE: missing or unreadable: cut " + std::to_string(cut) +
                            " is not whole");
  const std::string path = part_path(dir_, cut, kRecorderNode, whole->frame);
  const PartHeader h0 = read_part_header(path);
  PartHeader h;
  const std::vector<uint8_t> bytes = read_part(path, kRecorderNode, h0.run_id, h0.scene_hash, &h);
  StateIn in(bytes.data(), bytes.size(), path);
  uint64_t length = 0;
  uint32_t crc = 0;
  in(length, crc);
  journal_.resume(journal_path(), length, crc, replay);
  saved_cut_ = cut;
  saved_[h.frame] = static_cast<int64_t>(length);
  return Resumed{h.run_id, h.scene_hash, h.frame, length, path};
}

} // namespace dynhet
