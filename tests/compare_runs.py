#!/usr/bin/python3
"""Replays must reproduce the live results (Q(t), chi4, MSD, P(dx, t), clusters, S4) bit for bit (if the live run lost
no frame) and must be identical to each other.

Usage: compare_runs.py LIVE.h5 REPLAY1.h5 REPLAY2.h5
"""
import sys

import h5py
import numpy as np


def final_results(path):
    with h5py.File(path, "r") as f:
        out = {}
        for name, g in f["observables/overlap"].items():
            for obs in ("q", "q_err", "qr_var", "tau_alpha", "tau_alpha_err", "beta", "tau0", "tau_alpha_t0",
                        "tau_alpha_t0_err"):
                if obs in g:  # (tau_alpha_t0_err: not in runs recorded before it was computed)
                    out[f"{name}/{obs}"] = np.atleast_1d(g[obs]["value"][-1])
        for name, g in f.get("observables/chi4", {}).items():
            for obs in ("chi4", "chi4_err", "chi4_peak", "tau4"):
                out[f"chi4/{name}/{obs}"] = np.atleast_1d(g[obs]["value"][-1])
        if "observables/msd" in f:
            for obs in ("msd_all", "msd_small", "diffusion", "msd_fast_all", "msd_slow_all", "msd_fast_small",
                        "msd_slow_small"):
                out[f"msd/{obs}"] = np.atleast_1d(f["observables/msd"][obs]["value"][-1])
        if "observables/displacement" in f:
            for obs in ("p", "p_err", "gauss_d", "gauss_d_err", "tail_x0", "tail_x0_err", "tail_x_min"):
                out[f"displacement/{obs}"] = np.atleast_1d(f["observables/displacement"][obs]["value"][-1])
        for name, g in f.get("observables/s4", {}).items():  # FFTW_ESTIMATE plans: the same arithmetic every run
            for obs in ("s4", "s4_err", "s4_lag", "oz_xi", "oz_chi0", "a2_xi", "chi4", "tau_alpha", "xi_lag",
                        "xi_lag_err", "chi0_lag_err"):
                if obs in g:
                    out[f"s4/{name}/{obs}"] = np.atleast_1d(g[obs]["value"][-1])
        for name, g in f.get("observables/clusters", {}).items():
            for obs in ("neighbour_cutoff", "tau_alpha", "lag", "mean_size_slow", "mean_size_fast", "p_slow",
                        "p_fast", "rg_slow", "rg_fast", "slow_d_f", "slow_kappa", "fast_n0", "fast_sigma"):
                out[f"clusters/{name}/{obs}"] = np.atleast_1d(g[obs]["value"][-1])
        lost = int(f["observables/nodes/overlap/frames_lost/value"][-1])
        return out, lost


def same(a, b):
    return a.keys() == b.keys() and all(
        np.array_equal(a[k].view(np.uint64), b[k].view(np.uint64)) for k in a)


def main(live, r1, r2):
    (lv, lost), (a, _), (b, _) = final_results(live), final_results(r1), final_results(r2)
    ok = True
    if same(a, b):
        print("ok   replay 1 and replay 2 are identical bit for bit")
    else:
        print("FAIL replay 1 and replay 2 differ")
        ok = False
    if lost:
        print(f"note live run lost {lost} frames: no bitwise comparison with live")
    elif same(lv, a):
        print("ok   replay reproduces the live Q(t), tau_alpha bit for bit")
    else:
        print("FAIL replay differs from the live run")
        for k in lv:
            if not np.array_equal(lv[k].view(np.uint64), a[k].view(np.uint64)):
                print(f"     {k}: live {lv[k][:4]} replay {a[k][:4]}")
        ok = False
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:4]))
