// overlap_node: the overlap Q(t), its error bars and tau_alpha, computed
// live from the frames on DYNHET_FRAME and published on DYNHET_OVERLAP (one
// message per cutoff a) after every frame that adds a pair; if the run asks
// for chi4, also chi4(t) for every listed sub-box size on DYNHET_CHI4, from
// the same displacements. It holds only the origin frames that some later
// frame still needs (16 N bytes each, plus 4 N per origin for chi4's
// sub-box index).
//
// Usage: overlap_node [--lcm-url URL] [--publish-url URL]
// With --lcm-url file://LOG?speed=0 it re-runs the analysis from an
// lcm-logger log at full speed and publishes on --publish-url.
#include <algorithm>
#include <chrono>
#include <limits>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>

#include "dynhet/analysis/chi4.hpp"
#include "dynhet/analysis/displacement.hpp"
#include "dynhet/analysis/fits.hpp"
#include "dynhet/analysis/timescales.hpp"
#include "dynhet/analysis/overlap.hpp"
#include "dynhet/chi4_t.hpp"
#include "dynhet/msd_t.hpp"
#include "dynhet/chunking.hpp"
#include "dynhet/frame_chunk_t.hpp"
#include "dynhet/lcm_url.hpp"
#include "dynhet/node_status_t.hpp"
#include "dynhet/overlap_t.hpp"
#include "dynhet/run_info_t.hpp"
#include "dynhet/sim_status_t.hpp"
#include "dynhet/stats.hpp"

namespace {

using dynhet::utime_now;

using Clock = std::chrono::steady_clock;

namespace an = dynhet::analysis;

class OverlapNode {
public:
  OverlapNode(lcm::LCM& out, int64_t run_filter) : out_(out), run_filter_(run_filter) {
    status_.node = "overlap";
    status_.state = "waiting";
  }

  bool finished() const { return finished_; }
  bool has_run() const { return info_ != nullptr; }
  // The sim publishes its status every second; silence longer than
  // `timeout` (not after a checkpointed interruption) means it died.
  void check_sim_alive(double timeout) {
    if (!info_ || finished_ || sim_interrupted_) return;
    const double silent = std::chrono::duration<double>(Clock::now() - last_sim_news_).count();
    if (silent > timeout) finish(1, "the sim has been silent for " + std::to_string(static_cast<int>(silent)) + " s");
  }
  int exit_code() const { return exit_code_; }

  void on_run(const lcm::ReceiveBuffer*, const std::string&, const dynhet::run_info_t* m) {
    if (info_ || (run_filter_ && m->run_id != run_filter_)) return;
    info_ = std::make_unique<dynhet::run_info_t>(*m);
    last_sim_news_ = Clock::now();
    status_.run_id = m->run_id;
    status_.frames_expected = m->n_frames;
    status_.state = "running";
    grid_ = an::make_subbox_grid(m->n_particles, m->box_length, m->overlap_subbox_particles);
    for (int c = 0; c < m->n_cutoffs; ++c) acc_.emplace_back(m->n_origins, m->lag_time);
    auto wants = [&](const char* o) { return std::find(m->observables.begin(), m->observables.end(), o) != m->observables.end(); };
    want_chi4_ = wants("chi4");
    want_msd_ = wants("msd");
    if (want_chi4_ || want_msd_) start_pass(*m);
    // Which origins and which (origin, lag) pairs each frame serves.
    origin_at_.assign(m->n_frames, -1);
    pairs_at_.assign(m->n_frames, {});
    last_use_.assign(m->n_origins, -1);
    for (int k = 0; k < m->n_origins; ++k) {
      origin_at_[m->origin_frame[k]] = k;
      for (int j = 0; j < m->n_lags; ++j) {
        const int f = m->pair_frame[static_cast<size_t>(k) * m->n_lags + j];
        if (f < 0) continue;
        pairs_at_[f].push_back({k, j});
        last_use_[k] = std::max(last_use_[k], f);
      }
    }
    std::fprintf(stderr, "overlap_node: run %lld, N=%d, %d frames, %d origins x %d lags, %dx%d sub-boxes of N=%.1f\n",
                 static_cast<long long>(m->run_id), m->n_particles, m->n_frames, m->n_origins,
                 m->n_lags, grid_.per_side, grid_.per_side, grid_.mean_particles);
  }

  void on_chunk(const lcm::ReceiveBuffer*, const std::string&, const dynhet::frame_chunk_t* m) {
    if (!info_ || m->run_id != info_->run_id || m->n_values != 2 * m->count) return;
    last_sim_news_ = Clock::now();
    const dynhet::ChunkHeader h{m->frame_index, m->time,           m->n_particles, m->chunk_index,
                                m->chunk_count, m->first_particle, m->count};
    auto frame = assembler_.add(h, m->position.data());
    if (frame && frame->index < info_->n_frames) on_frame(*frame);
  }

  void on_sim_status(const lcm::ReceiveBuffer*, const std::string&, const dynhet::sim_status_t* m) {
    if (!info_ || m->run_id != info_->run_id || finished_) return;
    last_sim_news_ = Clock::now();
    sim_interrupted_ = m->phase == "interrupted"; // checkpointed: wait for --resume
    if (m->phase == "done") finish(0, "");
    if (m->phase == "failed") finish(1, "sim failed: " + m->message);
  }

  // The input ended (log replayed to its end) before the sim said done.
  void input_ended() {
    if (!finished_) finish(1, info_ ? "input ended before the run did" : "no run info in the input");
  }

  void publish_status() {
    status_.utime = utime_now();
    status_.frames_whole = assembler_.frames_whole();
    status_.frames_lost = assembler_.frames_lost();
    status_.chunks_received = assembler_.chunks_received();
    status_.pairs_done = pairs_done_;
    status_.origins_held = static_cast<int32_t>(origins_.size());
    out_.publish(dynhet::kChanNodeStatus, &status_);
    last_status_ = Clock::now();
  }
  void tick() {
    if (std::chrono::duration<double>(Clock::now() - last_status_).count() >= 1.0) publish_status();
  }

private:
  void on_frame(const dynhet::Frame& f) {
    const int k0 = origin_at_[f.index];
    if (k0 >= 0) origins_[k0] = f.position;
    if (k0 >= 0 && pass_on_) chi4_index_[k0] = std::make_unique<an::OriginIndex>(f.position.data(), info_->n_particles, spec_);
    bool added = false;
    for (const auto& [k, j] : pairs_at_[f.index]) {
      auto it = origins_.find(k);
      if (it == origins_.end()) continue; // the origin frame was lost
      an::overlap_subboxes(it->second.data(), f.position.data(), info_->n_particles, grid_,
                           info_->cutoff_a, qr_);
      const int nb = grid_.per_side * grid_.per_side;
      for (size_t c = 0; c < acc_.size(); ++c) acc_[c].add(k, j, qr_.data() + c * nb, nb);
      if (pass_on_) add_pass(k, j, it->second, f);
      ++pairs_done_;
      added = true;
    }
    // Drop origins no later frame needs.
    for (auto it = origins_.begin(); it != origins_.end();)
      if (last_use_[it->first] <= f.index) {
        chi4_index_.erase(it->first);
        it = origins_.erase(it);
      } else {
        ++it;
      }
    last_frame_ = f.index;
    last_time_ = f.time;
    if (added) publish_results(false);
    tick();
  }

  // The fields every result message shares: when, which run, which frame.
  template <class Msg> void stamp(Msg& m, bool final) const {
    m.utime = utime_now();
    m.run_id = info_->run_id;
    m.sim_time = last_time_;
    m.frame_index = last_frame_;
    m.is_final = final;
  }

  // Q(t) = 1/((t/tau0)^beta + 1), weighted by the errors if every lag has one.
  void fit_q(const an::OverlapAccumulator::Result& r, dynhet::overlap_t& m) const {
    m.beta = m.beta_err = m.tau0 = m.tau0_err = std::numeric_limits<double>::quiet_NaN();
    std::vector<double> t, q, e;
    bool weighted = true;
    for (size_t j = 0; j < r.q.size(); ++j) {
      if (std::isnan(r.q[j])) continue;
      t.push_back(info_->lag_time[j]);
      q.push_back(r.q[j]);
      e.push_back(r.q_err[j]);
      weighted = weighted && std::isfinite(r.q_err[j]) && r.q_err[j] > 0;
    }
    if (t.size() < 4) return;
    try {
      const auto f = an::fit_overlap(t, q, weighted ? e : std::vector<double>{});
      m.beta = f.beta, m.beta_err = f.beta_err, m.tau0 = f.tau0, m.tau0_err = f.tau0_err;
    } catch (const std::exception&) {
      // not converged yet: NaN
    }
  }

  // chi4 for every listed sub-box size (nested grids: one pass, see
  // displacement.hpp) and every cutoff.
  void start_pass(const dynhet::run_info_t& m) {
    pass_on_ = true;
    const size_t pairs = static_cast<size_t>(m.n_origins) * m.lag_time.size();
    msd_all_.assign(pairs, std::numeric_limits<double>::quiet_NaN());
    msd_small_ = msd_all_;
    spec_.grids = an::nested_subbox_grids(m.n_particles, m.box_length, m.chi4_subbox_particles);
    spec_.cutoffs = m.cutoff_a;
    std::sort(spec_.cutoffs.begin(), spec_.cutoffs.end()); // the pass wants them ascending
    species_.assign(m.species.begin(), m.species.end());
    for (const auto& g : spec_.grids)
      for (size_t c = 0; c < spec_.cutoffs.size(); ++c) chi4_acc_.emplace_back(m.n_origins, m.lag_time, g);
  }
  void add_pass(int k, int j, const std::vector<double>& pos0, const dynhet::Frame& f) {
    an::displacement_pass(pos0.data(), f.position.data(), species_.data(), info_->n_particles,
                          *chi4_index_.at(k), spec_, pass_);
    for (size_t i = 0; i < chi4_acc_.size(); ++i) chi4_acc_[i].add(k, j, pass_.q_r_sum[i], pass_.q_r_sum2[i]);
    msd_all_[static_cast<size_t>(k) * info_->lag_time.size() + j] = pass_.msd_all;
    msd_small_[static_cast<size_t>(k) * info_->lag_time.size() + j] = pass_.msd_small;
  }
  // Mean over the origins measured at each lag, and its standard error.
  void origin_mean(const std::vector<double>& v, std::vector<double>& mean, std::vector<double>& err) const {
    const size_t nj = info_->lag_time.size();
    mean.assign(nj, std::numeric_limits<double>::quiet_NaN());
    err = mean;
    for (size_t j = 0; j < nj; ++j) {
      dynhet::BlockAverage b;
      for (int k = 0; k < info_->n_origins; ++k)
        if (const double x = v[k * nj + j]; !std::isnan(x)) b.add(x);
      if (b.count()) mean[j] = b.mean(), err[j] = b.standard_error();
    }
  }
  void publish_msd(bool final) {
    dynhet::msd_t m{};
    stamp(m, final);
    m.lag_time = info_->lag_time;
    m.n_lags = static_cast<int32_t>(m.lag_time.size());
    origin_mean(msd_all_, m.msd_all, m.msd_all_err);
    origin_mean(msd_small_, m.msd_small, m.msd_small_err);
    // D from Delta = 4 D t + b where the MSD has become diffusive (local
    // log slope within 0.05 of 1 up to the end) or over the last decade of
    // lags, whichever range is longer.
    m.fit_t_max = m.lag_time.back();
    m.fit_t_min = m.fit_t_max / 10;
    if (const double onset = an::diffusive_onset(m.lag_time, m.msd_all); onset < m.fit_t_min) m.fit_t_min = onset;
    m.diffusion = m.diffusion_err = std::numeric_limits<double>::quiet_NaN();
    if (std::isfinite(m.fit_t_min) && m.fit_t_min < m.fit_t_max) {
      const auto d = an::fit_diffusion(m.lag_time, m.msd_all, m.fit_t_min, m.fit_t_max);
      if (d.n >= 3) m.diffusion = d.d, m.diffusion_err = d.d_err;
    }
    out_.publish(dynhet::kChanMsd, &m);
  }
  void publish_chi4(bool final) {
    const size_t nc = spec_.cutoffs.size(), ng = spec_.grids.size(), nj = info_->lag_time.size();
    for (size_t c = 0; c < nc; ++c) {
      dynhet::chi4_t m{};
      stamp(m, final);
      m.cutoff_a = spec_.cutoffs[c];
      m.n_grids = static_cast<int32_t>(ng);
      m.n_lags = static_cast<int32_t>(nj);
      m.lag_time = info_->lag_time;
      for (size_t g = 0; g < ng; ++g) {
        const auto r = chi4_acc_[g * nc + c].result();
        // The whole box has one sub-box: its chi4 is N var(Q) over origins.
        const bool whole = spec_.grids[g].per_side == 1;
        m.subbox_particles.push_back(spec_.grids[g].mean_particles);
        m.subbox_per_side.push_back(spec_.grids[g].per_side);
        const auto& v = whole ? r.chi4_pooled : r.chi4;
        m.chi4.insert(m.chi4.end(), v.begin(), v.end());
        if (whole)
          m.chi4_err.insert(m.chi4_err.end(), nj, std::numeric_limits<double>::quiet_NaN());
        else
          m.chi4_err.insert(m.chi4_err.end(), r.chi4_err.begin(), r.chi4_err.end());
        m.chi4_peak.push_back(r.chi4_peak);
        m.tau4.push_back(r.tau4);
      }
      m.n_values = static_cast<int32_t>(m.chi4.size());
      out_.publish(dynhet::kChanChi4, &m);
    }
  }

  void publish_results(bool final) {
    if (want_chi4_) publish_chi4(final);
    if (want_msd_) publish_msd(final);
    for (size_t c = 0; c < acc_.size(); ++c) {
      const auto r = acc_[c].result();
      dynhet::overlap_t m{};
      stamp(m, final);
      m.cutoff_a = info_->cutoff_a[c];
      m.subbox_per_side = grid_.per_side;
      m.subbox_particles = grid_.mean_particles;
      m.n_lags = info_->n_lags;
      m.lag_time = info_->lag_time;
      m.q = r.q;
      m.q_err = r.q_err;
      m.n_origins = r.n_origins;
      m.qr_var = r.qr_var;
      m.tau_alpha = r.tau_alpha;
      m.tau_alpha_err = r.tau_alpha_err;
      fit_q(r, m);
      for (int k = 0; k < info_->n_origins; ++k) m.t0.push_back(info_->frame_time[info_->origin_frame[k]]);
      m.tau_alpha_t0 = an::tau_alpha_per_origin(acc_[c], info_->lag_time, info_->n_origins);
      m.n_t0 = static_cast<int32_t>(m.t0.size());
      out_.publish(dynhet::kChanOverlap, &m);
      if (final)
        std::fprintf(stderr, "overlap_node: a=%g tau_alpha=%.5g +- %.2g (%d pairs)\n", m.cutoff_a,
                     m.tau_alpha, m.tau_alpha_err, pairs_done_);
    }
  }

  void finish(int code, const std::string& why) {
    if (info_) assembler_.finish(info_->n_frames);
    if (info_) publish_results(true);
    status_.state = code == 0 ? "done" : "failed";
    status_.message = why;
    publish_status();
    std::fprintf(stderr, "overlap_node: %s: %d frames whole, %d lost%s%s\n", status_.state.c_str(),
                 assembler_.frames_whole(), assembler_.frames_lost(), why.empty() ? "" : "; ",
                 why.c_str());
    finished_ = true;
    exit_code_ = code;
  }

  lcm::LCM& out_;
  int64_t run_filter_;
  std::unique_ptr<dynhet::run_info_t> info_;
  an::SubboxGrid grid_{};
  std::vector<an::OverlapAccumulator> acc_; // one per cutoff
  std::vector<int> origin_at_, last_use_;
  std::vector<std::vector<std::pair<int, int>>> pairs_at_;
  std::map<int, std::vector<double>> origins_; // origin k -> positions at t0
  std::vector<double> qr_;
  // The displacement pass, for chi4 and the MSD (only if the run asks)
  bool pass_on_ = false, want_chi4_ = false, want_msd_ = false;
  std::vector<double> msd_all_, msd_small_; // per (origin, lag)
  an::DisplacementSpec spec_;
  std::vector<uint8_t> species_;
  std::vector<an::Chi4Accumulator> chi4_acc_; // [grid * n_cutoffs + cutoff], cutoffs ascending
  std::map<int, std::unique_ptr<an::OriginIndex>> chi4_index_;
  an::DisplacementResult pass_;
  dynhet::FrameAssembler assembler_;
  dynhet::node_status_t status_{};
  Clock::time_point last_status_ = Clock::now();
  Clock::time_point last_sim_news_ = Clock::now();
  bool sim_interrupted_ = false;
  int pairs_done_ = 0, last_frame_ = -1;
  double last_time_ = 0;
  bool finished_ = false;
  int exit_code_ = 0;
};

} // namespace

int main(int argc, char** argv) {
  CLI::App app{"dynhet overlap_node: Q(t), tau_alpha from frames on LCM"};
  std::string url, publish_url;
  int64_t run_id = 0;
  double wait_run = 300;
  app.add_option("--lcm-url", url, "LCM URL to read from (file://LOG?speed=0 replays a log)");
  app.add_option("--publish-url", publish_url, "LCM URL to publish on (default: the input bus)");
  app.add_option("--run-id", run_id, "only this run (default: the first one seen)");
  app.add_option("--wait-run", wait_run, "give up after this many seconds without run info");
  double sim_timeout = 60;
  app.add_option("--sim-timeout", sim_timeout, "give up if the sim is silent this long (s) during a run");
  CLI11_PARSE(app, argc, argv);

  const std::string in_url = dynhet::resolve_lcm_url(url);
  const bool replay = in_url.rfind("file://", 0) == 0;
  lcm::LCM in(in_url);
  std::unique_ptr<lcm::LCM> out_owned;
  if (!publish_url.empty() || replay) out_owned = std::make_unique<lcm::LCM>(dynhet::resolve_lcm_url(publish_url));
  lcm::LCM& out = out_owned ? *out_owned : in;
  if (!in.good() || !out.good()) {
    std::fprintf(stderr, "overlap_node: cannot open LCM (%s)\n", in_url.c_str());
    return 3;
  }

  OverlapNode node(out, run_id);
  in.subscribe(dynhet::kChanRun, &OverlapNode::on_run, &node);
  in.subscribe(dynhet::kChanFrame, &OverlapNode::on_chunk, &node)->setQueueCapacity(100000);
  in.subscribe(dynhet::kChanSimStatus, &OverlapNode::on_sim_status, &node);

  std::fprintf(stderr, "overlap_node: ready, reading %s\n", in_url.c_str());
  const auto start = Clock::now();
  while (!node.finished()) {
    if (in.handleTimeout(200) < 0) { // a replayed log has ended
      node.input_ended();
      break;
    }
    node.tick();
    if (!replay) node.check_sim_alive(sim_timeout);
    if (!node.has_run() && std::chrono::duration<double>(Clock::now() - start).count() > wait_run) {
      std::fprintf(stderr, "overlap_node: no run info on %s within %g s\n", in_url.c_str(), wait_run);
      return 4;
    }
  }
  return node.exit_code();
}
