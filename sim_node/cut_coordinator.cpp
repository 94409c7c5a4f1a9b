#include "cut_coordinator.hpp"

#include <cstdio>
#include <filesystem>
#include <thread>

#include "dynhet/checkpoint_t.hpp"
#include "dynhet/cut.hpp"
#include "dynhet/lcm_exit.hpp"
#include "dynhet/lcm_guard.hpp"
#include "dynhet/lcm_url.hpp"
#include "dynhet/message_checks.hpp"
#include "dynhet/state_archive.hpp"

namespace dynhet {

CutCoordinator::CutCoordinator(lcm::LCM& lcm, Bus bus, std::string dir, int64_t run_id, std::string scene_text,
                               std::vector<std::string> parts)
    : lcm_(lcm), bus_(std::move(bus)), dir_(std::move(dir)), run_id_(run_id), scene_(std::move(scene_text)),
      scene_hash_(dynhet::scene_hash(scene_)), parts_(std::move(parts)) {
  std::filesystem::create_directories(dir_);
  const std::vector<int> cuts = list_cuts(dir_);
  next_cut_ = cuts.empty() ? 0 : cuts.back() + 1;
  for (auto it = cuts.rbegin(); it != cuts.rend(); ++it)
    if (const auto m = read_cut_marker(dir_, *it)) {
      if (last_whole_ < 0) last_whole_ = *it, last_whole_frame_ = m->frame;
      else if (previous_whole_ < 0) previous_whole_ = *it, previous_whole_frame_ = m->frame;
    }
  // Answers of every process (LCM patterns match whole names).
  sub_ = lcm_.subscribe(std::string(kChanCheckpoint) + "_.*", &CutCoordinator::on_answer, this);
  sub_->setQueueCapacity(1 << 14);
  sub_->setQueueCapacity(1000);
}

CutCoordinator::~CutCoordinator() {
  if (sub_) lcm_.unsubscribe(sub_);
}

double CutCoordinator::seconds_since_take() const {
  return std::chrono::duration<double>(Clock::now() - last_take_).count();
}

int CutCoordinator::take(int frame, double t, const std::vector<uint8_t>& sim_payload, bool stop) {
  if (!broken_.empty()) return -1;
  const int cut = next_cut_++;
  last_take_ = Clock::now();
  std::filesystem::create_directories(cut_dir(dir_, cut));
  // Older cuts stay open: nodes behind the sim (up to its pacing window)
  // save them in turn.
  while (pending_.size() >= kMaxOpen) pending_.erase(pending_.begin());
  Pending& p = pending_[cut];
  p.frame = frame, p.time = t, p.stop = stop;
  // The request first, then the sim's own part: the nodes and the recorder
  // write theirs while the sim writes its own (at N = 10^6 a stop's sim
  // part takes seconds), instead of after it. The cut is whole only once
  // the sim's part, too, is on disk and reads back (complete()); its
  // answers wait in the subscription's queue meanwhile.
  request(cut, p);
  PartHeader h;
  h.process = "sim", h.run_id = run_id_, h.cut = cut, h.frame = frame, h.scene_hash = scene_hash_;
  try {
    write_part(part_path(dir_, cut, "sim", frame), h, sim_payload);
  } catch (...) {
    // Not a cut: the others' parts of this frame boundary stay unused (and
    // go with the pruning), the restart point stays where it was.
    pending_.erase(cut);
    throw;
  }
  pending_[cut].saved.insert("sim");
  return cut;
}

void CutCoordinator::request(int cut, const Pending& p) {
  checkpoint_t m{};
  m.utime = utime_now();
  m.run_id = run_id_;
  m.cut = cut;
  m.frame = p.frame;
  m.sim_time = p.time;
  m.process = "sim";
  m.state = "save";
  m.message = p.stop ? "stop" : "";
  bus_.publish(lcm_, kChanCheckpoint, m);
  pending_[cut].asked = Clock::now();
}

void CutCoordinator::on_answer(const lcm::ReceiveBuffer* rb, const std::string& channel) {
  checkpoint_t m;
  std::string why;
  int size = 0;
  if (!bus_.open(channel, rb->data, rb->data_size, size, why)) {
    ++unauthenticated_;
    return;
  }
  if (!guard::safe_decode(rb->data, size, m, why)) return; // untrusted: dropped
  if (m.run_id != run_id_ || channel != checkpoint_answer_channel(m.process)) return;
  if (!checkpoint_problem(m, INT32_MAX - 1).empty()) return;
  auto it = pending_.find(m.cut);
  if (it == pending_.end() || m.frame != it->second.frame) return; // not this cut's boundary
  if (m.state == "saved") {
    it->second.saved.insert(m.process);
  } else if (m.state == "failed") {
    // A process that said "saved" has its part on disk (complete() checks):
    // a later "failed" answers a request sent again, or is not its own.
    if (it->second.saved.count(m.process)) return;
    std::fprintf(stderr, "\nsim_node: checkpoint cut %d: %s could not save its part (%s); the restart point stays "
                 "cut %d\n", m.cut, m.process.c_str(), m.message.c_str(), last_whole_);
    pending_.erase(it);
  }
}

bool CutCoordinator::complete(int cut, Pending& p) {
  // A newer cut is whole already (this one's last answer came late): it
  // adds nothing, and marking it whole would move the restart point back
  // and let the pruning below remove it.
  if (cut <= last_whole_) return true;
  CutInfo c;
  c.cut = cut, c.frame = p.frame, c.sim_time = p.time, c.run_id = run_id_, c.parts = parts_;
  try {
    const std::vector<std::string> bad = mark_cut_whole(dir_, c, scene_hash_);
    if (!bad.empty()) {
      // Answered but not on disk (a forged answer, or a write that failed
      // after it): wait for those processes' own answers again.
      for (const std::string& b : bad) {
        const std::string who = b.substr(0, b.find(':'));
        p.saved.erase(who);
        const int times = ++p.unusable[who];
        if (times == 1) std::fprintf(stderr, "\nsim_node: checkpoint cut %d: no usable part of %s\n", cut, b.c_str());
        // Its own answers keep coming ("saved" to every repeated request):
        // a part that stays unusable fails the cut instead of holding it
        // open to the end of the run.
        if (times >= kUnusableAnswers && !p.failed) {
          p.failed = true;
          std::fprintf(stderr, "\nsim_node: checkpoint cut %d fails: the part of %s is still unusable after %d of "
                       "its answers; the restart point stays cut %d\n", cut, who.c_str(), kUnusableAnswers,
                       last_whole_);
        }
        // A part from another build will not do at any cut: stop waiting.
        try {
          const PartHeader h = read_part_header(part_path(dir_, cut, who, p.frame));
          // (this run's part of this boundary by that process, not a file
          // left over from another run)
          if (h.build != build_id() && h.run_id == run_id_ && h.process == who && h.frame == p.frame &&
              broken_.empty())
            broken_ = who + " writes its parts from another build (" + h.build + "; this sim is " + build_id() +
                      "): start every process of a run from one build";
        } catch (const std::exception&) { // unreadable: another answer may yet bring it
        }
      }
      if (!broken_.empty()) {
        std::fprintf(stderr, "\nsim_node: checkpoint cuts are off for this run: %s. The run goes on; its restart "
                     "point stays cut %d\n", broken_.c_str(), last_whole_);
        pending_.clear();
      }
      return false;
    }
  } catch (const std::exception& e) { // WHOLE itself cannot be written
    std::fprintf(stderr, "\nsim_node: checkpoint cut %d is not whole: %s\n", cut, e.what());
    return false;
  }
  if (last_whole_ >= 0) previous_whole_ = last_whole_, previous_whole_frame_ = last_whole_frame_;
  last_whole_ = cut, last_whole_frame_ = p.frame;
  // The previous whole cut stays, as the fallback if this one is damaged.
  if (previous_whole_ >= 0) prune_cuts(dir_, previous_whole_, previous_whole_frame_);
  else prune_cuts(dir_, cut, p.frame);
  checkpoint_t m{};
  m.utime = utime_now();
  m.run_id = run_id_, m.cut = cut, m.frame = p.frame, m.sim_time = p.time;
  m.process = "sim", m.state = "whole";
  bus_.publish(lcm_, kChanCheckpoint, m);
  return true;
}

void CutCoordinator::poll() {
  while (handle_timeout(lcm_, 0) > 0) {
  }
  for (auto it = pending_.begin(); it != pending_.end();) {
    Pending& p = it->second;
    bool all = true;
    for (const std::string& part : parts_) all = all && p.saved.count(part);
    if (all && complete(it->first, p)) {
      it = pending_.erase(it);
      continue;
    }
    if (!broken_.empty()) return; // complete() dropped every open cut (it is invalid)
    if (p.failed || it->first < last_whole_) { // given up, or passed by a newer whole cut
      it = pending_.erase(it);
      continue;
    }
    if (std::chrono::duration<double>(Clock::now() - p.asked).count() > 1.0) request(it->first, p);
    ++it;
  }
}

int CutCoordinator::newest_open() const { return pending_.empty() ? -1 : pending_.rbegin()->first; }

bool CutCoordinator::wait_whole(int cut, double timeout, const std::function<bool()>& abort) {
  const auto t0 = Clock::now();
  for (;;) {
    poll();
    if (last_whole_ == cut) return true;
    if (!pending_.count(cut)) return false; // failed somewhere
    if (abort && abort()) return false;
    if (std::chrono::duration<double>(Clock::now() - t0).count() > timeout) return false;
    handle_timeout(lcm_, 20);
  }
}

} // namespace dynhet
