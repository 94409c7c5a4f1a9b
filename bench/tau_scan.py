#!/usr/bin/python3
"""tau_alpha against phi for one driving rule and restitution, by real runs
(launch_scripts/run_scene.sh: sim_node, overlap_node and the recorder on a
private bus), with run lengths scaled to tau_alpha. Resumable: a point
whose accepted result is on disk is skipped, so the same command goes on
where a killed one stopped.

Each point runs with a guess g of tau_alpha: equilibration 10 g, 8 origins
every g, lags from 0.02 g to 4 g. The first guess is --first-guess, later
ones extrapolate ln tau_alpha linearly in phi from the points before. A
run is accepted when Q(t) fell through 1/e and tau_alpha <= g (so the
equilibration was at least 10 tau_alpha and the lags reach 4 tau_alpha);
otherwise it is run again with g = 1.3 tau_alpha (or 4 g if Q never fell
through 1/e). Nothing here knows the paper's numbers.

Usage: bench/tau_scan.py --pairs neighbours --eps 0.9 --phi 0.60,0.70,... --out DIR
         [--n 8192] [--seed 1] [--first-guess 1.0] [--reach 1.0]
Writes DIR/<pairs>_eps<eps>/phi<phi>/{scene.toml,run.h5,...,result.toml}
and prints one line per point.
"""
import argparse
import math
import os
import subprocess
import sys

import numpy as np

import dynhet
import dynhet.scene

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def scene_text(a, phi, guess, origins=8):
    return f"""# bench/tau_scan.py: tau_alpha(phi), run lengths from a guess of tau_alpha = {guess:.6g}
[system]
n_particles = {a.n}
packing_fraction = {phi}
restitution = {a.eps}
seed = {a.seed}

[driving]
pairs = "{a.pairs}"
reach = {a.reach}

[run]
equilibration_time = {10 * guess:.6g}
checkpoint_interval = {max(10.0, guess):.6g}

[schedule]
origins = {origins}
origin_spacing = {guess:.6g}
lag_min = {0.02 * guess:.6g}
lag_max = {4 * guess:.6g}
lags_per_decade = 8

[observables]
compute = ["overlap"]
cutoff_a = [{dynhet.scene.default("observables", "cutoff_a")[0]}]
"""


def read_run(path, t_eq):
    """(complete, tau_alpha, its error, the mean kinetic energy after t_eq)
    of a run, through the package's reader (the scene's cutoff)."""
    with dynhet.open_run(path, allow_incomplete=True) as run:
        tau, tau_err = run.tau_alpha()
        t, v = run.observable("sim").history("kinetic_energy")
        v = np.asarray(v, float).ravel()
        sel = t >= t_eq
        temp = float(np.mean(v[sel])) if sel.any() else float("nan")
        return int(run.complete), tau, tau_err, temp


def read_result(path):
    out = {}
    with open(path) as f:
        for line in f:
            if "=" in line:
                k, v = (s.strip() for s in line.split("=", 1))
                out[k] = v.strip('"')
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--pairs", choices=["neighbours", "any"], required=True)
    p.add_argument("--eps", type=float, required=True)
    p.add_argument("--phi", required=True, help="comma-separated, in increasing order")
    p.add_argument("--out", required=True)
    p.add_argument("--n", type=int, default=8192)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--reach", type=float, default=1.0)
    p.add_argument("--first-guess", type=float, default=1.0)
    p.add_argument("--max-guess", type=float, default=5000.0, help="give a point up beyond this guess")
    a = p.parse_args()
    phis = [float(x) for x in a.phi.split(",")]
    base = os.path.join(a.out, f"{a.pairs}_eps{a.eps:g}")
    os.makedirs(base, exist_ok=True)
    done = []  # (phi, tau) accepted so far
    print(f"# tau_scan {a.pairs} eps={a.eps:g} N={a.n} seed={a.seed}: phi tau_alpha tau_err T guess runs", flush=True)
    for phi in phis:
        d = os.path.join(base, f"phi{phi:.4f}")
        os.makedirs(d, exist_ok=True)
        res_path = os.path.join(d, "result.toml")
        if os.path.exists(res_path):
            r = read_result(res_path)
            if r.get("accepted") == "true":
                done.append((phi, float(r["tau_alpha"])))
                print(f"{phi:.4f} {float(r['tau_alpha']):.5g} {float(r['tau_alpha_err']):.3g} "
                      f"{float(r['temperature']):.4f} {float(r['guess']):.4g} (done before)", flush=True)
                continue
        if len(done) >= 2:
            (p0, t0), (p1, t1) = done[-2], done[-1]
            guess = math.exp(math.log(t1) + (math.log(t1) - math.log(t0)) / (p1 - p0) * (phi - p1))
        elif done:
            guess = 2 * done[-1][1]
        else:
            guess = a.first_guess
        guess = max(guess, 0.5)
        runs = 0
        while True:
            runs += 1
            with open(os.path.join(d, "scene.toml"), "w") as f:
                f.write(scene_text(a, phi, guess))
            log = open(os.path.join(d, "run_scene.out"), "w")
            rc = subprocess.call(["bash", os.path.join(ROOT, "launch_scripts/run_scene.sh"),
                                  os.path.join(d, "scene.toml"), "--no-build", "--out", d],
                                 stdout=log, stderr=subprocess.STDOUT)
            try:
                complete, tau, tau_err, temp = read_run(os.path.join(d, "run.h5"), 10 * guess)
            except Exception as e:  # noqa: BLE001 - report and stop this point
                print(f"{phi:.4f} failed: run_scene exit {rc}, {e}", flush=True)
                break
            accepted = rc == 0 and complete == 1 and math.isfinite(tau) and tau <= guess
            with open(res_path, "w") as f:
                f.write(f'pairs = "{a.pairs}"\neps = {a.eps}\nphi = {phi}\nn_particles = {a.n}\nseed = {a.seed}\n'
                        f"guess = {guess}\ntau_alpha = {tau}\ntau_alpha_err = {tau_err}\ntemperature = {temp}\n"
                        f"complete = {complete}\nexit = {rc}\nruns = {runs}\n"
                        f"accepted = {'true' if accepted else 'false'}\n")
            if accepted:
                done.append((phi, tau))
                print(f"{phi:.4f} {tau:.5g} {tau_err:.3g} {temp:.4f} {guess:.4g} {runs}", flush=True)
                break
            if rc != 0 or complete != 1:
                print(f"{phi:.4f} failed: run_scene exit {rc}, complete {complete}; see {d}", flush=True)
                break
            guess = 4 * guess if not math.isfinite(tau) else 1.3 * tau
            if guess > a.max_guess:
                print(f"{phi:.4f} given up: tau_alpha beyond {a.max_guess}", flush=True)
                break
            print(f"#   {phi:.4f}: tau_alpha {tau:.4g} against guess; again with guess {guess:.4g}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
