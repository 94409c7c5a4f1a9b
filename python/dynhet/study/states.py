"""Prepared and equilibrated states shared by runs, and the pilots that measure tau_alpha."""
import fcntl
import hashlib
import json
import math
import os
import re
import time

from .paths import SIM
from ..scene import default
from .toml_io import toml_dump, write_atomic
from .model import StudyError, StudyInterrupted
from .rundir import read_status, run_h5_result, write_status
from .children import STOPPING, call_child, run_scene
from .archiving import archive_pilot, restored_pilot


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
           f"_r{float(sy.get('radius_ratio', default('system', 'radius_ratio'))):.6g}"
           f"_seed{int(sy.get('seed', default('system', 'seed')))}")
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
    interval = float(sc.get("run", {}).get("checkpoint_interval", default("run", "checkpoint_interval")))
    dyn = toml_dump({"system": sy, "driving": sc.get("driving", {}), "run": {"checkpoint_interval": interval}})
    key = (f"eq_n{int(sy['n_particles'])}_phi{float(sy['packing_fraction']):.6g}"
           f"_eps{float(sy.get('restitution', default('system', 'restitution'))):.6g}"
           f"_seed{int(sy.get('seed', default('system', 'seed')))}_"
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


def pilot_system_key(sc):
    """What a pilot simulates, as a hash: its scene without the run lengths
    ([run], [schedule]) and the prepared state's path. Two pilots with one
    key run the same system from the same state and measure the same
    tau_alpha."""
    phys = {k: v for k, v in sc.items() if k not in ("run", "schedule")}
    phys["system"] = {k: v for k, v in sc.get("system", {}).items() if k != "initial_state"}
    return hashlib.sha1(json.dumps(phys, sort_keys=True).encode()).hexdigest()[:16]


def same_system_pilot(sd, name, key, unit):
    """(name, status) of a complete pilot of another series that ran the
    system with this key (from the study directory, or from the archive on
    a machine that lost the directory), or None. A pilot from before keys
    were recorded is judged by its scene.toml."""
    from .toml_io import read_toml
    found = {}
    if sd.archive is not None:
        found.update(sd.archive.read()["pilots"])
    pdir = os.path.join(sd.dir, "pilots")
    for other in sorted(os.listdir(pdir)) if os.path.isdir(pdir) else []:
        st = read_status(os.path.join(pdir, other))
        if st.get("state") == "complete" and "system_key" not in st:
            try:
                st = dict(st, system_key=pilot_system_key(read_toml(os.path.join(pdir, other, "scene.toml"))))
            except (OSError, ValueError):
                continue
        found[other] = st
    for other, st in sorted(found.items()):
        if (other != name and st.get("state") == "complete" and st.get("system_key") == key
                and st.get("unit", sd.study.run_length["unit"]) == unit and math.isfinite(st.get("tau_alpha", math.nan))
                and not st.get("reused_from")):
            return other, st
    return None


def pilot(sd, p, unit=None):
    """tau_alpha of p (unit: "tau_alpha" or "tau_alpha_cr", default the
    study's run_length.unit) from a short, small run of its series; cached
    per point (not per seed)."""
    st = sd.study
    unit = unit or st.run_length["unit"]
    name = f"phi{p['packing_fraction']:.4f}_eps{p['restitution']:.3f}_n{p['n_particles']}_{p['pairs']}"
    if unit != st.run_length["unit"]:
        name += "_" + unit  # the equilibration's pilot (run_length.equilibration_unit)
    d = os.path.join(sd.dir, "pilots", name)
    os.makedirs(d, exist_ok=True)
    # Other seeds of the point (threads here, or Slurm tasks elsewhere) wait
    # for the one pilot instead of running it again in the same directory.
    with open(os.path.join(d, ".lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        return pilot_locked(sd, p, name, d, unit)


def pilot_locked(sd, p, name, d, unit):
    st = sd.study
    old = read_status(d)
    if old.get("state") == "complete":
        return old["tau_alpha"]
    kept = restored_pilot(sd, name, d)  # the archive's: the same tau_alpha, not simulated again
    if kept is not None:
        return kept["tau_alpha"]
    # The same pilot whichever seed of the point comes first (the first
    # seed's), and whatever else has finished (its first guess only from the
    # study file): the pilot, and so the run, is a function of the point.
    p = dict(p, seed=st.axes.get("seed", [st.base_value("seed")])[0])
    own = unit == st.run_length["unit"]
    g, _ = sd.guess(p, finished=False, table="tau_guess" if own else "tau_guess_cr")
    key = pilot_system_key(st.scene(p, g, pilot=True, unit=unit))
    same = same_system_pilot(sd, name, key, unit)
    if same is not None:
        # Another series' pilot ran this very system (a pilot runs min(N,
        # run_length.pilot_particles) particles, so the series of every N
        # above that share one): its tau_alpha, not the same run again.
        other, st_other = same
        done = {"state": "complete", "tau_alpha": st_other["tau_alpha"], "guess": st_other.get("guess", g),
                "attempts": 0, "packing_fraction": p["packing_fraction"], "series": list(st.series_key(p)),
                "wall_s": 0.0, "cpu_s": 0.0, "unit": unit, "system_key": key, "reused_from": other}
        write_status(d, done)
        archive_pilot(sd, name, done)
        return done["tau_alpha"]
    spent_wall = spent_cpu = 0.0  # over every attempt: what the pilot cost
    for attempt in range(1, 7):
        sc = st.scene(p, g, pilot=True, unit=unit)
        prepared_state(sd, sc)
        write_atomic(os.path.join(d, "scene.toml"), toml_dump(sc, f"# pilot of {name}, tau guess {g:.6g}"))
        # A later attempt runs its longer scene from the start (run_scene.sh
        # --fresh): on the same directory it would find the earlier attempt's
        # complete run.h5 and run nothing, and its tau_alpha would be the
        # earlier, too short attempt's.
        rc, wall, cpu = run_scene(os.path.join(d, "scene.toml"), d, os.path.join(d, "run_scene.log"),
                                  fresh=attempt > 1, plots=st.run_plots)
        spent_wall, spent_cpu = spent_wall + wall, spent_cpu + cpu
        if STOPPING.is_set():
            raise StudyInterrupted(f"pilot of {name} stopped")
        complete, tau = run_h5_result(os.path.join(d, "run.h5"), st.first_cutoff(sc), st.tau_group(unit))
        if rc != 0 or not complete:
            write_status(d, {"state": "failed", "exit": rc, "message": f"pilot run failed; log {d}/run_scene.log"})
            raise StudyError(f"pilot of {name} failed (exit {rc}); its log: {d}/run_scene.log")
        if math.isfinite(tau) and tau <= g:
            key = st.series_key(p)
            done = {"state": "complete", "tau_alpha": tau, "guess": g, "attempts": attempt,
                    "packing_fraction": p["packing_fraction"], "series": list(key), "wall_s": spent_wall, "cpu_s": spent_cpu,
                    "unit": unit, "system_key": pilot_system_key(sc)}
            write_status(d, done)
            archive_pilot(sd, name, done)
            return tau
        g = 4 * g if not math.isfinite(tau) else 1.3 * tau
    raise StudyError(f"pilot of {name}: tau_alpha not found after 6 attempts")
