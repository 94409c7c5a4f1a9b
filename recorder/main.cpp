// recorder: writes one run to an H5MD file. It locks on to the first run
// info it hears, records sim status, node status and the observables'
// results (and the frames, if the scene keeps them), and closes the file
// when the sim has ended and every observable the run names has its final
// result and its node has said done.
//
// When the scene keeps the frames (and they come from the bus), the
// recorder publishes its own status on DYNHET_NODE_STATUS_recorder,
// after every kept frame and every second, as the analysis nodes do: the
// sim paces its frames on it (flow control), so that a recorder slowed by
// its writes, or stopped, loses none. Its own status is not a node's: it
// ignores it when it reads the nodes' status.
//
// `recorder --list-nodes LOG` prints the analysis nodes the run in an
// lcm-logger log needs (for replays) and exits; with --analysis FILE, those
// of its re-analysis, or (exit 2) what the file may not change, by name.
//
// --analysis FILE (with --from-log): a re-analysis of the recorded run
// (dynhet/reanalysis.hpp): the run info, once checked, goes with the
// analysis tables and keys of FILE in place, and parameters/reanalysis says
// whose re-analysis the file is.
//
// Exit: 0 complete; 1 incomplete (sim failed, results missing after
// --timeout, no run info within --wait-run); 2 interrupted (SIGINT or
// SIGTERM; the file is closed cleanly; with --checkpoint-dir, after its part
// of the next checkpoint cut, or because the sim stopped resumably); 3
// could not start (bus, log, output file or the cut to resume).
//
// With --checkpoint-dir it journals every message it takes and saves its
// part of each checkpoint cut (recorder_cuts.hpp); --resume-cut N rebuilds
// run.h5 from the journal up to cut N and goes on.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>

#include "dynhet/bus.hpp"
#include "dynhet/bus_cli.hpp"
#include "dynhet/lcm_exit.hpp"
#include "dynhet/lcm_guard.hpp"
#include "dynhet/lcm_url.hpp"
#include "dynhet/message_checks.hpp"
#include "dynhet/run_info_scene.hpp"
#include "dynhet/scene.hpp"
#include "session.hpp"

namespace {

std::atomic<int> g_signal{0};
void on_signal(int sig) { g_signal = sig; }

// The nodes the run in `log_path` needs, named as the launch scripts
// start them ("overlap" -> overlap_node), on one line.
int list_nodes(const std::string &log_path, int64_t run_id, const std::string &analysis_path,
               const std::string &analysis_toml) {
  lcm::LogFile log(log_path, "r");
  if (!log.good()) {
    std::fprintf(stderr, "recorder: cannot read the log %s\n", log_path.c_str());
    return 3;
  }
  while (const lcm::LogEvent *e = log.readNextEvent()) {
    dynhet::run_info_t run;
    std::string why;
    // Only to name the nodes replay.sh starts: the tag is not checked here
    // (the replayed run's processes check every message).
    if (e->channel != dynhet::kChanRun ||
        !dynhet::guard::safe_decode(e->data, static_cast<int>(dynhet::lcm_bytes_of(e->data, e->datalen)), run, why) ||
        !dynhet::run_info_problem(run).empty() || (run_id && run.run_id != run_id))
      continue;
    if (!analysis_path.empty()) {
      try {
        dynhet::apply_reanalysis(run, analysis_toml, analysis_path);
      } catch (const std::exception &e) {
        std::fprintf(stderr, "recorder: %s\n", e.what());
        return 2;
      }
    }
    std::string line;
    for (const std::string &n : dynhet::nodes_for(run.observables)) line += (line.empty() ? "" : " ") + n;
    std::printf("%s\n", line.c_str());
    return 0;
  }
  std::fprintf(stderr, "recorder: no run info in %s\n", log_path.c_str());
  return 1;
}

} // namespace


int main(int argc, char **argv) {
  CLI::App app{"dynhet recorder: one run's results into an H5MD file"};
  dynhet::recorder::Options o;
  std::string list_log;
  app.add_option("--lcm-url", o.url, "LCM URL (default: $LCM_DEFAULT_URL, else the project's)");
  app.add_option("--out", o.out, "output file (.h5); required unless --list-nodes");
  app.add_option("--from-log", o.from_log,
                 "read run info, sim status and frames from this lcm-logger log; "
                 "results still come from the bus");
  app.add_option("--timeout", o.timeout,
                 "seconds to wait for results once the sim has ended (counted from the "
                 "last result or node progress), and for a silent sim")
      ->capture_default_str();
  app.add_option("--wait-run", o.wait_run, "seconds to wait for the run info")->capture_default_str();
  app.add_option("--run-id", o.run_id, "record only this run (default: the first one seen)");
  dynhet::add_bus_options(app, o.bus);
  app.add_option("--author", o.author,
                 "the file's h5md/author name (default: $DYNHET_AUTHOR, else $USER, else \"unknown\")");
  app.add_option("--author-email", o.author_email, "the file's h5md/author email (default: none)");
  app.add_option("--checkpoint-dir", o.checkpoint_dir,
                 "journal every message here and save the recorder's part of each checkpoint cut "
                 "(docs/checkpoints.md); SIGTERM/SIGINT then stop it after the next cut");
  app.add_option("--resume-cut", o.resume_cut, "rebuild the file from the journal up to this cut and go on");
  app.add_option("--cut-wait", o.cut_wait, "after SIGTERM/SIGINT, wait at most this long (s) for the next cut")
      ->capture_default_str();
  app.add_option("--test-message-delay", o.test_message_delay,
                 "tests: sleep this long (s) for each message taken from the bus, a recorder that falls behind");
  app.add_option("--list-nodes", list_log,
                 "print the analysis nodes the run in this lcm-logger log needs, and exit");
  app.add_option("--analysis", o.analysis,
                 "re-analysis: the recorded run's scene with the analysis tables and keys of this TOML in place "
                 "(cutoffs a, sub-box sizes, cage-relative, observables); the file says so in parameters/reanalysis");
  CLI11_PARSE(app, argc, argv);
  if (!o.analysis.empty()) {
    std::ifstream in(o.analysis);
    std::stringstream text;
    if (!in || !(text << in.rdbuf())) {
      std::fprintf(stderr, "recorder: cannot read %s\n", o.analysis.c_str());
      return 2;
    }
    o.analysis_toml = text.str();
  }
  if (!list_log.empty()) return list_nodes(list_log, o.run_id, o.analysis, o.analysis_toml);
  if (o.out.empty()) return app.exit(CLI::RequiredError("--out"));
  const std::optional<dynhet::Bus> bus = dynhet::bus_or_say("recorder", o.bus);
  if (!bus) return 2;

  const std::string url = dynhet::resolve_lcm_url(o.url);
  lcm::LCM lcm(url);
  if (dynhet::bus_unreachable(lcm, url)) {
    std::fprintf(stderr, "recorder: cannot open LCM at %s\n", url.c_str());
    return 3;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  dynhet::recorder::Session session(lcm, *bus, o, g_signal);
  const int code = session.run();
  // Its last status (the sim may pace on it) reaches the bus before it ends
  // (tcpq: dynhet/lcm_exit.hpp).
  if (const std::string why = dynhet::deliver_before_exit(lcm, url); !why.empty())
    std::fprintf(stderr, "recorder: %s\n", why.c_str());
  return code;
}
