#include <algorithm>
#include "run_recorder.hpp"

#include "dynhet/disk.hpp"

#include <cstdio>

#include "dynhet/lcm_url.hpp"
#include "dynhet/model.hpp"
#include "dynhet/run_info_scene.hpp"
#include "run_recorder_util.hpp"

namespace dynhet {

using namespace recorder_util;

namespace {

// A node's name as a path component.
std::string node_key(const std::string &node) {
  std::string key = node.empty() ? "unnamed" : node;
  for (char &c : key)
    if (c == '/') c = '_';
  return key;
}

std::string join(const std::vector<std::string> &lines, const char *sep) {
  std::string out;
  for (const std::string &l : lines) out += (out.empty() ? "" : sep) + l;
  return out;
}

bool ended(const std::string &phase) { return phase == "done" || phase == "failed"; }

} // namespace

RunRecorder::RunRecorder(std::string out_path, std::string creator_version, std::string author,
                         std::string author_email)
    : out_path_(std::move(out_path)), creator_version_(std::move(creator_version)),
      author_(std::move(author)), author_email_(std::move(author_email)) {}

std::optional<RunRecorder::Stamp> RunRecorder::at_frame(int64_t frame, bool last_word) const {
  if (frame < 0 || frame >= info_->n_frames) return std::nullopt;
  return Stamp{frame, info_->frame_time[frame], last_word};
}

// -1 is a node's "no frame yet" (e.g. its final result when the sim failed
// before the first frame): taken, with no record.
std::string RunRecorder::frame_problem(int32_t frame_index) const {
  if (frame_index >= -1 && frame_index < info_->n_frames) return "";
  return "frame_index " + std::to_string(frame_index) + " is not one of the run's " +
         std::to_string(info_->n_frames) + " frames (nor -1, none yet)";
}

bool RunRecorder::rejected(const std::string &channel, const std::string &why) {
  message_rejected(channel, why);
  return false;
}

// A failed write costs that record, not the run: it is reported on
// stderr (the first few times) and counted against completeness.
// Every write goes through here. A disk that fills must not leave an
// unreadable file: HDF5 that fails a write in mid-flush corrupts its own
// metadata. So before each write the recorder checks the free space, and
// below kDiskReserve it stops writing for good: it marks the file
// incomplete ("no space left on device"), closes it while it still can,
// and the run ends non-zero. A write that fails anyway stops writing too.
void RunRecorder::guarded(const char *what, const std::function<void()> &write) {
  if (stopped_) return;
  if (const int64_t free = free_bytes(out_path_); free >= 0 && free < kDiskReserve)
    return stop_writing("no space left on device (ENOSPC): " + std::to_string(free / 1024) +
                        " KiB free on the file system of " + out_path_ + ", below the " +
                        std::to_string(kDiskReserve / (1024 * 1024)) + " MiB the recorder keeps to close the file");
  try {
    write();
    if (flush_each_) writer_->flush();
  } catch (const std::exception &e) {
    const std::string why = e.what();
    if (++write_errors_ <= 10) std::fprintf(stderr, "recorder: %s: %s\n", what, why.substr(0, 400).c_str());
    if (write_errors_ == 10) std::fprintf(stderr, "recorder: further write errors not shown\n");
    if (why.find("errno = 28") != std::string::npos || why.find("No space left") != std::string::npos)
      stop_writing("no space left on device (ENOSPC) writing " + std::string(what));
  }
}

void RunRecorder::flush_each(bool on) {
  flush_each_ = on;
  if (on && writer_) guarded("flush", [] {});
}

void RunRecorder::stop_writing(const std::string &why) {
  if (stopped_) return;
  stopped_ = true;
  stop_reason_ = why;
  std::fprintf(stderr, "recorder: %s: stopped writing; the file stays readable and says incomplete\n", why.c_str());
  try {
    writer_->set_attribute("", "complete", int32_t{0});
    writer_->set_attribute("", "missing", why);
    writer_->flush();
  } catch (const std::exception &) {
    // what was flushed before stays; the summary says incomplete from the start
  }
}

bool RunRecorder::on_run(const run_info_t &recorded) {
  if (info_) return false;
  run_info_t m = recorded;
  if (!reanalysis_file_.empty()) {
    recorded_scene_ = recorded.scene_toml;
    apply_reanalysis(m, reanalysis_, reanalysis_file_);
  }
  writer_ =
      std::make_unique<H5mdWriter>(out_path_, "dynhet recorder", creator_version_, author_, author_email_);
  info_ = std::make_unique<run_info_t>(m);
  assembler_.expect(m.n_particles, m.n_frames, m.chunk_particles);
  writer_->set_auto_flush(false); // one flush per message, in guarded()
  completion_ = Completion(m.observables, m.cutoff_a);
  write_run_info(m);
  return true;
}

void RunRecorder::write_run_info(const run_info_t &m) {
  // Incomplete from the start: a recorder killed before finish() leaves a
  // file that says so (finish() overwrites both).
  guarded("summary", [&] {
    writer_->set_attribute("", "complete", int32_t{0});
    writer_->set_attribute("", "missing", std::string("the recorder did not finish the file (killed?)"));
  });
  guarded("parameters", [&] { writer_->write_parameters(m.scene_toml); });
  if (!reanalysis_file_.empty())
    guarded("re-analysis", [&] { writer_->write_reanalysis(m.run_id, reanalysis_file_, reanalysis_, recorded_scene_); });
  guarded("particles", [&] {
    const auto sp = dynhet::species_by_rule(m.n_particles, m.n_small);
    writer_->set_particles("all", m.box_length, std::vector<int32_t>(sp.begin(), sp.end()));
  });
  guarded("run info", [&] {
    const std::string p = "parameters/run_info";
    writer_->set_attribute(p, "run_id", m.run_id);
    writer_->set_attribute(p, "n_particles", m.n_particles);
    writer_->set_attribute(p, "box_length", m.box_length);
    writer_->set_attribute(p, "packing_fraction", m.packing_fraction);
    writer_->set_attribute(p, "restitution", m.restitution);
    writer_->set_attribute(p, "radius", std::vector<double>(m.radius, m.radius + 2));
    writer_->set_attribute(p, "mass", std::vector<double>(m.mass, m.mass + 2));
    writer_->set_attribute(p, "observables", join(m.observables, ","));
    writer_->set_attribute(p, "overlap_subbox_particles", m.overlap_subbox_particles);
    writer_->set_attribute(p, "keep_frames", int32_t{m.keep_frames});
    writer_->set_attribute(p, "chunk_particles", m.chunk_particles);
  });
  guarded("schedule", [&] {
    writer_->write_fixed("schedule/frame_time", m.frame_time);
    writer_->write_fixed("schedule/origin_frame", m.origin_frame);
    writer_->write_fixed("schedule/lag_time", m.lag_time);
    writer_->write_fixed("schedule/pair_frame", m.pair_frame, {dim(m.n_origins), dim(m.n_lags)});
    writer_->write_fixed("schedule/cutoff_a", m.cutoff_a);
    writer_->set_attribute("observables/schedule", "n_origins", m.n_origins);
    writer_->set_attribute("observables/schedule", "n_lags", m.n_lags);
  });
}

bool RunRecorder::on_sim_status(const sim_status_t &m) {
  if (!info_ || m.run_id != info_->run_id) return false;
  guarded("sim status", [&] { write_sim(m); });
  // The frames kept are counted at the end (finish), not at a "done": a
  // forged one must not close the recorder's frames while the sim goes on.
  // Its count is untrusted too: at most the run's frames (a forged
  // INT32_MAX would make every run incomplete), and never below a count
  // already seen (a forged smaller one after the sim's would excuse lost
  // frames); the safe direction is to expect more.
  if (ended(m.phase) && m.frames_published > 0)
    frames_published_ = std::max(frames_published_, std::min(m.frames_published, info_->n_frames));
  completion_.sim_phase(m.phase, m.message);
  sim_unauthenticated_ = m.messages_unauthenticated;
  std::copy(std::begin(m.bus_drops), std::end(m.bus_drops), sim_bus_drops_.begin());
  return true;
}

// Step f: the sim had published frames 0 .. f. The first status after a
// frame makes the record, the sim's last word (done, failed, interrupted)
// replaces it; sim_time is the status's own simulation time (>= time).
void RunRecorder::write_sim(const sim_status_t &m) {
  const auto at = at_frame(int64_t{m.frames_published} - 1, ended(m.phase) || m.phase == "interrupted");
  if (!at) return;
  const std::pair<const char *, double> doubles[] = {{"sim_time", m.sim_time},
                                                     {"kinetic_energy", m.kinetic_energy},
                                                     {"packing_fraction", m.packing_fraction},
                                                     {"collisions_per_second", m.collisions_per_second},
                                                     {"reduced_pressure", m.reduced_pressure},
                                                     {"reduced_pressure_err", m.reduced_pressure_err},
                                                     {"collision_frequency", m.collision_frequency},
                                                     {"collision_frequency_err", m.collision_frequency_err}};
  for (const auto &[name, v] : doubles) writer_->append_scalar("sim/" + std::string(name), *at, v);
  writer_->append_scalar("sim/n_collisions", *at, m.n_collisions);
  writer_->append_scalar("sim/n_kicks", *at, m.n_kicks);
  writer_->append_scalar("sim/n_tc", *at, m.n_tc);
  writer_->append_scalar("sim/frames_published", *at, m.frames_published);
}

// All chunks the sim sent before saying it ended have been handled by
// now, so frames still incomplete are lost.
void RunRecorder::count_frames() {
  if (!info_->keep_frames) return;
  const int expected = frames_published_ > 0 ? frames_published_ : info_->n_frames;
  assembler_.finish(expected);
  completion_.frames(assembler_.frames_lost(), expected);
}

bool RunRecorder::on_node_status(const node_status_t &m) {
  if (!info_ || m.run_id != info_->run_id) return false;
  Node &n = nodes_[node_key(m.node)];
  const bool progress = n.latest.utime == 0 || m.state != n.latest.state ||
                        m.frames_whole != n.latest.frames_whole || m.pairs_done != n.latest.pairs_done;
  n.latest = m;
  completion_.node_state(m.node, m.state);
  completion_.node_frames(m.node, m.frames_whole, m.frames_lost, m.frames_expected);
  guarded("node status", [&] { write_node(m); });
  return progress;
}

// Step f: the node had handled f + 1 frames (whole or lost), time the
// simulation time of frame f; its done or failed replaces the record of
// that step. wall_time: seconds since the first node status that made a
// record, any node's (node clocks are the host's; the run info's own stamp
// is old in a replay). Not since the first status heard: the statuses of
// nodes waiting for frames race the run info, so which of them a recorder
// takes depends on when it heard the run info, and a log played into a
// recorder would not give the live recorder's clock.
void RunRecorder::write_node(const node_status_t &m) {
  const auto at = at_frame(int64_t{m.frames_whole} + m.frames_lost - 1, ended(m.state));
  if (!at) return;
  if (!node_clock_zero_) node_clock_zero_ = m.utime;
  const std::string base = "nodes/" + node_key(m.node) + "/";
  writer_->append_scalar(base + "frames_whole", *at, m.frames_whole);
  writer_->append_scalar(base + "frames_lost", *at, m.frames_lost);
  writer_->append_scalar(base + "chunks_received", *at, m.chunks_received);
  writer_->append_scalar(base + "pairs_done", *at, m.pairs_done);
  writer_->append_scalar(base + "wall_time", *at, 1e-6 * static_cast<double>(m.utime - *node_clock_zero_));
}

bool RunRecorder::on_frame_chunk(const frame_chunk_t &m) {
  if (!info_ || !info_->keep_frames || m.run_id != info_->run_id) return false;
  if (int64_t(m.n_values) != 2 * int64_t(m.count) || static_cast<int64_t>(m.position.size()) != m.n_values)
    return false;
  const ChunkHeader h{m.frame_index, m.time,           m.n_particles, m.chunk_index,
                      m.chunk_count, m.first_particle, m.count};
  const int64_t bad = assembler_.chunks_malformed();
  std::optional<Frame> f = assembler_.add(h, m.position.data());
  if (assembler_.chunks_malformed() > bad) {
    message_rejected(kChanFrame, "a chunk that is not one of this run's, or non-finite positions");
    return false;
  }
  if (f) guarded("frame", [&] { writer_->append_frame(*at_frame(f->index, false), f->position); });
  return true;
}

std::vector<std::string> RunRecorder::finish(const std::string &reason) {
  std::vector<std::string> missing;
  if (!reason.empty()) missing.push_back(reason);
  if (!info_) return missing;
  if (stopped_) {
    missing.push_back(stop_reason_);
    try {
      writer_->close(); // the reserve leaves room for it
    } catch (const std::exception &e) {
      std::fprintf(stderr, "recorder: closing after the disk filled: %s\n", std::string(e.what()).substr(0, 300).c_str());
    }
    return missing;
  }
  count_frames();
  for (const std::string &m : completion_.missing()) missing.push_back(m);
  if (write_errors_ > 0) missing.push_back(std::to_string(write_errors_) + " failed writes");
  write_summary(missing);
  writer_->close();
  return missing;
}

void RunRecorder::write_summary(const std::vector<std::string> &missing) {
  guarded("summary", [&] {
    writer_->set_attribute("", "complete", int32_t{missing.empty()});
    writer_->set_attribute("", "missing", join(missing, "; "));
    writer_->set_attribute("", "run_id", info_->run_id);
    writer_->set_attribute("", "sim_phase", completion_.phase());
    if (info_->keep_frames) writer_->set_attribute("", "frames_lost_recorder", assembler_.frames_lost());
    writer_->set_attribute("", "messages_rejected_recorder", rejected_);
    writer_->set_attribute("", "last_rejection_recorder", last_rejection_);
    writer_->set_attribute("", "messages_unauthenticated_recorder", unauthenticated_);
    writer_->set_attribute("", "last_unauthenticated_recorder", last_unauthenticated_);
    writer_->set_attribute("", "messages_unauthenticated_sim", sim_unauthenticated_);
    write_bus_drops("", "_recorder", bus_drops_.data());
    write_bus_drops("", "_sim", sim_bus_drops_.data());
    for (const auto &[key, n] : nodes_) {
      const node_status_t &s = n.latest;
      const std::string g = "observables/nodes/" + key;
      writer_->set_attribute("", "frames_lost_" + key, s.frames_lost);
      writer_->set_attribute(g, "state", s.state);
      writer_->set_attribute(g, "message", s.message);
      writer_->set_attribute(g, "frames_expected", s.frames_expected);
      writer_->set_attribute(g, "frames_whole", s.frames_whole);
      writer_->set_attribute(g, "frames_lost", s.frames_lost);
      writer_->set_attribute(g, "chunks_received", s.chunks_received);
      writer_->set_attribute(g, "messages_rejected", s.messages_rejected);
      writer_->set_attribute(g, "chunks_rejected", s.chunks_rejected);
      writer_->set_attribute(g, "last_rejection", s.last_rejection);
      writer_->set_attribute(g, "messages_unauthenticated", s.messages_unauthenticated);
      write_bus_drops(g, "", s.bus_drops);
    }
  });
}

// bus_dropped_<reason><suffix>: every message a process dropped on its
// side of the bus, one attribute per reason (BusDrop).
void RunRecorder::write_bus_drops(const std::string &group, const std::string &suffix, const int64_t *drops) {
  for (int r = 0; r < kBusDropReasons; ++r)
    writer_->set_attribute(group, std::string("bus_dropped_") + bus_drop_name(static_cast<BusDrop>(r)) + suffix,
                           drops[r]);
}

} // namespace dynhet
