"""The Slurm executor: one job array (a task per run) that checkpoints and requeues itself, and a dependent index job."""
import os
import signal
import subprocess
import time

from .paths import BUILD, STUDY_PY
from .toml_io import write_atomic
from .model import AXES, StudyError
from .rundir import read_status, write_status
from .children import RESUMABLE, signal_children
from .runner import do_run
from .archiving import restore_archived
from .index import run_estimates_left, run_order, write_index


def run_slurm(sd, a):
    points = sd.study.points()
    restored = restore_archived(sd, points)
    todo = []
    for p in points:
        st = read_status(sd.run_dir(p))
        if st.get("state") == "complete":
            continue
        if st.get("state") == "queued" and st.get("job"):
            q = subprocess.run(["squeue", "-h", "-j", str(st["job"]), "-o", "%T"], capture_output=True, text=True)
            if q.returncode == 0 and q.stdout.strip():
                print(f"{sd.study.run_name(p)}: still in Slurm job {st['job']} ({q.stdout.split()[0]})")
                continue
        todo.append(p)
    todo = run_order(sd, todo, run_estimates_left(sd), a.order, a.first)
    sdir = os.path.join(sd.dir, "slurm")
    stamp = time.strftime("%Y%m%d-%H%M%S")
    me = STUDY_PY
    common = []
    for flag, val in (("--partition", a.partition), ("--time", a.time), ("--mem", a.mem)):
        if val:
            common.append(f"#SBATCH {flag}={val}")
    common += [f"#SBATCH {x}" for x in a.sbatch]
    after = os.path.join(sdir, f"index-{stamp}.sbatch")

    def index_job(dependency):
        """The job that writes the index and analyses the study (after the array, or alone)."""
        os.makedirs(sdir, exist_ok=True)
        write_atomic(after, "\n".join([
            "#!/bin/bash", f"#SBATCH --job-name=dynhet-{sd.study.name}-index",
            f"#SBATCH --output={sdir}/index-%j.out", *common,
            "# After every task: the study's index (and what must follow the runs).",
            f"exec /usr/bin/python3 {me} index {sd.dir} --analyse" + (" --no-figures" if a.no_figures else ""), ""]))
        r2 = subprocess.run(["sbatch", "--parsable", *dependency, after], capture_output=True, text=True)
        if r2.returncode != 0:
            raise StudyError(f"sbatch refused the index job: {r2.stderr.strip()}")
        return r2.stdout.strip().split(";")[0]

    if not todo:
        write_index(sd)
        if restored and all(read_status(sd.run_dir(p)).get("state") == "complete" for p in points):
            # every run restored from the archive (a new machine): nothing to run, the analysis still to do
            dep = index_job([])
            print(f"study {sd.study.name}: every run complete in the archive; index job {dep} analyses the study")
            return 0
        print(f"study {sd.study.name}: nothing to submit ({len(points)} runs complete or queued)")
        return 0
    os.makedirs(sdir, exist_ok=True)
    listing = os.path.join(sdir, f"batch-{stamp}.txt")
    write_atomic(listing, "".join(sd.study.run_name(p) + "\n" for p in todo))
    array = os.path.join(sdir, f"array-{stamp}.sbatch")
    write_atomic(array, "\n".join([
        "#!/bin/bash",
        f"#SBATCH --job-name=dynhet-{sd.study.name}",
        f"#SBATCH --array=0-{len(todo) - 1}" + (f"%{a.jobs}" if a.jobs else ""),
        f"#SBATCH --output={sdir}/task-%A_%a.out",
        "#SBATCH --open-mode=append",
        "#SBATCH --cpus-per-task=2",
        # Before the time limit Slurm sends SIGTERM to this shell: the run
        # takes a last checkpoint cut and stops (exit 75), and the task goes
        # back in the queue, to resume from the cut.
        f"#SBATCH --signal=B:TERM@{int(a.signal_lead)}",
        "#SBATCH --requeue",
        *common,
        "# One run of the study per array task (launch_scripts/study.py task).",
        f"name=$(sed -n \"$((SLURM_ARRAY_TASK_ID + 1))p\" {listing})",
        f"export BUILD_DIR={BUILD}",
        f"echo \"$(date '+%F %T') task $name: start (requeued ${{SLURM_RESTART_COUNT:-0}} times)\"",
        f"/usr/bin/python3 {me} task {sd.dir} \"$name\" &",
        "child=$!",
        "trap 'kill -TERM $child 2>/dev/null' TERM",
        "wait $child; rc=$?",
        "while kill -0 $child 2>/dev/null; do wait $child; rc=$?; done",
        f"if [ $rc -eq {RESUMABLE} ]; then",
        "  id=${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID}",
        f"  if [ ${{SLURM_RESTART_COUNT:-0}} -lt {int(a.max_requeues)} ]; then",
        "    echo \"$(date '+%F %T') task $name: interrupted and resumable: requeued\"",
        "    scontrol requeue \"$id\"",
        "  else",
        f"    echo \"$(date '+%F %T') task $name: interrupted, but requeued {int(a.max_requeues)} times already: "
        "run the study again to resume\"",
        "  fi",
        "fi",
        "exit $rc", ""]))
    # Held until every run's status says queued: a task that started at once
    # would have its "running" overwritten by this loop's "queued".
    r = subprocess.run(["sbatch", "--parsable", "--hold", array], capture_output=True, text=True)
    if r.returncode != 0:
        raise StudyError(f"sbatch refused the job array: {r.stderr.strip()}")
    job = r.stdout.strip().split(";")[0]
    before = {}   # each run's status as it was: put back if the array cannot be released
    try:
        for p in todo:
            d = sd.run_dir(p)
            os.makedirs(d, exist_ok=True)
            st = read_status(d)
            before[d] = dict(st)
            if st.get("state") not in (None, "queued"):
                st["previous_state"] = st["state"]   # what the run was: do_run goes by it (runner.effective_state)
            st.update({"state": "queued", "job": job})
            for k in AXES:
                st[k] = p[k]
            write_status(d, st)
        rel = subprocess.run(["scontrol", "release", job], capture_output=True, text=True)
        if rel.returncode != 0:
            raise StudyError(f"scontrol could not release job array {job}: {rel.stderr.strip()}")
    except BaseException as e:   # a held array left behind would keep its runs "queued" for ever
        c = subprocess.run(["scancel", job], capture_output=True, text=True)
        for d, st in before.items():
            path = os.path.join(d, "status.toml")
            if st:
                write_status(d, st)
            elif os.path.exists(path):
                os.remove(path)
        if isinstance(e, StudyError):
            raise StudyError(f"{e}; the array " + ("cancelled" if c.returncode == 0 else
                             f"could not be cancelled either ({c.stderr.strip()}): scancel {job}")
                             + ", the runs' states put back: submit again") from None
        raise
    dep = index_job([f"--dependency=afterany:{job}"])
    write_index(sd)
    print(f"study {sd.study.name}: {len(todo)} runs submitted as Slurm job array {job} "
          f"(tasks {sdir}/task-{job}_<i>.out), index job {dep} after it; run the same command again to "
          f"resubmit what failed")
    return 0


def task(sd, name):
    # The task does its run in this thread: a signal must not raise in it
    # (a run that completes just as the signal comes stays complete).
    signal.signal(signal.SIGTERM, signal_children)
    signal.signal(signal.SIGINT, signal_children)
    for p in sd.study.points():
        if sd.study.run_name(p) == name:
            st = do_run(sd, p)
            write_index(sd)
            print(f"{name}: {st.get('state')} {st.get('message', '')}", flush=True)
            if st.get("state") == "interrupted" and st.get("resumable"):
                return RESUMABLE  # a Slurm task requeues itself on it
            return 0 if st.get("state") == "complete" else 1
    raise StudyError(f"{sd.dir}: no run named {name}")
