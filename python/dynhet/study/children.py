"""The processes a study starts: run_scene.sh and sim_node in sessions of their own, stopped together on a signal."""
import glob
import os
import signal
import subprocess
import threading
import time

from .paths import RUN_SCENE


STOPPING = threading.Event()  # SIGINT/SIGTERM: children are stopped, runs marked interrupted
CHILDREN = set()
CHILDREN_LOCK = threading.Lock()


def stop_children():
    STOPPING.set()
    with CHILDREN_LOCK:
        procs = list(CHILDREN)
    for proc in procs:  # run_scene.sh passes SIGTERM on: sim_node writes a checkpoint and stops
        try:
            os.killpg(proc.pid, signal.SIGTERM)
        except ProcessLookupError:
            pass
    deadline = time.time() + 120
    for proc in procs:
        try:
            proc.wait(timeout=max(1.0, deadline - time.time()))
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)


def already_stopping(*_):
    """The handler of SIGINT/SIGTERM once the study is stopping: a second
    signal (Ctrl-C twice, a shutdown's repeated SIGTERM) is said, not raised.
    Raised, it cut stop_children short: the runs went on writing their
    checkpoints unwatched and the study died with a traceback, leaving a run
    marked "running". A signal handler: one write, no lock."""
    os.write(2, b"study: already stopping; each run is writing its checkpoint (at most 2 min, then it is killed)\n")


RESUMABLE = 75  # run_scene.sh: interrupted, resumable from a whole checkpoint cut


def newest_whole_cut(run_dir):
    """The number of the newest cut of a run directory that is whole (has its
    WHOLE marker), or None. run_scene.sh checks its parts when it resumes."""
    cuts = glob.glob(os.path.join(run_dir, "checkpoints", "cut-*", "WHOLE"))
    return max(int(os.path.basename(os.path.dirname(c))[4:]) for c in cuts) if cuts else None


def signal_children(*_):
    """SIGTERM/SIGINT of a Slurm task: every child stops at a checkpoint cut
    (run_scene.sh passes the signal on); the task goes on to record what
    its run came to: complete if it finished meanwhile, else interrupted.
    A signal handler: it neither waits nor takes a lock."""
    STOPPING.set()
    for proc in list(CHILDREN):
        try:
            os.killpg(proc.pid, signal.SIGTERM)
        except (ProcessLookupError, PermissionError):
            pass


def call_child(cmd, log, **kw):
    """subprocess.call in a session of its own, stopped with the others on
    SIGTERM (signal_children, stop_children)."""
    proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, start_new_session=True, **kw)
    with CHILDREN_LOCK:
        CHILDREN.add(proc)
    if STOPPING.is_set():  # the signal came before the child was known
        signal_children()
    try:
        return proc.wait()
    finally:
        with CHILDREN_LOCK:
            CHILDREN.discard(proc)


def run_scene(scene_path, out, log_path, resume=None, fresh=False, plots=True):
    """fresh: the run starts over (run_scene.sh --fresh), its old cuts and file
    discarded; plots=False: no PNGs (run_scene.sh --no-plots)."""
    cmd = ["bash", RUN_SCENE, "--no-build", "--out", out] + (["--fresh"] if fresh else [])
    cmd += [] if plots else ["--no-plots"]
    cmd += ["--resume", resume] if resume else [scene_path]
    with open(log_path, "a") as log:
        log.write(f"\n# {time.strftime('%Y-%m-%d %H:%M:%S')} {' '.join(cmd)}\n")
        log.flush()
        t0 = time.time()
        r0 = os.times()
        if STOPPING.is_set():
            return 130, 0.0, 0.0
        # Each run on a private bus of its own (run_scene.sh --bus private makes
        # a new network namespace unless told it is in one already): runs that
        # share a bus would take each other's frames.
        env = {k: v for k, v in os.environ.items() if k != "DYNHET_IN_NETNS"}
        try:
            rc = call_child(cmd, log, env=env)
        except KeyboardInterrupt:  # Ctrl-C in the local executor's worker: the run stops at a checkpoint
            stop_children()
            rc = RESUMABLE
        r1 = os.times()
    return rc, time.time() - t0, (r1.children_user - r0.children_user) + (r1.children_system - r0.children_system)
