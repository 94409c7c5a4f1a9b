"""The local executor: a pool of runs on this machine, with progress; the analysis when all are done."""
import os
import signal
import subprocess
import sys
import threading
import time

from .paths import ROOT
from .model import AXES, StudyError, StudyInterrupted
from .estimates import fmt_time
from .rundir import read_status, write_status
from .children import RESUMABLE, STOPPING, already_stopping, stop_children
from .runner import do_run
from .archiving import restore_archived
from .index import estimates_whole_and_left, run_order, write_index
from .progress import PROGRESS_EVERY, describe, eta_seconds, sim_progress, study_eta


def run_local(sd, jobs, order="longest", first=(), figures=True):
    points = [p for p in sd.study.points()]
    restore_archived(sd, points)
    todo = [p for p in points if read_status(sd.run_dir(p)).get("state") != "complete"]
    done0 = len(points) - len(todo)
    if done0:
        print(f"study {sd.study.name}: {done0} of {len(points)} runs complete already (skipped)", flush=True)
    # est: whole runs, what the measured CPU of finished ones compares with;
    # left: what each has still to run, for the order and the queue's ETA
    est, left = estimates_whole_and_left(sd)
    todo = run_order(sd, todo, left, order, first)
    lock = threading.Lock()
    state = {"done": done0, "failed": 0, "running": 0, "left": len(todo), "cpu_done": 0.0, "est_done": 0.0,
             "active": {}}
    queue = list(todo)
    failures = []
    t_start = time.time()

    def say(msg):
        with lock:
            print(msg, flush=True)

    def progress():
        with lock:
            ratio = state["cpu_done"] / state["est_done"] if state["est_done"] > 0 else 1.0
            queued = [ratio * left[sd.study.run_name(p)] for p in queue]
            active = list(state["active"].values())
        # The running runs' own ETAs (their sims'), then the queue on the slots they free.
        running = []
        for d, since in active:
            pr = sim_progress(d, since)
            running.append((eta_seconds(pr["eta"]) if pr else None) or 0.0)
        eta = study_eta(running, queued, max(1, jobs))
        with lock:
            print(f"[{fmt_time(time.time() - t_start)}] study {sd.study.name}: {state['done']} done, "
                  f"{state['running']} running, {state['left']} left, {state['failed']} failed; "
                  f"ETA {fmt_time(eta)} (the running runs' sims, then the queue's estimates on {max(1, jobs)} "
                  f"slots)", flush=True)

    def worker():
        while True:
            with lock:
                if not queue or STOPPING.is_set():
                    return
                p = queue.pop(0)
                state["left"] -= 1
                state["running"] += 1
            name = sd.study.run_name(p)
            with lock:
                state["active"][name] = (sd.run_dir(p), time.time())
            try:
                st = do_run(sd, p, say)
            except StudyError as e:
                st = {"state": "failed", "message": str(e)}
                write_status(sd.run_dir(p), dict(st, **{a: p[a] for a in AXES}))
            except StudyInterrupted as e:
                st = {"state": "interrupted", "message": str(e)}
                write_status(sd.run_dir(p), dict(st, **{a: p[a] for a in AXES}))
            except OSError as e:
                # A program that cannot be started (a build replacing it
                # meanwhile, a full disk): this run failed, the study goes on
                # (the same command again reruns it).
                st = {"state": "failed", "message": f"{type(e).__name__}: {e}"}
                write_status(sd.run_dir(p), dict(st, **{a: p[a] for a in AXES}))
            with lock:
                state["active"].pop(name, None)
                state["running"] -= 1
                if st.get("state") == "complete":
                    state["done"] += 1
                    state["cpu_done"] += st.get("cpu_s", 0.0)
                    state["est_done"] += est.get(name, 0.0)
                elif st.get("state") == "interrupted":
                    state["left"] += 1
                    continue
                else:
                    state["failed"] += 1
                    failures.append((name, st.get("message", "")))
            say(f"{name}: {st.get('state')}" + (f", tau_alpha {st['tau_alpha']:.4g}" if st.get("tau_alpha") else "")
                + (f" ({st.get('message')})" if st.get("state") != "complete" else ""))
            with lock:  # one writer at a time: the index written last is the newest
                write_index(sd)
            progress()

    progress()
    threads = [threading.Thread(target=worker, daemon=True) for _ in range(max(1, jobs))]
    for t in threads:
        t.start()
    try:
        last = time.time()
        while any(t.is_alive() for t in threads):
            time.sleep(0.5)
            if time.time() - last >= PROGRESS_EVERY:  # runs of hours: say where each stands
                last = time.time()
                progress()
                with lock:
                    active = sorted(state["active"].items())
                for name, (d, since) in active:
                    say(describe(name, d, since))
    except KeyboardInterrupt:
        for sig in (signal.SIGINT, signal.SIGTERM):  # a second signal must not cut the stop short
            signal.signal(sig, already_stopping)
        say(f"study {sd.study.name}: stopping the runs (each writes a checkpoint)")
        stop_children()
        for t in threads:
            t.join(timeout=30)
        write_index(sd)
        say(f"study {sd.study.name}: interrupted; run the same command again to resume")
        return RESUMABLE
    write_index(sd)
    print(f"study {sd.study.name}: {state['done']} of {len(points)} runs complete, {state['failed']} failed "
          f"in {fmt_time(time.time() - t_start)} -> {sd.dir}/index.toml", flush=True)
    for name, msg in failures:
        print(f"  failed: {name}: {msg}", flush=True)
    if state["failed"]:
        return 1
    return analyse(sd, figures)


def analyse(sd, figures=True):
    """The study analysis (analyse_study.py) once every run is complete:
    study.h5, figures/ and reproduction.md in the study directory (without
    figures, run_study.sh --no-figures: the text and study.h5 alone)."""
    script = os.path.join(ROOT, "launch_scripts", "analyse_study.py")
    args = [sd.dir] + ([] if figures else ["--no-figures"])
    print(f"study {sd.study.name}: analysing ({os.path.relpath(script, ROOT)} {' '.join(args)})", flush=True)
    rc = subprocess.run([sys.executable, script, *args]).returncode
    if rc:
        print(f"study {sd.study.name}: the analysis failed (exit {rc}); the runs are complete, "
              f"run launch_scripts/analyse_study.sh {' '.join(args)} again after a fix", flush=True)
    return 1 if rc else 0
