#!/usr/bin/python3
"""The bond breaking of a run with kept frames (observables compute
"bond_breaking") against a brute-force recomputation from its frames: every
pair i < j of the origin frame by the minimum image is a bond when
r_ij < a1 sigma_ij, broken at t0 + t when |b_ij + dr_j - dr_i| > a2 sigma_ij
(dr unwrapped); C_B(t) the unbroken fraction averaged over origins; chi_B per
sub-box grid N_r times the variance (n - 1) of C_B,r over every sub-box of
every origin, C_B,r of the bonds whose first particle was in sub-box r at t0
(1 where a box has none); tau_B where C_B crosses 1/e.

Usage: check_bond_breaking.py RUN.h5
"""
import math
import sys

import h5py
import numpy as np

# The checks and tau's crossing as check_run.py has them (one list of failures).
from check_run import check, crossing_time, failures  # noqa: E402


def main(path):
    f = h5py.File(path, "r")
    obs = f["observables"]
    check("bond_breaking" in obs, "bond_breaking recorded")
    g = obs["bond_breaking"]
    a1, a2 = float(g.attrs["a1"]), float(g.attrs["a2"])
    L = float(f["particles/all/box/edges"][0])
    unwrapped = f["particles/all/position/value"][()] + f["particles/all/image/value"][()] * L
    species = f["particles/all/species"][()]
    radius = f["parameters/run_info"].attrs["radius"]
    sched = obs["schedule"]
    origin_frame, pair_frame, lag = sched["origin_frame"][()], sched["pair_frame"][()], sched["lag_time"][()]
    nk, nj = pair_frame.shape
    n = unwrapped.shape[1]
    rad = np.asarray(radius)[species]
    sigma = rad[:, None] + rad[None, :]
    per_side = g["subbox_per_side"][()]
    n_r = n / per_side.astype(float) ** 2
    c = np.full((nk, nj), np.nan)
    boxes = {m: [] for m in per_side}  # per grid: C_B,r of every (origin, lag) [k][j][r]
    bonds_pp = []
    for k, of in enumerate(origin_frame):
        x0 = unwrapped[of]
        d = x0[None, :, :] - x0[:, None, :]  # r_j - r_i
        d -= L * np.round(d / L)
        r2 = np.sum(d ** 2, axis=2)
        i_, j_ = np.nonzero(np.triu(r2 < (a1 * sigma) ** 2, 1))
        bonds_pp.append(len(i_) / n)
        folded = x0[i_] - L * np.floor(x0[i_] / L)
        per_grid = {m: [] for m in per_side}
        for j, pf in enumerate(pair_frame[k]):
            dr = unwrapped[pf] - x0
            b = d[i_, j_] + dr[j_] - dr[i_]
            intact = np.sum(b ** 2, axis=1) <= (a2 * sigma[i_, j_]) ** 2
            c[k, j] = intact.mean()
            for m in per_side:
                cell = np.minimum((folded / L * m).astype(int), m - 1)
                r = cell[:, 1] * m + cell[:, 0]
                nb = np.bincount(r, minlength=m * m).astype(float)
                ni = np.bincount(r, weights=intact, minlength=m * m)
                per_grid[m].append(np.where(nb > 0, ni / np.maximum(nb, 1), 1.0))
        for m in per_side:
            boxes[m].append(per_grid[m])
    rec = float(g["bonds_per_particle"]["value"][-1])
    check(abs(rec - np.mean(bonds_pp)) < 1e-12, f"bonds per particle {rec:.4g} equals brute force")
    c_bf = c.mean(axis=0)
    d = np.max(np.abs(g["c_b"]["value"][-1] - c_bf))
    check(d < 1e-12, f"C_B(t) equals brute force (max diff {d:.2g})")
    tau, tau_bf = float(g["tau_b"]["value"][-1]), crossing_time(lag, c_bf, math.exp(-1))
    check((math.isnan(tau) and math.isnan(tau_bf)) or abs(tau - tau_bf) <= 1e-9 * tau_bf,
          f"tau_B {tau:.6g} (brute force {tau_bf:.6g}: NaN where C_B has not crossed 1/e)")
    chi = g["chi_b"]["value"][-1]
    for w, m in enumerate(per_side):
        v = np.array(boxes[m])  # [k][j][r]
        chi_bf = np.array([n_r[w] * np.var(v[:, j, :].ravel(), ddof=1) for j in range(nj)])
        dd = np.max(np.abs(chi[w] - chi_bf) / np.maximum(np.abs(chi_bf), 1e-12))
        check(dd < 1e-9, f"chi_B of {m}x{m} sub-boxes equals brute force (max rel diff {dd:.2g})")
    check(math.isfinite(tau_bf), "C_B crosses 1/e within the lags (the test's scene breaks bonds at a2 small enough)")
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
