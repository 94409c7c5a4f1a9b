#include "recorder_cuts.hpp"

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
    if (m.cut == saved_cut_) {
      answer(m.cut, "saved", saved_bytes_, 0, ""); // asked again
      return "";
    }
    if (m.cut < saved_cut_) return "";
    pending_[m.cut].frame = m.frame;
    pending_[m.cut].stop = m.message == "stop";
  } else {
    if (channel != checkpoint_answer_channel(m.process)) return "not this process's channel";
    if (!nodes_.count(m.process) || m.state != "saved" || m.cut <= saved_cut_) return "";
    pending_[m.cut].saved.insert(m.process);
  }
  while (pending_.size() > 64) pending_.erase(pending_.begin()); // a flood: the oldest go
  return "";
}

std::vector<int> RecorderCuts::save_ready() {
  std::vector<int> saved;
  for (auto it = pending_.begin(); it != pending_.end();) {
    const int cut = it->first;
    const Pending& p = it->second;
    bool ready = p.frame >= -1;
    for (const std::string& n : nodes_) ready = ready && p.saved.count(n);
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
      std::filesystem::create_directories(cut_dir(dir_, cut));
      PartHeader h;
      h.process = kRecorderNode, h.run_id = run_id_, h.cut = cut, h.frame = p.frame, h.scene_hash = scene_hash_;
      write_part(part_path(dir_, cut, kRecorderNode), h, out.bytes());
      saved_cut_ = cut, saved_frame_ = p.frame;
      stop_saved_ = stop_saved_ || p.stop;
      saved_bytes_ = static_cast<int64_t>(length);
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      answer(cut, "saved", saved_bytes_, s, "");
      saved.push_back(cut);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "recorder: checkpoint: cut %d NOT saved: %s\n", cut, e.what());
      answer(cut, "failed", 0, 0, e.what());
    }
    // Older cuts than one saved (or failed) are over.
    it = pending_.erase(pending_.begin(), std::next(it));
  }
  return saved;
}

void RecorderCuts::answer(int cut, const std::string& state, int64_t bytes, double seconds,
                          const std::string& message) {
  checkpoint_t a{};
  a.utime = utime_now();
  a.run_id = run_id_;
  a.cut = cut;
  a.frame = state == "saved" ? saved_frame_ : -1;
  a.process = kRecorderNode;
  a.state = state;
  a.bytes = bytes;
  a.write_seconds = seconds;
  a.message = message.substr(0, 400);
  lcm_.publish(checkpoint_answer_channel(kRecorderNode), &a);
}

RecorderCuts::Resumed RecorderCuts::read_and_replay(
    int cut, const std::function<void(const std::string&, const uint8_t*, uint32_t)>& replay) {
  const std::string path = part_path(dir_, cut, kRecorderNode);
  const PartHeader h0 = read_part_header(path);
  PartHeader h;
  const std::vector<uint8_t> bytes = read_part(path, kRecorderNode, h0.run_id, h0.scene_hash, &h);
  StateIn in(bytes.data(), bytes.size(), path);
  uint64_t length = 0;
  uint32_t crc = 0;
  in(length, crc);
  journal_.resume(journal_path(), length, crc, replay);
  saved_cut_ = cut, saved_frame_ = h.frame, saved_bytes_ = static_cast<int64_t>(length);
  return Resumed{h.run_id, h.scene_hash, h.frame, length};
}

} // namespace dynhet
