"""One run of a study: its scene from the run lengths, resumed where it stopped, its status recorded."""
import math
import os
import socket
import time

from .toml_io import read_toml, toml_dump, write_atomic
from .model import AXES
from .rundir import read_status, run_h5_result, write_status
from .children import RESUMABLE, STOPPING, newest_whole_cut, run_scene
from .progress import sim_progress
from .states import equilibrated_state, pid_alive, pilot, prepared_state
from .archiving import archive_run, restored_run

# The source of a run's tau_alpha estimate when it runs again after a too
# short attempt.
LONGER = "1.3 x the tau_alpha of the previous, too short attempt"


def effective_state(old):
    """A run's state as do_run goes by it: a Slurm submission writes "queued"
    over what the run was and keeps that in previous_state, so that a run
    that failed is started over and a run killed while running is resumed
    (and its lost CPU counted), as on the local executor."""
    s = old.get("state")
    return old.get("previous_state", s) if s == "queued" else s


def resume_from(d, state):
    """What do_run resumes run directory d in (effective) state `state` from:
    "cut" (run_scene.sh continues from its newest whole checkpoint cut), the
    path of its checkpoint_before_frames.h5 (the production from its start),
    or None (it starts over: another state, no checkpoint, or no scene.toml)."""
    if state not in ("running", "queued", "interrupted") or not os.path.exists(os.path.join(d, "scene.toml")):
        return None
    if newest_whole_cut(d) is not None:
        return "cut"
    ck = os.path.join(d, "checkpoint_before_frames.h5")
    return ck if os.path.exists(ck) else None


def carried_cpu(old, resume):
    """(CPU seconds, attempts whose CPU was lost) that a new attempt carries
    from its run's previous status: a resumed run's earlier attempts; an
    earlier attempt left "running" was killed before it could record its own
    (its process is gone: do_run returns before this for a live one). A run
    that starts over carries nothing."""
    if resume is None:
        return 0.0, 0
    return float(old.get("cpu_s", 0.0)), int(old.get("cpu_unrecorded", 0)) + int(effective_state(old) == "running")


def schedules_tried(old):
    """How many run lengths a run has been given, counting the attempt that
    starts now: the first attempt gives it one, and each start after a too
    short result a longer one; any other attempt (a resumption, a start over
    after an interruption before the first checkpoint, or after a failure)
    goes on with the length it had. max_attempts bounds these, not the
    starts: a run stopped and resumed many times has been given one length.
    A status from before this count (no "schedules") is taken as one."""
    before = int(old.get("schedules", 1 if old.get("attempts") else 0))
    return before + 1 if before == 0 or effective_state(old) == "too_short" else before


def running_status(old, resume, source):
    """The status an attempt writes at its start (over old, the previous one)."""
    carried, unrecorded = carried_cpu(old, resume)
    status = {"state": "running", "host": socket.gethostname(), "pid": os.getpid(),
              "started": time.strftime("%Y-%m-%dT%H:%M:%S"), "attempts": int(old.get("attempts", 0)) + 1,
              "schedules": schedules_tried(old), "tau_source": source or "scene", "cpu_s": carried}
    if unrecorded:
        status["cpu_unrecorded"] = unrecorded
    return status


def equilibration_tau(sd, p, tau_est, source):
    """(tau, its source) the equilibration counts in: None (tau_est's own
    unit) unless run_length.equilibration_unit differs from the unit, then
    its own pilot's, times the margin."""
    st = sd.study
    if tau_est is None or not st.split_units():
        return None, None
    unit = st.run_length["equilibration_unit"]
    m = st.run_length["pilot_margin"]
    return m * pilot(sd, p, unit), f"{unit} pilot x {m:g}"


def equilibrated(sd, sc, d, tau):
    """Whether the run's equilibration reached 0.9 x equilibration_tau of the
    tau_alpha it counts in, as the run itself measured it (tau: the run's
    tau_alpha of run_length.unit). With the equilibration in the other unit,
    the run's own measure of that where the run has it (cage_relative on and
    lags long enough); else its pilot's estimate stands."""
    st = sd.study
    rl = st.run_length
    if st.split_units():
        _, tau = run_h5_result(os.path.join(d, "run.h5"), st.first_cutoff(sc), st.tau_group(rl["equilibration_unit"]))
        if not math.isfinite(tau):
            return True
    return sc["run"]["equilibration_time"] >= 0.9 * rl["equilibration_tau"] * tau


def origins_too_close(sc, tau, spacing_tau):
    """Whether a run's origins, planned at least one tau_alpha apart
    (run_length.origin_spacing_tau >= 1), lie closer than the tau_alpha the
    run measured (tau, of run_length.unit): then its tau_alpha(t0) are
    correlated and its steadiness over the production cannot be checked
    (docs/analysis.md), so the run is too short for its plan."""
    spacing = float(sc.get("schedule", {}).get("origin_spacing", math.nan))
    return spacing_tau >= 1.0 and math.isfinite(tau) and math.isfinite(spacing) and spacing < tau


def do_run(sd, p, log=print):
    """Runs (or resumes) one run to the end; returns its final status."""
    st = sd.study
    d = sd.run_dir(p)
    os.makedirs(d, exist_ok=True)
    old = read_status(d)
    if old.get("state") == "complete":
        return old
    restored = restored_run(sd, p)  # a run the archive holds is complete, its directory gone or not
    if restored is not None:
        log(f"{st.run_name(p)}: complete in the archive {sd.archive.dir}; not run again")
        return restored
    rl = st.run_length
    resume = None
    tau_eq = None
    tau_est, source = old.get("tau_estimate"), old.get("tau_source")
    if old.get("state") == "running" and old.get("host") == socket.gethostname() and pid_alive(old.get("pid")):
        return dict(old, state="running", message=f"still running in process {old.get('pid')}")
    state = effective_state(old)
    if state in ("running", "queued", "interrupted"):
        resume = resume_from(d, state)
        if resume == "cut":
            # run_scene.sh on the same directory resumes from the cut itself.
            last = sim_progress(d)  # what the sim last reported (a cut is taken in either phase)
            said = f" (its sim last said: {last['phase']} t = {last['t']:.6g} of {last['end']:.6g})" if last else ""
            log(f"{st.run_name(p)}: was interrupted; resuming from checkpoint cut {newest_whole_cut(d)}{said}")
        elif resume is not None:
            log(f"{st.run_name(p)}: was interrupted; resuming from {resume}")
        elif state != "queued" or old.get("started"):
            log(f"{st.run_name(p)}: was interrupted before its first checkpoint; starting again")
    elif state in ("failed", "too_short", "unknown"):
        log(f"{st.run_name(p)}: {state} before ({old.get('message', '')}); running it again")
    if resume is None:
        if rl["tau_alpha"] == "scene":
            tau_est, source = None, "scene"
        elif state == "too_short" and old.get("tau_alpha"):
            tau_est, source = 1.3 * old["tau_alpha"], LONGER
        elif state in ("running", "queued", "interrupted") and str(old.get("tau_source")).startswith(LONGER):
            pass  # interrupted before its first checkpoint: the longer length it was given, again
        elif rl["tau_alpha"] == "interpolate" and len(sd.finished_taus(p)) >= 2:
            tau_est, source = sd.guess(p)
        else:
            # A short, small pilot scatters by some 10% from the run (seen in
            # studies/quick.toml): a margin spares most runs a second attempt.
            tau_est = rl["pilot_margin"] * pilot(sd, p)
            source = "pilot" if rl["pilot_margin"] == 1.0 else f"pilot x {rl['pilot_margin']:g}"
        tau_eq, eq_source = equilibration_tau(sd, p, tau_est, source)
        sc = st.scene(p, tau_est, tau_eq=tau_eq)
        # A lag at the best tau_alpha estimate (the pilot's, or the previous
        # attempt's, without the margin), for what the paper takes at
        # tau_alpha (clusters, S4). Measured in studies/seeds.toml it does not
        # bring them closer: the pilot scatters by as much as the lag spacing
        # (clusters and S4 at a median 6%, at most 15%, from the run's
        # tau_alpha either way); a better estimate would.
        if tau_est is not None:
            best = tau_est / (rl["pilot_margin"] if source.startswith("pilot") else
                              1.3 if source == LONGER else 1.0)
            sch = sc["schedule"]
            if sch["lag_min"] <= best <= sch["lag_max"]:
                sch["extra_lags"] = [round(best, 6)]
        prepared_state(sd, sc)
        equilibrated_state(sd, sc)
        write_atomic(os.path.join(d, "scene.toml"),
                     toml_dump(sc, f"# {st.name}: {st.run_name(p)}; tau_alpha estimate {tau_est} ({source})"))
    sc = read_toml(os.path.join(d, "scene.toml"))
    # A resumed run's CPU includes its earlier attempts' (what the result
    # cost: the study's CPU figures and --dry-run's measured scale use it),
    # recorded from the start: an attempt killed before it can write its own
    # (SIGKILL, a machine that goes down) leaves the status "running", and
    # must not take the earlier attempts' record with it; its own CPU is lost,
    # and counted as lost (cpu_unrecorded, which the study analysis states).
    status = running_status(old, resume, source)
    carried = status["cpu_s"]
    if tau_est is not None:
        status["tau_estimate"] = tau_est
    if resume is None and tau_eq is not None:
        status.update(tau_eq_estimate=tau_eq, tau_eq_source=eq_source)
    elif old.get("tau_eq_estimate"):
        status.update(tau_eq_estimate=old["tau_eq_estimate"], tau_eq_source=old.get("tau_eq_source", "?"))
    for a in AXES:
        status[a] = p[a]
    write_status(d, status)
    if os.environ.get("SLURM_RESTART_COUNT"):
        status["requeues"] = int(os.environ["SLURM_RESTART_COUNT"])
    scene_path = os.path.join(d, "scene.toml")
    cut0 = newest_whole_cut(d)
    # A run that failed (or was too short) starts over: resuming it from its
    # last cut would repeat what failed (a recorder part that lost frames
    # can never make the run complete).
    again = state in ("failed", "too_short", "unknown")
    rc, wall, cpu = run_scene(scene_path, d, os.path.join(d, "run_scene.log"), None if resume == "cut" else resume,
                              fresh=again and resume is None, plots=sd.study.run_plots)
    # A process of the run died (exit 75: resumable): again from the last
    # whole cut, a few times, before the run counts as failed; twice in a row
    # without a new whole cut is no transient (a resume that fails the same
    # way each time) and the run fails, with its log, rather than loop.
    stuck = 0
    for _ in range(3):
        if rc != RESUMABLE or STOPPING.is_set():
            break
        cut1 = newest_whole_cut(d)
        stuck = stuck + 1 if cut1 == cut0 else 0
        if stuck >= 2:
            break
        cut0 = cut1
        log(f"{st.run_name(p)}: interrupted (a process died); resuming from its last checkpoint cut")
        rc2, wall2, cpu2 = run_scene(scene_path, d, os.path.join(d, "run_scene.log"), plots=sd.study.run_plots)
        rc, wall, cpu = rc2, wall + wall2, cpu + cpu2
    if rc == RESUMABLE and not STOPPING.is_set() and newest_whole_cut(d) == cut0:
        rc = 1  # no progress: a failure, not an interruption
    complete, tau = run_h5_result(os.path.join(d, "run.h5"), st.first_cutoff(sc), st.tau_group()) if rc == 0 else (0, float("nan"))
    status.update({"exit": rc, "wall_s": wall, "cpu_s": carried + cpu, "cpu_s_attempt": cpu,
                   "finished": time.strftime("%Y-%m-%dT%H:%M:%S"), "tau_alpha": tau})
    status.pop("pid", None)
    # A run that finished before the stop reached it is complete: a signal
    # late in a Slurm task's time must not cost the run its result.
    if rc == RESUMABLE or (STOPPING.is_set() and rc != 0):
        status["state"] = "interrupted"
        status["message"] = ("the study was stopped; run it again to resume" if STOPPING.is_set() else
                             f"interrupted; run the study again to resume (log {d}/run_scene.log)")
        status["resumable"] = newest_whole_cut(d) is not None
        write_status(d, status)
        return status
    if rc != 0 or not complete:
        status["state"] = "failed"
        status["message"] = f"run_scene exit {rc}, complete {complete}; log {d}/run_scene.log"
    elif tau_est is not None and not (math.isfinite(tau) and equilibrated(sd, sc, d, tau)):
        status["state"] = "too_short"
        status["message"] = (f"tau_alpha {tau:.4g} against the estimate {tau_est:.4g}: the equilibration was "
                             f"under {0.9 * rl['equilibration_tau']:g} {rl['equilibration_unit']}")
    elif tau_est is not None and origins_too_close(sc, tau, rl["origin_spacing_tau"]):
        status["state"] = "too_short"
        status["message"] = (f"tau_alpha {tau:.4g} against the estimate {tau_est:.4g}: its origins, "
                             f"{float(sc['schedule']['origin_spacing']):.4g} apart, lie closer than its tau_alpha, "
                             f"so its steadiness over the production cannot be checked")
    else:
        status["state"] = "complete"
    write_status(d, status)
    if status["state"] == "complete":
        archive_run(sd, p, status, log)
    if status["state"] == "too_short" and status["schedules"] < rl["max_attempts"] and not STOPPING.is_set():
        log(f"{st.run_name(p)}: {status['message']}; again with 1.3 tau_alpha")
        return do_run(sd, p, log)
    return status
