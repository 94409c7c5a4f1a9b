#!/usr/bin/python3
"""dynhet studies: a sweep of scenes, run on this machine or on a Slurm
cluster, resumable. launch_scripts/run_study.sh is the command; this is its
engine. A run stays what it is (launch_scripts/run_scene.sh: one scene, its
processes on a private bus, one run.h5); a study only writes scenes, starts
runs, reads their files and keeps their status on disk.

  study.py run STUDY.toml [--executor local|slurm] [--jobs K] [--out DIR] [--dry-run]
                          [--partition P] [--time T] [--mem M] [--sbatch ARG]...
  study.py task DIR NAME      one run of a study directory (what a Slurm task runs)
  study.py index DIR          write DIR/index.toml from the runs' status files

The study file format is in studies/README.md.
"""
import argparse
import copy
import fcntl
import glob
import hashlib
import math
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
import tomllib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BUILD = os.environ.get("BUILD_DIR", os.path.join(ROOT, "build"))
SIM = os.path.join(BUILD, "bin", "sim_node")
RUN_SCENE = os.path.join(ROOT, "launch_scripts", "run_scene.sh")


class StudyError(Exception):
    pass


class StudyInterrupted(Exception):
    pass


# ------------------------------------------------------------------ TOML out


def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isinf(v) or math.isnan(v):
            return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf")
        return repr(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(f"cannot write {v!r} as TOML")


def toml_dump(tables, header=""):
    """Tables of scalars and arrays (a scene, a status file)."""
    out = [header] if header else []
    top = {k: v for k, v in tables.items() if not isinstance(v, dict)}
    for k, v in top.items():
        out.append(f"{k} = {toml_value(v)}")
    for name, t in tables.items():
        if not isinstance(t, dict):
            continue
        out.append(f"\n[{name}]")
        for k, v in t.items():
            out.append(f"{k} = {toml_value(v)}")
    return "\n".join(out) + "\n"


def write_atomic(path, text):
    tmp = f"{path}.tmp{os.getpid()}"
    with open(tmp, "w") as f:
        f.write(text)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def read_toml(path):
    with open(path, "rb") as f:
        return tomllib.load(f)


# ------------------------------------------------------------------ study file

AXES = {  # axis -> (scene table, key, type)
    "packing_fraction": ("system", "packing_fraction", float),
    "restitution": ("system", "restitution", float),
    "n_particles": ("system", "n_particles", int),
    "seed": ("system", "seed", int),
    "pairs": ("driving", "pairs", str),
}
RUN_LENGTH_KEYS = {
    "tau_alpha": str,  # "scene" | "pilot" | "interpolate"
    "equilibration_tau": float,
    "lag_max_tau": float,
    "lag_min_tau": float,
    "origin_spacing_tau": float,
    "origins": int,
    "pilot_particles": int,
    "pilot_margin": float,
    "max_attempts": int,
    "tau_guess": list,
}
RUN_LENGTH_DEFAULTS = dict(tau_alpha="scene", equilibration_tau=10.0, lag_max_tau=4.0, lag_min_tau=0.02,
                           origin_spacing_tau=1.0, origins=8, pilot_particles=2048, pilot_margin=1.2, max_attempts=3,
                           tau_guess=[])


def check_type(where, v, typ):
    if typ is float:
        ok = isinstance(v, (int, float)) and not isinstance(v, bool)
    else:
        ok = isinstance(v, typ) and not (typ is int and isinstance(v, bool))
    if not ok:
        raise StudyError(f"{where}: value {v!r} is {type(v).__name__}, expected {typ.__name__}")
    return float(v) if typ is float else v


class Study:
    def __init__(self, path, base_scene=None):
        """base_scene: read the base scene from this file instead (a study
        directory's copy, for its tasks wherever they run)."""
        self.path = os.path.abspath(path)
        try:
            self.text = open(self.path, "rb").read()
            data = tomllib.loads(self.text.decode())
        except FileNotFoundError:
            raise StudyError(f"{path}: no such study file")
        except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
            raise StudyError(f"{path}: not valid TOML: {e}")
        self.errors = []
        known = {"study", "scene", "axes", "series", "run_length", "override"}
        for k in data:
            if k not in known:
                self.errors.append(f"{k}: unknown key or table; known: {', '.join(sorted(known))}")
        st = data.get("study", {})
        for k in st:
            if k not in ("name", "description", "scene", "prepared_states"):
                self.errors.append(f"study.{k}: unknown key; known keys in [study]: name, description, scene, "
                                   "prepared_states")
        # true or "compressed": compression once per (N, phi, ratio, seed);
        # "equilibrated": also the equilibration, once per run dynamics
        # (extended, never repeated, when a run needs more); false: neither.
        ps = st.get("prepared_states", True)
        if not (isinstance(ps, bool) or ps in ("compressed", "equilibrated")):
            self.errors.append(f"study.prepared_states: value {ps!r} must be true, false, \"compressed\" or "
                               "\"equilibrated\"")
            ps = True
        self.prepared_states = {True: "compressed", False: None}.get(ps, ps) if isinstance(ps, bool) else ps
        self.equilibrated_states = self.prepared_states == "equilibrated"
        self.name = st.get("name", os.path.splitext(os.path.basename(path))[0])
        if not isinstance(self.name, str) or not self.name or "/" in self.name:
            self.errors.append(f"study.name: value {self.name!r} must be a non-empty string without '/'")
        # The base scene: a path (relative to the study file) or an inline [scene] table.
        if "scene" in st and "scene" in data:
            self.errors.append("study.scene: give the base scene as a path or as a [scene] table, not both")
        if base_scene:
            self.base = read_toml(base_scene)
        elif "scene" in st:
            if not isinstance(st["scene"], str):
                self.errors.append(f"study.scene: value {st['scene']!r} must be a path (string)")
                self.base = {}
            else:
                sp = os.path.join(os.path.dirname(self.path), st["scene"])
                try:
                    self.base = read_toml(sp)
                except FileNotFoundError:
                    self.errors.append(f"study.scene: no scene file {sp}")
                    self.base = {}
                except tomllib.TOMLDecodeError as e:
                    self.errors.append(f"study.scene: {sp} is not valid TOML: {e}")
                    self.base = {}
        elif "scene" in data:
            self.base = data["scene"]
            if not isinstance(self.base, dict):
                self.errors.append("scene: must be a table of scene tables ([scene.system], ...)")
                self.base = {}
        else:
            self.base = {}
        # [axes]: one product of axes; or [[series]]: several, the runs their union.
        if "axes" in data and "series" in data:
            self.errors.append("series: give [axes] or [[series]], not both")
        blocks = [("axes", data.get("axes", {}))]
        if "series" in data:
            if not isinstance(data["series"], list):
                self.errors.append("series: must be an array of tables ([[series]])")
            else:
                blocks = [(f"series[{i}]", b) for i, b in enumerate(data["series"])]
        self.series = [self.read_axes(where, b) for where, b in blocks]
        self.axes = {}  # every value of each axis over all series
        for ax in self.series:
            for k, vals in ax.items():
                self.axes.setdefault(k, [])
                self.axes[k] += [v for v in vals if v not in self.axes[k]]
        rl = dict(RUN_LENGTH_DEFAULTS)
        for k, v in data.get("run_length", {}).items():
            if k not in RUN_LENGTH_KEYS:
                self.errors.append(f"run_length.{k}: unknown key; known: {', '.join(RUN_LENGTH_KEYS)}")
                continue
            try:
                rl[k] = check_type(f"run_length.{k}", v, RUN_LENGTH_KEYS[k])
            except StudyError as e:
                self.errors.append(str(e))
        if rl["tau_alpha"] not in ("scene", "pilot", "interpolate"):
            self.errors.append(f"run_length.tau_alpha: value {rl['tau_alpha']!r} is not allowed; "
                               'allowed: "scene" (the scene\'s own times), "pilot", "interpolate"')
        if not (1.0 <= rl["pilot_margin"] <= 10.0):
            self.errors.append(f"run_length.pilot_margin: value {rl['pilot_margin']} is not allowed; allowed: 1 to 10")
        for k in ("equilibration_tau", "lag_max_tau", "lag_min_tau", "origin_spacing_tau"):
            if not (rl[k] > 0 and math.isfinite(rl[k])):
                self.errors.append(f"run_length.{k}: value {rl[k]} must be > 0")
        if rl["lag_min_tau"] >= rl["lag_max_tau"]:
            self.errors.append("run_length.lag_min_tau: must be smaller than run_length.lag_max_tau")
        for k, lo in (("origins", 1), ("pilot_particles", 100), ("max_attempts", 1)):
            if rl[k] < lo:
                self.errors.append(f"run_length.{k}: value {rl[k]} must be >= {lo}")
        guesses = []
        for g in rl["tau_guess"]:
            if (not isinstance(g, list) or len(g) != 2 or not all(isinstance(x, (int, float)) for x in g)
                    or not g[1] > 0):
                self.errors.append(f"run_length.tau_guess: entry {g!r} must be [phi, tau_alpha > 0]")
                continue
            guesses.append((float(g[0]), float(g[1])))
        rl["tau_guess"] = sorted(guesses)
        self.run_length = rl
        self.overrides = []
        for i, o in enumerate(data.get("override", [])):
            where = f"override[{i}]"
            if not isinstance(o, dict) or set(o) - {"when", "set"} or "set" not in o:
                self.errors.append(f"{where}: an override is {{when = {{axis = value, ...}}, set = {{table = {{key = value}}}}}}")
                continue
            when = o.get("when", {})
            for k, v in when.items():
                if k not in AXES:
                    self.errors.append(f"{where}.when.{k}: unknown axis; known: {', '.join(AXES)}")
                elif k in self.axes and check_type(f"{where}.when.{k}", v, AXES[k][2]) not in self.axes[k]:
                    self.errors.append(f"{where}.when.{k}: value {v!r} is not on axis {k} {self.axes[k]}")
            if not isinstance(o["set"], dict) or not all(isinstance(t, dict) for t in o["set"].values()):
                self.errors.append(f"{where}.set: must be scene tables, e.g. {{system = {{n_particles = 4096}}}}")
                continue
            self.overrides.append((when, o["set"]))
        if self.errors:
            raise StudyError(f"{path}: invalid study ({len(self.errors)} problem"
                             f"{'s' if len(self.errors) > 1 else ''}):\n  " + "\n  ".join(self.errors))

    def read_axes(self, where, block):
        axes = {}
        if not isinstance(block, dict):
            self.errors.append(f"{where}: must be a table of axes")
            return axes
        for k, v in block.items():
            if k not in AXES:
                self.errors.append(f"{where}.{k}: unknown axis; known: {', '.join(AXES)}")
                continue
            if not isinstance(v, list) or not v:
                self.errors.append(f"{where}.{k}: value {v!r} must be a non-empty array")
                continue
            try:
                vals = [check_type(f"{where}.{k}", x, AXES[k][2]) for x in v]
            except StudyError as e:
                self.errors.append(str(e))
                continue
            if len(set(vals)) != len(vals):
                self.errors.append(f"{where}.{k}: each value may be listed once")
                continue
            axes[k] = vals
        return axes

    def base_value(self, axis):
        table, key, _ = AXES[axis]
        defaults = {"packing_fraction": 0.7, "restitution": 0.9, "n_particles": 1000, "seed": 1,
                    "pairs": "neighbours"}
        return self.base.get(table, {}).get(key, defaults[axis])

    def points(self):
        """Every run: a dict of axis values, in a fixed order (phi slowest)."""
        names = list(AXES)
        runs = []
        for ax in self.series:
            block = [{}]
            for a in names:
                block = [dict(r, **{a: v}) for r in block for v in ax.get(a, [self.base_value(a)])]
            runs += [r for r in block if r not in runs]
        # Overrides of an axis' own key (a larger N at low phi) show in the point.
        for r in runs:
            for when, st in self.overrides:
                if self.matches(r, when):
                    for a, (table, key, typ) in AXES.items():
                        if key in st.get(table, {}):
                            r[a] = typ(st[table][key])
        order = ["pairs", "restitution", "n_particles", "packing_fraction", "seed"]
        return sorted(runs, key=lambda r: tuple(r[a] for a in order))

    @staticmethod
    def matches(p, when):
        return all(p[k] == (float(v) if AXES[k][2] is float else v) for k, v in when.items())

    def run_name(self, p):
        s = f"phi{p['packing_fraction']:.4f}_eps{p['restitution']:.3f}_n{p['n_particles']}_seed{p['seed']}"
        if "pairs" in self.axes:
            s += f"_{p['pairs']}"
        return s

    def series_key(self, p):  # points whose tau_alpha may be interpolated in phi
        return (p["restitution"], p["pairs"], p["n_particles"])

    def scene(self, p, tau=None, pilot=False):
        """The scene of run p as tables; with tau, run lengths in units of it."""
        sc = copy.deepcopy(self.base)
        for a, (table, key, _) in AXES.items():
            sc.setdefault(table, {})[key] = p[a]
        for when, st in self.overrides:
            if self.matches(p, when):
                for table, kv in st.items():
                    sc.setdefault(table, {}).update(kv)
        if tau is not None:
            rl = self.run_length
            eq, origins, lag_max = rl["equilibration_tau"], rl["origins"], rl["lag_max_tau"]
            if pilot:  # short and small: only tau_alpha is wanted
                eq, origins = min(eq, 5.0), min(origins, 4)
                sc["system"]["n_particles"] = min(int(sc["system"]["n_particles"]), rl["pilot_particles"])
                sc["observables"] = {"compute": ["overlap"], "cutoff_a": sc.get("observables", {}).get("cutoff_a", [0.6])}
                for t in ("chi4", "s4", "clusters", "msd", "displacement"):
                    sc.pop(t, None)
            sc.setdefault("run", {})["equilibration_time"] = round(eq * tau, 6)
            sc["run"].pop("production_time", None)
            sched = sc.setdefault("schedule", {})
            sched["origins"] = origins
            sched["origin_spacing"] = round(rl["origin_spacing_tau"] * tau, 6)
            sched["lag_min"] = round(rl["lag_min_tau"] * tau, 6)
            sched["lag_max"] = round(lag_max * tau, 6)
        return sc

    def first_cutoff(self, sc):
        return sc.get("observables", {}).get("cutoff_a", [0.6])[0]


# ------------------------------------------------------------------ estimates


def kick_rate(phi, ratio=1.43):
    """The Enskog frequency of common/include/dynhet/model.hpp (mixture G_c)."""
    s = (2.0, 2.0 * ratio)
    m = (1.0, ratio * ratio)
    m1, m2 = 0.5 * (s[0] + s[1]), 0.5 * (s[0] ** 2 + s[1] ** 2)
    num = den = 0.0
    for a in range(2):
        for b in range(2):
            sab = 0.5 * (s[a] + s[b])
            g = 1 / (1 - phi) + 9 / 16 * phi / (1 - phi) ** 2 * s[a] * s[b] / sab * m1 / m2
            w = 0.25 * sab * math.sqrt((m[a] + m[b]) / (m[a] * m[b]))
            num += w * g
            den += w
    return 2.59 * phi * (num / den) / math.sqrt(math.pi)


def events_per_second(n):
    """Driven collisions + kicks per CPU second with neighbour pairs
    (docs/engine.md, bench_engine): about 2e6 up to 10^4, 1.5e6 at 10^5,
    1.2e6 at 10^6, log-linear between."""
    x = math.log10(max(n, 1e4))
    return 2.0e6 - 0.5e6 * min(x - 4, 1) - 0.3e6 * max(0.0, x - 5)


def estimate(sc, n_nodes):
    """(CPU seconds, bytes) of one run from the engine's measured speed."""
    sy, rn, sch = sc.get("system", {}), sc.get("run", {}), sc.get("schedule", {})
    n, phi = int(sy.get("n_particles", 1000)), float(sy.get("packing_fraction", 0.7))
    eq = float(rn.get("equilibration_time", 100.0))
    origins, spacing = int(sch.get("origins", 10)), float(sch.get("origin_spacing", 10.0))
    lag_max = float(sch.get("lag_max", 100.0))
    t = eq + (origins - 1) * spacing + lag_max
    w = kick_rate(phi, float(sy.get("radius_ratio", 1.43)))
    events = n * w * t  # collisions ~ N w / 2 and kicks N w / 2 per unit time
    compress = 2.5e-4 * n * (1 + max(0.0, phi - 0.6) * 10)  # seconds, bench_engine's compression times
    cpu = events / events_per_second(n) + compress
    held = min(origins, lag_max / spacing + 2)
    mem = 60e6 + 230 * n + n_nodes * 16 * n * held
    return cpu, mem


def fmt_time(s):
    if not math.isfinite(s):
        return "?"
    s = int(round(s))
    return f"{s // 3600}:{s % 3600 // 60:02d}:{s % 60:02d}"


# ------------------------------------------------------------------ runs on disk


def read_status(d):
    p = os.path.join(d, "status.toml")
    if not os.path.exists(p):
        return {}
    try:
        return read_toml(p)
    except tomllib.TOMLDecodeError:
        return {"state": "unknown"}


def write_status(d, st):
    write_atomic(os.path.join(d, "status.toml"), toml_dump(st, "# dynhet study run status (run_study.sh reads it)"))


def run_h5_result(path, cutoff):
    """(complete, tau_alpha) of a run.h5."""
    out = subprocess.run(
        ["/usr/bin/python3", "-c",
         "import h5py,sys,math\n"
         "f=h5py.File(sys.argv[1],'r')\n"
         "c=int(f.attrs.get('complete',0))\n"
         "g=f.get('observables/overlap/a'+sys.argv[2])\n"
         "t=float(g['tau_alpha/value'][-1]) if g is not None else float('nan')\n"
         "print(c, t)", path, f"{cutoff:g}"],
        capture_output=True, text=True)
    if out.returncode != 0:
        return 0, float("nan")
    c, t = out.stdout.split()
    return int(c), float(t)


class StudyDir:
    def __init__(self, study, out):
        self.study = study
        self.dir = os.path.abspath(out)
        self.runs_dir = os.path.join(self.dir, "runs")
        self.lock = threading.Lock()

    def claim(self):
        """Create the directory or check it holds this very study."""
        os.makedirs(self.runs_dir, exist_ok=True)
        copy_path = os.path.join(self.dir, "study.toml")
        base_path = os.path.join(self.dir, "base_scene.toml")
        base_text = toml_dump(self.study.base, "# the study's base scene, as read when the study started")
        if os.path.exists(copy_path):
            if open(copy_path, "rb").read() != self.study.text:
                raise StudyError(f"{self.study.path} differs from the study that {self.dir} holds "
                                 f"({copy_path}): a changed study is never mixed into old runs; "
                                 "give another --out, or restore the study file")
            if os.path.exists(base_path) and open(base_path).read() != base_text:
                raise StudyError(f"the base scene of {self.study.path} changed since {self.dir} was started "
                                 f"({base_path} holds the old one): give another --out, or restore the scene")
        else:
            with open(copy_path, "wb") as f:
                f.write(self.study.text)
        if not os.path.exists(base_path):
            write_atomic(base_path, base_text)

    def run_dir(self, p):
        return os.path.join(self.runs_dir, self.study.run_name(p))

    def finished_taus(self, p):
        """(phi, tau_alpha) of complete runs and pilots of p's series."""
        pts = []
        key = self.study.series_key(p)
        for q in self.study.points():
            if self.study.series_key(q) != key:
                continue
            st = read_status(self.run_dir(q))
            if st.get("state") == "complete" and math.isfinite(st.get("tau_alpha", float("nan"))):
                pts.append((q["packing_fraction"], st["tau_alpha"]))
        pdir = os.path.join(self.dir, "pilots")
        if os.path.isdir(pdir):
            for name in os.listdir(pdir):
                st = read_status(os.path.join(pdir, name))
                if st.get("state") == "complete" and tuple(st.get("series", [])) == (
                        key[0], key[1], key[2]):
                    pts.append((st["packing_fraction"], st["tau_alpha"]))
        by_phi = {}
        for ph, t in pts:
            by_phi.setdefault(ph, []).append(t)
        return sorted((ph, math.exp(sum(map(math.log, ts)) / len(ts))) for ph, ts in by_phi.items())

    @staticmethod
    def interpolate(pts, phi):
        """ln tau linear in phi between the nearest points (or from the nearest two at the ends)."""
        if len(pts) < 2:
            return None
        for ph, t in pts:
            if abs(ph - phi) < 1e-12:
                return t
        below = [x for x in pts if x[0] < phi]
        above = [x for x in pts if x[0] > phi]
        if below and above:
            a, b = below[-1], above[0]
        elif below:
            a, b = below[-2] if len(below) > 1 else below[-1], below[-1]
        else:
            a, b = above[0], above[1]
        if a[0] == b[0]:
            return None
        s = (math.log(b[1]) - math.log(a[1])) / (b[0] - a[0])
        return math.exp(math.log(a[1]) + s * (phi - a[0]))

    def guess(self, p, finished=True):
        """A prior guess of tau_alpha: finished points, then the study's tau_guess table, then 1."""
        t = self.interpolate(self.finished_taus(p), p["packing_fraction"]) if finished else None
        if t:
            return t, "interpolated from finished points"
        g = self.study.run_length["tau_guess"]
        if len(g) >= 2:
            return self.interpolate(g, p["packing_fraction"]), "the study's tau_guess"
        if len(g) == 1:
            return g[0][1], "the study's tau_guess"
        return 1.0, "no estimate (1.0)"


# ------------------------------------------------------------------ one run


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


def run_scene(scene_path, out, log_path, resume=None):
    cmd = ["bash", RUN_SCENE, "--no-build", "--out", out]
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


def prepared_state(sd, sc):
    """The prepared state (compressed, velocities drawn) of scene sc's system:
    made once per (N, phi, radius ratio, seed) by sim_node --prepare-only and
    shared by every run and pilot of it (other restitutions, driving, cutoffs,
    schedules); a run from it equals the run that compresses itself, bit for
    bit. Sets sc's system.initial_state to it."""
    if sd.study.prepared_states is None or sc["system"].get("initial_state"):
        return
    sy = sc["system"]
    key = (f"n{int(sy['n_particles'])}_phi{float(sy['packing_fraction']):.6g}"
           f"_r{float(sy.get('radius_ratio', 1.43)):.6g}_seed{int(sy.get('seed', 1))}")
    d = os.path.join(sd.dir, "states")
    os.makedirs(d, exist_ok=True)
    path = os.path.join(d, key + ".h5")
    with open(os.path.join(d, key + ".lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not os.path.exists(path):
            scene_path = os.path.join(d, key + ".toml")
            write_atomic(scene_path, toml_dump(sc, f"# the system of prepared state {key}"))
            with open(os.path.join(d, key + ".log"), "w") as log:
                rc = call_child([SIM, scene_path, "--prepare-only", path + ".tmp"], log)
            if rc != 0 or STOPPING.is_set():
                if STOPPING.is_set():
                    raise StudyInterrupted(f"preparing {key} stopped")
                raise StudyError(f"preparing the state {key} failed (exit {rc}); its log: {d}/{key}.log")
            os.replace(path + ".tmp", path)
    sy["initial_state"] = path


def equilibrated_state(sd, sc):
    """With prepared_states = "equilibrated": the state of run scene sc's
    dynamics (everything in [system] and [driving], and the checkpoint
    interval, which the bit-for-bit continuation needs) equilibrated up to
    its run.equilibration_time, made by sim_node --prepare-only --equilibrate
    from the compressed state or from the longest shorter one already made
    (a run found too short extends its state instead of starting again).
    Each length is a file of its own, never replaced, so a run that refers
    to one can always start again. Sets sc's initial_state to it; a run
    from it equals, bit for bit, the run that equilibrates itself."""
    if not sd.study.equilibrated_states:
        return
    sy = {k: v for k, v in sc["system"].items() if k != "initial_state"}
    interval = float(sc.get("run", {}).get("checkpoint_interval", 10.0))  # the scene default
    dyn = toml_dump({"system": sy, "driving": sc.get("driving", {}), "run": {"checkpoint_interval": interval}})
    key = (f"eq_n{int(sy['n_particles'])}_phi{float(sy['packing_fraction']):.6g}"
           f"_eps{float(sy.get('restitution', 1.0)):.6g}_seed{int(sy.get('seed', 1))}_"
           + hashlib.sha1(dyn.encode()).hexdigest()[:10])
    d = os.path.join(sd.dir, "states")
    t_eq = float(sc["run"]["equilibration_time"])
    if t_eq < interval:  # not one checkpoint slot: the run equilibrates itself
        return
    with open(os.path.join(d, key + ".lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        made = {}  # time -> path of the states of this dynamics made so far
        for f in os.listdir(d):
            if f.startswith(key + "_t") and f.endswith(".h5"):
                made[float(f[len(key) + 2:-3])] = os.path.join(d, f)
        within = [t for t in made if t <= t_eq]
        # Equilibrated to within one checkpoint interval of what the run asks
        # (the last slot before it is where sim_node --equilibrate stops): take it.
        if within and max(within) > t_eq - interval:
            sc["system"]["initial_state"] = made[max(within)]
            return
        src = dict(sc, system=dict(sc["system"]))
        if within:
            src["system"]["initial_state"] = made[max(within)]
        scene_path = os.path.join(d, f"{key}.toml")
        write_atomic(scene_path, toml_dump(src, f"# the dynamics of equilibrated states {key}"))
        tmp = os.path.join(d, key + ".tmp.h5")
        with open(os.path.join(d, key + ".log"), "a") as log:
            log.write(f"\n# {time.strftime('%Y-%m-%d %H:%M:%S')} to t = {t_eq:g}\n")
            log.flush()
            rc = call_child([SIM, scene_path, "--prepare-only", tmp, "--equilibrate"], log)
        if rc != 0 or STOPPING.is_set():
            if STOPPING.is_set():
                raise StudyInterrupted(f"equilibrating {key} stopped")
            raise StudyError(f"equilibrating the state {key} failed (exit {rc}); its log: {d}/{key}.log")
        with open(os.path.join(d, key + ".log")) as log:
            t = float(re.findall(r"equilibrated state .* from t = \S+ to (\S+) in ", log.read())[-1])
        path = os.path.join(d, f"{key}_t{t:.10g}.h5")
        os.replace(tmp, path)
    sc["system"]["initial_state"] = path


def pid_alive(pid):
    try:
        os.kill(int(pid), 0)
        return True
    except (TypeError, ValueError, ProcessLookupError):
        return False
    except PermissionError:
        return True


def pilot(sd, p):
    """tau_alpha of p from a short, small run of its series; cached per point (not per seed)."""
    st = sd.study
    name = f"phi{p['packing_fraction']:.4f}_eps{p['restitution']:.3f}_n{p['n_particles']}_{p['pairs']}"
    d = os.path.join(sd.dir, "pilots", name)
    os.makedirs(d, exist_ok=True)
    # Other seeds of the point (threads here, or Slurm tasks elsewhere) wait
    # for the one pilot instead of running it again in the same directory.
    with open(os.path.join(d, ".lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        return pilot_locked(sd, p, name, d)


def pilot_locked(sd, p, name, d):
    st = sd.study
    old = read_status(d)
    if old.get("state") == "complete":
        return old["tau_alpha"]
    # The same pilot whichever seed of the point comes first (the first
    # seed's), and whatever else has finished (its first guess only from the
    # study file): the pilot, and so the run, is a function of the point.
    p = dict(p, seed=st.axes.get("seed", [st.base_value("seed")])[0])
    g, _ = sd.guess(p, finished=False)
    for attempt in range(1, 7):
        sc = st.scene(p, g, pilot=True)
        prepared_state(sd, sc)
        write_atomic(os.path.join(d, "scene.toml"), toml_dump(sc, f"# pilot of {name}, tau guess {g:.6g}"))
        rc, wall, cpu = run_scene(os.path.join(d, "scene.toml"), d, os.path.join(d, "run_scene.log"))
        if STOPPING.is_set():
            raise StudyInterrupted(f"pilot of {name} stopped")
        complete, tau = run_h5_result(os.path.join(d, "run.h5"), st.first_cutoff(sc))
        if rc != 0 or not complete:
            write_status(d, {"state": "failed", "exit": rc, "message": f"pilot run failed; log {d}/run_scene.log"})
            raise StudyError(f"pilot of {name} failed (exit {rc}); its log: {d}/run_scene.log")
        if math.isfinite(tau) and tau <= g:
            key = st.series_key(p)
            write_status(d, {"state": "complete", "tau_alpha": tau, "guess": g, "attempts": attempt,
                             "packing_fraction": p["packing_fraction"], "series": list(key),
                             "wall_s": wall, "cpu_s": cpu})
            return tau
        g = 4 * g if not math.isfinite(tau) else 1.3 * tau
    raise StudyError(f"pilot of {name}: tau_alpha not found after 6 attempts")


def do_run(sd, p, log=print):
    """Runs (or resumes) one run to the end; returns its final status."""
    st = sd.study
    d = sd.run_dir(p)
    os.makedirs(d, exist_ok=True)
    old = read_status(d)
    if old.get("state") == "complete":
        return old
    rl = st.run_length
    attempts = int(old.get("attempts", 0))
    resume = None
    tau_est, source = old.get("tau_estimate"), old.get("tau_source")
    if old.get("state") == "running" and old.get("host") == socket.gethostname() and pid_alive(old.get("pid")):
        return dict(old, state="running", message=f"still running in process {old.get('pid')}")
    if old.get("state") in ("running", "queued", "interrupted"):
        ck = os.path.join(d, "checkpoint_before_frames.h5")
        cut = newest_whole_cut(d)
        if cut is not None and os.path.exists(os.path.join(d, "scene.toml")):
            # run_scene.sh on the same directory resumes from the cut itself.
            resume = "cut"
            log(f"{st.run_name(p)}: was interrupted; resuming mid-production from checkpoint cut {cut}")
        elif os.path.exists(ck) and os.path.exists(os.path.join(d, "scene.toml")):
            resume = ck
            log(f"{st.run_name(p)}: was interrupted; resuming from {ck}")
        elif old.get("state") != "queued" or old.get("started"):
            log(f"{st.run_name(p)}: was interrupted before its first checkpoint; starting again")
    elif old.get("state") in ("failed", "too_short", "unknown"):
        log(f"{st.run_name(p)}: {old.get('state')} before ({old.get('message', '')}); running it again")
    if resume is None:
        if rl["tau_alpha"] == "scene":
            tau_est, source = None, "scene"
        elif old.get("state") == "too_short" and old.get("tau_alpha"):
            tau_est, source = 1.3 * old["tau_alpha"], "1.3 x the tau_alpha of the previous, too short attempt"
        elif rl["tau_alpha"] == "interpolate" and len(sd.finished_taus(p)) >= 2:
            tau_est, source = sd.guess(p)
        else:
            # A short, small pilot scatters by some 10% from the run (seen in
            # studies/quick.toml): a margin spares most runs a second attempt.
            tau_est = rl["pilot_margin"] * pilot(sd, p)
            source = "pilot" if rl["pilot_margin"] == 1.0 else f"pilot x {rl['pilot_margin']:g}"
        sc = st.scene(p, tau_est)
        # A lag at the best tau_alpha estimate (the pilot's, or the previous
        # attempt's, without the margin), for what the paper takes at
        # tau_alpha (clusters, S4). Measured in studies/seeds.toml it does not
        # bring them closer: the pilot scatters by as much as the lag spacing
        # (clusters and S4 at a median 6%, at most 15%, from the run's
        # tau_alpha either way); a better estimate would.
        if tau_est is not None:
            best = tau_est / (rl["pilot_margin"] if source.startswith("pilot") else
                              1.3 if source.startswith("1.3 x") else 1.0)
            sch = sc["schedule"]
            if sch["lag_min"] <= best <= sch["lag_max"]:
                sch["extra_lags"] = [round(best, 6)]
        prepared_state(sd, sc)
        equilibrated_state(sd, sc)
        write_atomic(os.path.join(d, "scene.toml"),
                     toml_dump(sc, f"# {st.name}: {st.run_name(p)}; tau_alpha estimate {tau_est} ({source})"))
    sc = read_toml(os.path.join(d, "scene.toml"))
    status = {"state": "running", "host": socket.gethostname(), "pid": os.getpid(),
              "started": time.strftime("%Y-%m-%dT%H:%M:%S"), "attempts": attempts + 1,
              "tau_source": source or "scene"}
    if tau_est is not None:
        status["tau_estimate"] = tau_est
    for a in AXES:
        status[a] = p[a]
    write_status(d, status)
    if os.environ.get("SLURM_RESTART_COUNT"):
        status["requeues"] = int(os.environ["SLURM_RESTART_COUNT"])
    scene_path = os.path.join(d, "scene.toml")
    cut0 = newest_whole_cut(d)
    rc, wall, cpu = run_scene(scene_path, d, os.path.join(d, "run_scene.log"), None if resume == "cut" else resume)
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
        rc2, wall2, cpu2 = run_scene(scene_path, d, os.path.join(d, "run_scene.log"))
        rc, wall, cpu = rc2, wall + wall2, cpu + cpu2
    if rc == RESUMABLE and not STOPPING.is_set() and newest_whole_cut(d) == cut0:
        rc = 1  # no progress: a failure, not an interruption
    complete, tau = run_h5_result(os.path.join(d, "run.h5"), st.first_cutoff(sc)) if rc == 0 else (0, float("nan"))
    status.update({"exit": rc, "wall_s": wall, "cpu_s": cpu, "finished": time.strftime("%Y-%m-%dT%H:%M:%S"),
                   "tau_alpha": tau})
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
    elif tau_est is not None and not (math.isfinite(tau) and
                                      sc["run"]["equilibration_time"] >= 0.9 * rl["equilibration_tau"] * tau):
        status["state"] = "too_short"
        status["message"] = (f"tau_alpha {tau:.4g} against the estimate {tau_est:.4g}: the equilibration was "
                             f"under {0.9 * rl['equilibration_tau']:g} tau_alpha")
    else:
        status["state"] = "complete"
    write_status(d, status)
    if status["state"] == "too_short" and status["attempts"] < rl["max_attempts"] and not STOPPING.is_set():
        log(f"{st.run_name(p)}: {status['message']}; again with 1.3 tau_alpha")
        return do_run(sd, p, log)
    return status


# ------------------------------------------------------------------ index, dry run, executors


def write_index(sd):
    rows = {}
    for p in sd.study.points():
        st = read_status(sd.run_dir(p))
        row = {a: p[a] for a in AXES}
        row["path"] = os.path.relpath(sd.run_dir(p), sd.dir)
        row["state"] = st.get("state", "pending")
        for k in ("tau_estimate", "tau_source", "tau_alpha", "wall_s", "cpu_s", "attempts", "requeues", "message"):
            if k in st:
                row[k] = st[k]
        rows[sd.study.run_name(p)] = row
    text = [f"# dynhet study index: {sd.study.name} ({sd.study.path}); one table per run", ""]
    for name, row in rows.items():
        text.append(f'[runs."{name}"]')
        text += [f"{k} = {toml_value(v)}" for k, v in row.items()]
        text.append("")
    write_atomic(os.path.join(sd.dir, "index.toml"), "\n".join(text))
    return rows


def plan(sd):
    """[(point, scene, tau, source, state)] with times from the estimates known now (nothing started)."""
    out = []
    for p in sd.study.points():
        st = read_status(sd.run_dir(p))
        if sd.study.run_length["tau_alpha"] == "scene":
            tau, src = None, "scene"
        elif st.get("tau_estimate") and st.get("state") != "too_short":
            tau, src = st["tau_estimate"], st.get("tau_source", "?")
        else:
            tau, src = sd.guess(p)
            src = f"guess: {src}" + ("; a pilot will measure it" if sd.study.run_length["tau_alpha"] == "pilot" else "")
        out.append((p, sd.study.scene(p, tau), tau, src, st.get("state", "pending")))
    return out


def nodes_of(sc):
    comp = sc.get("observables", {}).get("compute", ["overlap"])
    return len({("overlap" if c in ("chi4", "msd", "displacement") else c) for c in comp})


def dry_run(sd):
    rows = plan(sd)
    print(f"# study {sd.study.name}: {len(rows)} runs; times from the tau_alpha estimates known now; "
          "CPU time from the engine's measured speed (docs/engine.md)")
    print(f"{'run':44s} {'state':9s} {'N':>8s} {'tau_est':>9s} {'t_equil':>9s} {'t_prod':>9s} "
          f"{'cpu':>9s} {'memory':>8s}  tau from")
    tot_cpu = left_cpu = 0.0
    peak = 0.0
    for p, sc, tau, src, state in rows:
        cpu, mem = estimate(sc, nodes_of(sc))
        sch = sc.get("schedule", {})
        prod = (int(sch.get("origins", 10)) - 1) * float(sch.get("origin_spacing", 10)) + float(sch.get("lag_max", 100))
        tot_cpu += cpu
        left_cpu += 0 if state == "complete" else cpu
        peak = max(peak, mem)
        print(f"{sd.study.run_name(p):44s} {state:9s} {sc['system']['n_particles']:8d} "
              f"{(f'{tau:.4g}' if tau else '-'):>9s} {sc.get('run', {}).get('equilibration_time', 100):9.4g} "
              f"{prod:9.4g} {fmt_time(cpu):>9s} {mem / 2**20:7.0f}M  {src}")
    print(f"# total CPU {fmt_time(tot_cpu)} ({tot_cpu / 3600:.2f} CPU-hours), left {fmt_time(left_cpu)}; "
          f"largest run {peak / 2**20:.0f} MiB (pilots not counted)")


def run_local(sd, jobs):
    points = [p for p in sd.study.points()]
    todo = [p for p in points if read_status(sd.run_dir(p)).get("state") != "complete"]
    done0 = len(points) - len(todo)
    if done0:
        print(f"study {sd.study.name}: {done0} of {len(points)} runs complete already (skipped)", flush=True)
    if sd.study.run_length["tau_alpha"] == "interpolate":  # low phi first: the rest interpolate from them
        todo.sort(key=lambda p: p["packing_fraction"])
    est = {sd.study.run_name(p): estimate(sc, nodes_of(sc))[0] for p, sc, *_ in plan(sd)}
    lock = threading.Lock()
    state = {"done": done0, "failed": 0, "running": 0, "left": len(todo), "cpu_done": 0.0, "est_done": 0.0}
    queue = list(todo)
    failures = []
    t_start = time.time()

    def say(msg):
        with lock:
            print(msg, flush=True)

    def progress():
        with lock:
            left_est = sum(est[sd.study.run_name(p)] for p in queue)
            ratio = state["cpu_done"] / state["est_done"] if state["est_done"] > 0 else 1.0
            eta = ratio * left_est / max(1, jobs)
            print(f"[{fmt_time(time.time() - t_start)}] study {sd.study.name}: {state['done']} done, "
                  f"{state['running']} running, {state['left']} left, {state['failed']} failed; "
                  f"ETA {fmt_time(eta)} (queued runs, estimated)", flush=True)

    def worker():
        while True:
            with lock:
                if not queue or STOPPING.is_set():
                    return
                p = queue.pop(0)
                state["left"] -= 1
                state["running"] += 1
            name = sd.study.run_name(p)
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
            write_index(sd)
            progress()

    progress()
    threads = [threading.Thread(target=worker, daemon=True) for _ in range(max(1, jobs))]
    for t in threads:
        t.start()
    try:
        while any(t.is_alive() for t in threads):
            time.sleep(0.5)
    except KeyboardInterrupt:
        say(f"study {sd.study.name}: stopping the runs (each writes a checkpoint)")
        stop_children()
        for t in threads:
            t.join(timeout=30)
        write_index(sd)
        say(f"study {sd.study.name}: interrupted; run the same command again to resume")
        return 130
    write_index(sd)
    print(f"study {sd.study.name}: {state['done']} of {len(points)} runs complete, {state['failed']} failed "
          f"in {fmt_time(time.time() - t_start)} -> {sd.dir}/index.toml", flush=True)
    for name, msg in failures:
        print(f"  failed: {name}: {msg}", flush=True)
    if state["failed"]:
        return 1
    return analyse(sd)


def analyse(sd):
    """The study analysis (analyse_study.py) once every run is complete:
    study.h5, figures/ and reproduction.md in the study directory."""
    script = os.path.join(ROOT, "launch_scripts", "analyse_study.py")
    print(f"study {sd.study.name}: analysing ({os.path.relpath(script, ROOT)} {sd.dir})", flush=True)
    rc = subprocess.run([sys.executable, script, sd.dir]).returncode
    if rc:
        print(f"study {sd.study.name}: the analysis failed (exit {rc}); the runs are complete, "
              f"run launch_scripts/analyse_study.sh {sd.dir} again after a fix", flush=True)
    return 1 if rc else 0


def run_slurm(sd, a):
    points = sd.study.points()
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
    if not todo:
        print(f"study {sd.study.name}: nothing to submit ({len(points)} runs complete or queued)")
        write_index(sd)
        return 0
    sdir = os.path.join(sd.dir, "slurm")
    os.makedirs(sdir, exist_ok=True)
    stamp = time.strftime("%Y%m%d-%H%M%S")
    listing = os.path.join(sdir, f"batch-{stamp}.txt")
    write_atomic(listing, "".join(sd.study.run_name(p) + "\n" for p in todo))
    me = os.path.abspath(__file__)
    common = []
    for flag, val in (("--partition", a.partition), ("--time", a.time), ("--mem", a.mem)):
        if val:
            common.append(f"#SBATCH {flag}={val}")
    common += [f"#SBATCH {x}" for x in a.sbatch]
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
    after = os.path.join(sdir, f"index-{stamp}.sbatch")
    write_atomic(after, "\n".join([
        "#!/bin/bash", f"#SBATCH --job-name=dynhet-{sd.study.name}-index",
        f"#SBATCH --output={sdir}/index-%j.out", *common,
        "# After every task: the study's index (and what must follow the runs).",
        f"exec /usr/bin/python3 {me} index {sd.dir} --analyse", ""]))
    r = subprocess.run(["sbatch", "--parsable", array], capture_output=True, text=True)
    if r.returncode != 0:
        raise StudyError(f"sbatch refused the job array: {r.stderr.strip()}")
    job = r.stdout.strip().split(";")[0]
    for p in todo:
        d = sd.run_dir(p)
        os.makedirs(d, exist_ok=True)
        st = read_status(d)
        st.update({"state": "queued", "job": job})
        for k in AXES:
            st[k] = p[k]
        write_status(d, st)
    r2 = subprocess.run(["sbatch", "--parsable", f"--dependency=afterany:{job}", after], capture_output=True,
                        text=True)
    if r2.returncode != 0:
        raise StudyError(f"sbatch refused the index job: {r2.stderr.strip()}")
    dep = r2.stdout.strip().split(";")[0]
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


def raise_interrupt(*_):
    raise KeyboardInterrupt


def main():
    signal.signal(signal.SIGTERM, raise_interrupt)
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("study")
    r.add_argument("--executor", choices=["local", "slurm"], default="local")
    r.add_argument("--jobs", type=int, default=0, help="runs at once (local: default the cores / 2, at least 1; "
                                                       "slurm: array tasks at once, default no limit)")
    r.add_argument("--out", help="study directory (default runs/study-<name>)")
    r.add_argument("--dry-run", action="store_true")
    r.add_argument("--partition")
    r.add_argument("--time")
    r.add_argument("--mem")
    r.add_argument("--signal-lead", type=float, default=300,
                   help="slurm: seconds before the time limit at which a task is told to checkpoint and stop "
                        "(sbatch --signal; a cut needs the sim to reach its next synchronised time), default 300")
    r.add_argument("--max-requeues", type=int, default=20,
                   help="slurm: a task interrupted by its time limit goes back in the queue at most this often")

    r.add_argument("--sbatch", action="append", default=[], help="extra sbatch flag, e.g. --sbatch=--qos=long")
    t = sub.add_parser("task")
    t.add_argument("dir")
    t.add_argument("name")
    i = sub.add_parser("index")
    i.add_argument("dir")
    i.add_argument("--analyse", action="store_true", help="then, if every run is complete, the study analysis")
    a = ap.parse_args()
    try:
        if a.cmd == "run":
            study = Study(a.study)
            sd = StudyDir(study, a.out or os.path.join(ROOT, "runs", f"study-{study.name}"))
            if a.dry_run:
                if os.path.exists(os.path.join(sd.dir, "study.toml")):
                    sd.claim()
                check_scenes(sd)
                dry_run(sd)
                return 0
            check_scenes(sd)
            sd.claim()
            if a.executor == "local":
                return run_local(sd, a.jobs or max(1, (os.cpu_count() or 2) // 2))
            return run_slurm(sd, a)
        sd = StudyDir(Study(os.path.join(a.dir, "study.toml"), os.path.join(a.dir, "base_scene.toml")), a.dir)
        if a.cmd == "task":
            return task(sd, a.name)
        rows = write_index(sd)
        states = {}
        for row in rows.values():
            states[row["state"]] = states.get(row["state"], 0) + 1
        print(f"study {sd.study.name}: " + ", ".join(f"{v} {k}" for k, v in sorted(states.items())))
        if set(states) != {"complete"}:
            return 1
        return analyse(sd) if a.analyse else 0
    except StudyError as e:
        print(f"run_study: {e}", file=sys.stderr)
        return 2


def check_scenes(sd):
    """Every point's scene through sim_node --check, before anything runs."""
    problems = []
    tmp = os.path.join("/tmp", f"dynhet-study-check-{os.getpid()}.toml")
    try:
        for p, sc, *_ in plan(sd):
            write_atomic(tmp, toml_dump(sc))
            r = subprocess.run([SIM, tmp, "--check"], capture_output=True, text=True)
            if r.returncode != 0:
                msg = " ".join(r.stderr.strip().replace(tmp, "scene").split())
                problems.append(f"{sd.study.run_name(p)}: {msg}")
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
    if problems:
        raise StudyError(f"{sd.study.path}: {len(problems)} of the study's scenes would be refused:\n  " +
                         "\n  ".join(problems))


if __name__ == "__main__":
    sys.exit(main())
