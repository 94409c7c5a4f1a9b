#!/usr/bin/python3
"""Are dynhet's error bars honest? For every quantity a run records with an
error, the spread between independent runs (seeds) of the same point against
the error the runs quote.

Reads a study directory (launch_scripts/run_study.sh): runs that differ only
in their seed are one point. Per quantity, pooled over points,

    ratio^2 = sum_points sum_seeds (x_i - mean_point)^2 / e_point^2 / sum_points (K - 1),

e_point the mean quoted error over the point's seeds: the ratio is the
seed-to-seed standard deviation over the mean quoted error, pooled. An
honest error gives about 1; its own uncertainty is ratio / sqrt(2 dof) (a
chi-square with dof = sum (K - 1) degrees of freedom), more where the
quoted errors scatter. Values without an
error (NaN) are counted, not pooled.

Usage: bench/seed_spread.py STUDY_DIR [STUDY_DIR ...] [--cutoff 0.6] [--points] [--markdown]
(--points: also one line per point and quantity).
"""
import argparse
import math
import os
import sys
import tomllib

import h5py
import numpy as np

AXES_BUT_SEED = ("packing_fraction", "restitution", "n_particles", "pairs")


def last(f, path):
    """The final record of an H5MD element (or a plain dataset)."""
    if path not in f:
        return None
    d = f[path]
    d = d["value"] if isinstance(d, h5py.Group) else d
    return np.asarray(d[-1] if d.shape and d.shape[0] > 0 else d[()], dtype=float)


def quantities(path, a):
    """{name: (value, error)} of one run.h5 (final records)."""
    out = {}
    with h5py.File(path, "r") as f:
        o = "observables"

        def pair(name, v, e):
            vv, ee = last(f, v), last(f, e)
            if vv is None or ee is None:
                return
            vv, ee = np.atleast_1d(vv), np.atleast_1d(ee)
            if vv.size == 1:
                out[name] = (float(vv[0]), float(ee[0]))
            else:
                for k in range(vv.size):
                    out[f"{name}[{k}]"] = (float(vv[k]), float(ee[k]))

        pair("tau_alpha", f"{o}/overlap/a{a}/tau_alpha", f"{o}/overlap/a{a}/tau_alpha_err")
        pair("beta", f"{o}/overlap/a{a}/beta", f"{o}/overlap/a{a}/beta_err")
        pair("tau0", f"{o}/overlap/a{a}/tau0", f"{o}/overlap/a{a}/tau0_err")
        pair("D", f"{o}/msd/diffusion", f"{o}/msd/diffusion_err")
        flow, flow_e = last(f, f"{o}/msd/diffusion_flow"), last(f, f"{o}/msd/diffusion_flow_err")
        if flow is not None and "D" in out:
            out["_D_flow"] = (float(flow), float(flow_e))
        pair("Z", f"{o}/sim/reduced_pressure", f"{o}/sim/reduced_pressure_err")
        pair("collision frequency", f"{o}/sim/collision_frequency", f"{o}/sim/collision_frequency_err")
        # chi4(t) of every sub-box size at the lag of its largest value
        # (the lag fixed per point below); records are [grid][lag], kept
        # here as [lag][size].
        c, ce = last(f, f"{o}/chi4/a{a}/chi4"), last(f, f"{o}/chi4/a{a}/chi4_err")
        sizes = f.get(f"{o}/chi4/a{a}/subbox_particles")
        if c is not None and sizes is not None:
            out["_chi4"] = (c.T, ce.T, np.asarray(sizes[()]))
        for k in ("chi4_peak", "tau4"):
            pair(k, f"{o}/chi4/a{a}/{k}", f"{o}/chi4/a{a}/{k}_err")
        pair("xi", f"{o}/s4/a{a}/xi", f"{o}/s4/a{a}/xi_err")
        pair("chi0", f"{o}/s4/a{a}/chi0", f"{o}/s4/a{a}/chi0_err")
        pair("chi4 box (S4 node)", f"{o}/s4/a{a}/chi4_box", f"{o}/s4/a{a}/chi4_box_err")
        pair("d_f slow", f"{o}/clusters/a{a}/slow_d_f", f"{o}/clusters/a{a}/slow_d_f_err")
        pair("d_f fast", f"{o}/clusters/a{a}/fast_d_f", f"{o}/clusters/a{a}/fast_d_f_err")
        pair("kappa", f"{o}/clusters/a{a}/slow_kappa", f"{o}/clusters/a{a}/slow_kappa_err")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("study_dir", nargs="+", help="one or more studies; runs of the same point in several studies "
                    "pool (their seeds must differ)")
    ap.add_argument("--cutoff", default="0.6")
    ap.add_argument("--points", action="store_true")
    ap.add_argument("--markdown", action="store_true", help="the table as markdown (for docs/analysis.md)")
    args = ap.parse_args()
    points, seen = {}, set()
    for study in args.study_dir:
        with open(os.path.join(study, "index.toml"), "rb") as f:
            runs = tomllib.load(f)["runs"]
        for name, r in runs.items():
            if r.get("state") != "complete":
                continue
            key = tuple(r.get(k) for k in AXES_BUT_SEED)
            if (key, r.get("seed")) in seen:
                sys.exit(f"seed_spread: seed {r.get('seed')} of {key} is in two studies; pool studies of different seeds")
            seen.add((key, r.get("seed")))
            points.setdefault(key, []).append(quantities(os.path.join(study, r["path"], "run.h5"), args.cutoff))
    points = {k: v for k, v in points.items() if len(v) >= 2}
    if not points:
        sys.exit("seed_spread: no point with two or more complete seeds")
    # chi4(t) at the lag of the point's largest mean, per size.
    for runs_ in points.values():
        if not all("_chi4" in q for q in runs_):
            continue
        mean = np.mean([q["_chi4"][0] for q in runs_], axis=0)
        sizes = runs_[0]["_chi4"][2]
        for s in range(mean.shape[1]):
            j = int(np.nanargmax(mean[:, s])) if np.isfinite(mean[:, s]).any() else 0
            for q in runs_:
                q[f"chi4 at its peak lag, N_box {sizes[s]:.0f}"] = (q["_chi4"][0][j, s], q["_chi4"][1][j, s])
    names = []
    for runs_ in points.values():
        for q in runs_:
            for n in q:
                if not n.startswith("_") and n not in names:
                    names.append(n)
    print(f"studies {', '.join(os.path.abspath(d) for d in args.study_dir)}: {len(points)} points, "
          f"{sum(len(v) for v in points.values())} runs (seeds per point: "
          f"{sorted(set(len(v) for v in points.values()))})")
    print(f"{'quantity':44s} {'points':>6s} {'dof':>5s} {'spread/error':>13s} {'+-':>6s} {'no error':>8s}")
    rows, md = [], []
    for n in names:
        num, dof, nan, used = 0.0, 0, 0, 0
        for key, runs_ in points.items():
            vals = [q[n] for q in runs_ if n in q]
            ok = [(v, e) for v, e in vals if math.isfinite(v) and math.isfinite(e) and e > 0]
            nan += len(vals) - len(ok)
            if len(ok) < 2:
                continue
            x = np.array([v for v, _ in ok])
            e2 = np.mean([e for _, e in ok]) ** 2
            num += np.sum((x - x.mean()) ** 2) / e2
            dof += len(ok) - 1
            used += 1
            if args.points:
                print(f"   {n} {key}: values {np.round(x, 5).tolist()}, sd {x.std(ddof=1):.4g}, "
                      f"quoted {math.sqrt(e2):.4g}")
        if dof == 0:
            print(f"{n:44s} {used:6d} {dof:5d} {'-':>13s} {'':>6s} {nan:8d}")
            continue
        r = math.sqrt(num / dof)
        rows.append((n, r))
        flag = "" if 0.7 <= r <= 1.5 else "  <- outside 0.7-1.5"
        print(f"{n:44s} {used:6d} {dof:5d} {r:13.3f} {r / math.sqrt(2 * dof):6.2f} {nan:8d}{flag}")
        md.append(f"| {n} | {dof} | {r:.2f} +- {r / math.sqrt(2 * dof):.2f} | {nan} |")
    if args.markdown:
        print("\n| quantity | dof | spread / mean error | runs without an error |\n|---|---|---|---|")
        print("\n".join(md))
    flow_report(points)


def flow_report(points):
    """D's flow part (docs/analysis.md, "D and the long-lived flows"): per
    point, its share of D, and the spread of D and of D - D_flow over the
    error without the flows' part (the jackknife's)."""
    lines = []
    for key, runs_ in points.items():
        ok = [q for q in runs_ if "_D_flow" in q and all(map(math.isfinite, q["D"] + q["_D_flow"]))]
        if len(ok) < 2:
            continue
        d = np.array([q["D"][0] for q in ok])
        fl = np.array([q["_D_flow"][0] for q in ok])
        jk = np.mean([math.sqrt(max(q["D"][1] ** 2 - q["_D_flow"][1] ** 2, 0.0)) for q in ok])
        tot = np.mean([q["D"][1] for q in ok])
        lines.append(f"  {key}: D {d.mean():.4g}, D_flow {fl.mean():.4g} ({fl.mean() / d.mean():.0%}); "
                     f"spread of D / jackknife error {d.std(ddof=1) / jk:.2f}, of D - D_flow {np.std(d - fl, ddof=1) / jk:.2f}; "
                     f"spread of D / quoted error {d.std(ddof=1) / tot:.2f}")
    if lines:
        print("D's flow part per point (packing fraction, restitution, N, pairs):")
        print("\n".join(lines))


if __name__ == "__main__":
    main()
