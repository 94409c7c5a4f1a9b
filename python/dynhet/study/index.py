"""The study's index (index.toml), its plan and the dry run."""
import fnmatch
import os

from .. import schema
from ..scene import resolved
from .toml_io import toml_value, write_atomic
from .model import AXES, StudyError
from .estimates import estimate, fmt_time
from .progress import sim_progress
from .rundir import read_status
from .runner import effective_state, resume_from


def write_index(sd):
    rows = {}
    for p in sd.study.points():
        st = read_status(sd.run_dir(p))
        row = {a: p[a] for a in AXES}
        row["path"] = os.path.relpath(sd.run_dir(p), sd.dir)
        row["state"] = st.get("state", "pending")
        for k in ("tau_estimate", "tau_source", "tau_alpha", "wall_s", "cpu_s", "cpu_unrecorded", "attempts", "requeues",
                  "message", "archived"):
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
        st = sd.status(p)
        if sd.study.run_length["tau_alpha"] == "scene":
            tau, src = None, "scene"
        elif st.get("tau_estimate") and st.get("state") != "too_short":
            tau, src = st["tau_estimate"], st.get("tau_source", "?")
        else:
            tau, src = sd.guess(p)
            src = f"guess: {src}"
            if sd.study.run_length["tau_alpha"] == "pilot" and tau is not None:  # the run: its pilot's tau x margin
                m = sd.study.run_length["pilot_margin"]
                tau *= m
                src += f" x {m:g}; a pilot will measure it" if m != 1.0 else "; a pilot will measure it"
        out.append((p, sd.study.scene(p, tau, tau_eq=planned_tau_eq(sd, p, st, tau)), tau, src, st.get("state", "pending")))
    return out


def planned_tau_eq(sd, p, st, tau):
    """The tau the equilibration counts in, as known now (with
    run_length.equilibration_unit other than unit): the run's own estimate,
    its pilot's, or the study's tau_guess_cr times the margin."""
    study = sd.study
    if tau is None or not study.split_units():
        return None
    if st.get("tau_eq_estimate") and st.get("state") != "too_short":
        return st["tau_eq_estimate"]
    g, _ = sd.guess(p, finished=False, table="tau_guess_cr")
    return study.run_length["pilot_margin"] * g


def run_estimates(sd):
    """{run name: estimated CPU seconds} from the estimates known now."""
    return estimates_whole_and_left(sd)[0]


def run_estimates_left(sd):
    """{run name: estimated CPU seconds still to run} (estimates_whole_and_left)."""
    return estimates_whole_and_left(sd)[1]


def estimates_whole_and_left(sd):
    """({run name: estimated CPU seconds}, {run name: what is still to run}),
    from one pass over the plan. What is left is the estimate less the share
    of its simulated time that a stopped run resumes past (what do_run
    resumes it from: its newest checkpoint cut, about where its sim's last
    progress line was; its checkpoint before the frames, the end of
    equilibration; nothing, the start), so that an order by length puts a
    run that is nearly through ahead of a fresh one of the same size, and
    one that will start over where a fresh one would be."""
    whole, left = {}, {}
    for p, sc, *_ in plan(sd):
        d, run, name = sd.run_dir(p), resolved(sc)["run"], sd.study.run_name(p)
        state = effective_state(read_status(d))
        how, total = resume_from(d, state), run["equilibration_time"] + run["production_time"]
        done = (share_done(d, "interrupted", total) if how == "cut"
                else run["equilibration_time"] / total if how and total > 0 else 0.0)
        whole[name] = estimate(sc, nodes_of(sc))[0]
        left[name] = whole[name] * (1 - done)
    return whole, left


def run_order(sd, todo, est, order="longest", first=()):
    """The order the executors take runs in (the local pool, and the Slurm
    array's task indices, which a throttled array starts in order). With
    interpolated run lengths the low densities first (the rest interpolate
    from them). Otherwise, by default, the longest estimated run first, so
    that the longest run, which sets the study's wall time on a few cores,
    does not start last behind the short ones (longest-processing-time
    first); with order "shortest" the shortest first, so that the most runs
    are complete (and archived) by any moment, where the machine may be
    lost before the study ends. est is what each run has still to run
    (run_estimates_left: an interrupted run counts what its checkpoint has
    not done). Equal estimates keep the study's order.
    The runs whose names match a pattern of first (shell globs) go before all
    others, those of the first pattern first (each group in that order):
    the runs a result waits for, ahead of the rest. Within each group (and
    before the densities' order with interpolated lengths) the
    runs that resume past their start (a checkpoint cut, or their state
    before the frames) go before those that start afresh: the CPU they
    have had becomes an archived result soonest, on a machine that may be
    lost, and their checkpoints leave the disk."""
    def afresh(p):
        d = sd.run_dir(p)
        return resume_from(d, effective_state(read_status(d))) is None
    if sd.study.run_length["tau_alpha"] == "interpolate":
        if first:
            raise StudyError(f"--first: study {sd.study.name} interpolates its run lengths (tau_alpha = "
                             "\"interpolate\"), so its lower densities must run first; give it no --first")
        return sorted(todo, key=lambda p: (afresh(p), p["packing_fraction"]))  # a resumed run's length is set
    names = [sd.study.run_name(p) for p in sd.study.points()]
    for pat in first:
        if not fnmatch.filter(names, pat):
            raise StudyError(f"--first {pat!r} matches none of study {sd.study.name}'s {len(names)} runs "
                             f"(names like {names[0]})")
    sign = {"longest": -1.0, "shortest": 1.0}[order]

    def group(p):
        name = sd.study.run_name(p)
        return next((i for i, pat in enumerate(first) if fnmatch.fnmatchcase(name, pat)), len(first))
    return sorted(todo, key=lambda p: (group(p), afresh(p), sign * est.get(sd.study.run_name(p), 0.0)))


def nodes_of(sc):
    """How many analysis nodes scene sc starts (each observable's declared node)."""
    return len({schema.declaration(c)["node"] for c in resolved(sc)["observables"]["compute"]})


def measured_ratio(done):
    """[(N, estimated CPU s, measured CPU s)] of complete runs -> {N: measured
    / estimated} per N, and the ratio over all of them (None without data).
    The engine's estimate leaves out the nodes, the recorder and the start of
    every process, which weigh most at small N."""
    per = {}
    for n, est, got in done:
        a = per.setdefault(n, [0.0, 0.0])
        a[0] += est
        a[1] += got
    ratios = {n: g / e for n, (e, g) in per.items() if e > 0}
    e_all, g_all = sum(e for e, _ in per.values()), sum(g for _, g in per.values())
    return ratios, (g_all / e_all if e_all > 0 else None)


def share_done(run_dir, state, sim_time):
    """The share of a running or interrupted run's simulated time (equilibration
    and production, one clock from 0) that its sim's last progress line has
    passed; 0 for any other state (a failed run starts over)."""
    if state not in ("running", "interrupted"):
        return 0.0
    p = sim_progress(run_dir)
    total = sim_time
    return min(1.0, max(0.0, p["t"] / total)) if p and total > 0 else 0.0


def dry_run(sd):
    rows = plan(sd)
    costs = [(p, sc, tau, src, state, *estimate(sc, nodes_of(sc)), sd.status(p).get("cpu_s"))
             for p, sc, tau, src, state in rows]
    done = [(sc["system"]["n_particles"], cpu, float(got)) for _, sc, _, _, state, cpu, _, got in costs
            if state == "complete" and got]
    ratios, overall = measured_ratio(done)
    print(f"# study {sd.study.name}: {len(rows)} runs; times from the tau_alpha estimates known now; "
          "CPU time from the engine's measured speed (docs/engine.md)"
          + (", times the measured CPU over that estimate of the complete runs (per N where some of that N "
             "are complete, else over all); complete runs at their measured CPU" if overall else ""))
    print(f"{'run':44s} {'state':9s} {'N':>8s} {'tau_est':>9s} {'t_equil':>9s} {'t_prod':>9s} "
          f"{'cpu':>9s} {'memory':>8s}  tau from")
    tot_cpu = left_cpu = engine_cpu = 0.0
    peak = 0.0
    for p, sc, tau, src, state, cpu, mem, got in costs:
        n = sc["system"]["n_particles"]
        engine_cpu += cpu
        if state == "complete" and got:
            cpu = float(got)
        else:
            cpu *= ratios.get(n, overall or 1.0)
        run = resolved(sc)["run"]
        t_eq, prod = run["equilibration_time"], run["production_time"]
        tot_cpu += cpu
        left_cpu += 0 if state == "complete" else cpu * (1 - share_done(sd.run_dir(p), state, t_eq + prod))
        peak = max(peak, mem)
        print(f"{sd.study.run_name(p):44s} {state:9s} {n:8d} "
              f"{(f'{tau:.4g}' if tau else '-'):>9s} {t_eq:9.4g} "
              f"{prod:9.4g} {fmt_time(cpu):>9s} {mem / 2**20:7.0f}M  {src}")
    if overall:
        print("# measured CPU over the engine's estimate, complete runs: "
              + ", ".join(f"N {n}: {r:.2f}" for n, r in sorted(ratios.items())) + f"; all: {overall:.2f}")
    print(f"# total CPU {fmt_time(tot_cpu)} ({tot_cpu / 3600:.2f} CPU-hours), left {fmt_time(left_cpu)} "
          "(a running or interrupted run less the share of its simulated time its sim has passed); "
          + (f"the engine's estimate alone {engine_cpu / 3600:.2f} CPU-hours; " if overall else "")
          + f"largest run {peak / 2**20:.0f} MiB (pilots not counted)")
