#!/usr/bin/python3
"""Checks a dynhet run file: the H5MD layout, the scene, the frames, no
loss, and the recorded Q(t) and tau_alpha against a brute-force
recomputation from the recorded frames.

Usage: check_run.py RUN.h5 SCENE.toml
"""
import math
import sys

import h5py
import numpy as np

failures = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        failures.append(what)


def crossing_time(t, q, level):
    """Same definition as the node: first downward crossing, linear in ln t."""
    prev = None
    for j in range(len(q)):
        if math.isnan(q[j]):
            continue
        if q[j] < level:
            if prev is None:
                return math.nan
            f = (q[prev] - level) / (q[prev] - q[j])
            return math.exp(math.log(t[prev]) + f * (math.log(t[j]) - math.log(t[prev])))
        prev = j
    return math.nan


def check_msd(f, unwrapped, origin_frame, pair_frame, lag):
    """Delta(t) = <|r(t0+t) - r(t0)|^2> over particles (all, small), then over origins; D by brute force."""
    species = f["particles/all/species"][()]
    g = f["observables/msd"]
    d2 = np.array([[np.sum((unwrapped[pf] - unwrapped[of]) ** 2, axis=1) for pf in pair_frame[k]]
                   for k, of in enumerate(origin_frame)])  # origin, lag, particle
    for name, sel in (("msd_all", slice(None)), ("msd_small", species == 0)):
        bf = d2[:, :, sel].mean(axis=2).mean(axis=0)
        rec = g[name]["value"][-1]
        err = np.max(np.abs(rec - bf) / bf)
        check(err < 1e-12, f"msd: {name} equals brute force (max rel diff {err:.2g})")
    D, t_min, t_max = (float(g[k]["value"][-1]) for k in ("diffusion", "fit_t_min", "fit_t_max"))
    if math.isfinite(D):
        bf = d2.mean(axis=2).mean(axis=0)
        sel = (lag >= t_min) & (lag <= t_max)
        slope = np.polyfit(lag[sel], bf[sel], 1)[0]
        check(abs(D - slope / 4) <= 1e-9 * abs(D), f"msd: D = {D:.5g} is the slope/4 over [{t_min:.3g}, {t_max:.3g}]")
    else:
        check(False, "msd: no diffusion coefficient")


def check_chi4(f, unwrapped, L, origin_frame, pair_frame):
    """chi4(t) = mean over origins of N [<Q_r^2> - <Q_r>^2] (paper eq. 14), by brute force;
    for the whole box N_tot times the variance of Q over origins."""
    n = unwrapped.shape[1]
    for name, g in f["observables/chi4"].items():
        a = float(g.attrs["cutoff_a"])
        sides = g["subbox_per_side"][()]
        n_lags = len(g["lag_time"][()])
        rec = g["chi4"]["value"][-1].reshape(len(sides), n_lags)
        for gi, m in enumerate(sides):
            N = n / (m * m)
            chi = np.zeros(n_lags)
            per_origin = []
            for k, of in enumerate(origin_frame):
                x0 = unwrapped[of] % L
                box = (np.minimum((x0[:, 1] // (L / m)).astype(int), m - 1) * m
                       + np.minimum((x0[:, 0] // (L / m)).astype(int), m - 1))
                row = []
                for j, pf in enumerate(pair_frame[k]):
                    slow = np.hypot(*(unwrapped[pf] - unwrapped[of]).T) < a
                    q_r = np.bincount(box, weights=slow, minlength=m * m) / N
                    row.append((q_r.mean(), N * q_r.var()))
                per_origin.append(row)
            per_origin = np.array(per_origin)  # origin, lag, (Q, chi4 term)
            if m == 1:
                chi = n * per_origin[:, :, 0].var(axis=0, ddof=1)
            else:
                chi = per_origin[:, :, 1].mean(axis=0)
            err = np.max(np.abs(chi - rec[gi]) / np.maximum(np.abs(chi), 1e-12))
            check(err < 1e-9, f"chi4 {name} m={m}: equals brute force (max rel diff {err:.2g})")


def main(path, scene_path):
    f = h5py.File(path, "r")
    check(list(f["h5md"].attrs["version"]) == [1, 1], "h5md version 1.1")
    check("name" in f["h5md/creator"].attrs, "h5md creator")
    text = f["parameters/scene_toml"][()]
    text = text.decode() if isinstance(text, bytes) else str(text)
    check(text == open(scene_path).read(), "parameters/scene_toml is the scene file")
    check(int(f.attrs.get("complete", 0)) == 1, "file marked complete")

    box = f["particles/all/box"]
    check(int(box.attrs["dimension"]) == 2, "box is 2D")
    L = float(box["edges"][0])
    pos = f["particles/all/position/value"][()]
    img = f["particles/all/image/value"][()]
    unwrapped = pos + img * L
    sched = f["observables/schedule"]
    frame_time = sched["frame_time"][()]
    origin_frame = sched["origin_frame"][()]
    pair_frame = sched["pair_frame"][()]
    lag = sched["lag_time"][()]
    n_frames, n, _ = pos.shape
    check(n_frames == len(frame_time), f"all {len(frame_time)} frames recorded")
    check(np.allclose(f["particles/all/position/time"][()], frame_time, rtol=0, atol=1e-9), "frame times")
    check(np.all((pos >= 0) & (pos < L)), "positions folded into the box")

    nodes = f["observables/nodes/overlap"]
    check(int(nodes["frames_lost"]["value"][-1]) == 0, "overlap node lost no frame")
    check(int(nodes["frames_whole"]["value"][-1]) == n_frames, "overlap node got every frame whole")

    pair_frame = pair_frame.reshape(len(origin_frame), len(lag))
    for name, g in f["observables/overlap"].items():
        a = float(g.attrs["cutoff_a"])
        q_rec = g["q"]["value"][-1]
        # Brute force: Q(t;t0) = <Q_r> = fraction of particles that moved less than a.
        q_k = np.array([[np.mean(np.hypot(*(unwrapped[pf] - unwrapped[of]).T) < a)
                         for pf in pair_frame[k]] for k, of in enumerate(origin_frame)])
        q_bf = q_k.mean(axis=0)
        err = np.max(np.abs(q_bf - q_rec))
        check(err < 1e-12, f"{name}: Q(t) equals brute force (max diff {err:.2g})")
        tau = float(g["tau_alpha"]["value"][-1])
        tau_bf = crossing_time(lag, q_bf, math.exp(-1))
        check(math.isfinite(tau) and abs(tau - tau_bf) <= 1e-9 * tau_bf,
              f"{name}: tau_alpha {tau:.6g} (brute force {tau_bf:.6g})")
        check(np.all(np.diff(q_bf) <= 0.05), f"{name}: Q(t) decays")
        tau_t0 = g["tau_alpha_t0"]["value"][-1]
        tau_t0_bf = np.array([crossing_time(lag, q_k[k], math.exp(-1)) for k in range(len(origin_frame))])
        same = np.allclose(tau_t0, tau_t0_bf, rtol=1e-9, atol=0, equal_nan=True)
        check(same, f"{name}: tau_alpha(t0) per origin equals brute force")
        beta, tau0 = float(g["beta"]["value"][-1]), float(g["tau0"]["value"][-1])
        # The fit (unweighted here: early lags have zero error) is a least-squares
        # minimum: nudging either parameter by 0.1% does not lower the residual.
        def sse(b_, t_):
            return np.sum((q_bf - 1 / ((lag / t_) ** b_ + 1)) ** 2)
        best = sse(beta, tau0)
        nudged = min(sse(beta * f1, tau0 * f2) for f1 in (0.999, 1, 1.001) for f2 in (0.999, 1, 1.001)
                     if (f1, f2) != (1, 1))
        check(best <= nudged * (1 + 1e-9), f"{name}: fit beta={beta:.4g} tau0={tau0:.4g} is a least-squares minimum")
    if "observables/chi4" in f:
        check_chi4(f, unwrapped, L, origin_frame, pair_frame)
    if "observables/msd" in f:
        check_msd(f, unwrapped, origin_frame, pair_frame, lag)
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
