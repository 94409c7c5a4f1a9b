#!/usr/bin/python3
"""The cage-relative results of a run with kept frames ([observables]
cage_relative = true) against a brute-force recomputation from its frames,
with cages found independently of the node's CGAL: the Voronoi neighbours of
each origin frame are the Delaunay neighbours (scipy's Qhull) of the frame
tiled 3 x 3, taken for the central copy and folded back to particle indices.

  dr_i^CR = dr_i - mean over j in V_i(t0) of dr_j

Checked: overlap_cr Q(t) and tau_alpha per cutoff, s4_cr by check_spatial.py's
exact sums with the cage-relative weights, clusters_cr by its brute force
with slow and fast chosen by |dr^CR|, msd_cr (all and small
particles), chi4_cr of the whole box (N times the variance of Q over
origins, n - 1), and in msd and msd_cr both ways F_s(q, t) = <J0(q |dr|)>
(scipy's j0) at the recorded q and alpha_2(t) = <dr^4> / (2 <dr^2>^2) - 1,
each to rounding; and that every cage-relative group the scene asks for is
there, marked as such, beside its standard group.

Usage: check_cage_relative.py RUN.h5
"""
import math
import sys

import h5py
import numpy as np
from scipy.spatial import Delaunay
from scipy.special import j0

# The checks and tau's crossing as check_run.py has them (one list of failures).
from check_common import check, crossing_time, failures, scene_of  # noqa: E402
from check_spatial import check_clusters, check_s4  # noqa: E402


def voronoi_neighbours(x, L):
    """Neighbour sets of the periodic frame x (n, 2): Delaunay of the 3 x 3 tiling."""
    n = len(x)
    x = np.mod(x, L)
    shifts = np.array([(i, j) for i in (-1, 0, 1) for j in (-1, 0, 1)], float) * L
    tiled = np.concatenate([x + s for s in shifts])
    centre = 4  # the copy with shift (0, 0)
    tri = Delaunay(tiled)
    nb = [set() for _ in range(n)]
    for simplex in tri.simplices:
        for a in simplex:
            if a // n != centre:
                continue
            for b in simplex:
                if b != a:
                    nb[a % n].add(b % n)
    return [np.array(sorted(s - {i}), int) for i, s in enumerate(nb)]


def gab_neighbours(x, L, species, cut):
    """Neighbour sets of the frame x: pairs closer than cut[s_i + s_j] (minimum image), as the clusters node's."""
    d = x[None, :, :] - x[:, None, :]
    d -= L * np.round(d / L)
    close = np.hypot(d[..., 0], d[..., 1]) < np.asarray(cut)[species[:, None] + species[None, :]]
    np.fill_diagonal(close, False)
    return [np.flatnonzero(row) for row in close]


def cage_relative(dr, nb):
    return np.array([dr[i] - (dr[v].mean(axis=0) if len(v) else 0) for i, v in enumerate(nb)])


def main(path):
    f = h5py.File(path, "r")
    obs = f["observables"]
    check(int(f.attrs.get("complete", 0)) == 1, "file marked complete")
    for name in ("overlap", "chi4", "msd", "displacement", "s4", "clusters"):
        if name in obs:
            check(name + "_cr" in obs, f"{name}_cr recorded beside {name}")
    L = float(f["particles/all/box/edges"][0])
    unwrapped = f["particles/all/position/value"][()] + f["particles/all/image/value"][()] * L
    species = f["particles/all/species"][()]
    species = species[0] if species.ndim > 1 else species
    sched = obs["schedule"]
    origin_frame, pair_frame, lag = sched["origin_frame"][()], sched["pair_frame"][()], sched["lag_time"][()]
    n = unwrapped.shape[1]
    # dr^CR of every (origin, lag) pair, with the cages of the scene's kind
    kind = scene_of(f["parameters/scene_toml"][()])["observables"]["cage"]
    cut = None
    if kind == "g_ab":  # the first minima of g_ab of the first origin frame: the clusters node's cutoffs
        cut = obs["clusters"][sorted(obs["clusters"])[0]]["neighbour_cutoff"]["value"][-1]
        print(f"     g_ab cages: r11, r12, r22 = {np.round(cut, 4)} (the clusters node's)")
    dr_cr = {}
    for k, of in enumerate(origin_frame):
        nb = voronoi_neighbours(unwrapped[of], L) if cut is None else gab_neighbours(unwrapped[of], L, species, cut)
        counts = np.array([len(v) for v in nb])
        if k == 0:
            inv_n = np.mean([1 / c for c in counts if c > 0])
        if k == 0 and cut is None:
            check(abs(counts.mean() - 6) < 1e-9, f"Voronoi cells have 6 neighbours on average ({counts.mean():.6g})")
        elif k == 0:
            print(f"     g_ab cages: {counts.mean():.3f} neighbours on average")
        for j, pf in enumerate(pair_frame[k]):
            if pf >= 0:
                dr_cr[k, j] = cage_relative(unwrapped[pf] - unwrapped[of], nb)
    nk, nj = pair_frame.shape

    for name, g in obs["overlap_cr"].items():
        a = float(g.attrs["cutoff_a"])
        check("cage-relative" in str(g.attrs.get("displacements", "")), f"overlap_cr/{name} says it is cage-relative")
        q_k = np.array([[np.mean(np.hypot(*dr_cr[k, j].T) < a) for j in range(nj)] for k in range(nk)])
        q_bf = q_k.mean(axis=0)
        q_rec = g["q"]["value"][-1]
        err = np.max(np.abs(q_bf - q_rec))
        check(err < 1e-12, f"overlap_cr/{name}: Q(t) equals brute force (max diff {err:.2g})")
        tau, tau_bf = float(g["tau_alpha"]["value"][-1]), crossing_time(lag, q_bf, math.exp(-1))
        check(math.isfinite(tau) and abs(tau - tau_bf) <= 1e-9 * tau_bf,
              f"overlap_cr/{name}: tau_alpha {tau:.6g} (brute force {tau_bf:.6g})")
        tau_std = float(obs["overlap"][name]["tau_alpha"]["value"][-1])
        print(f"     overlap {name}: tau_alpha {tau_std:.4g} standard, {tau:.4g} cage-relative")
        if "chi4_cr" in obs and name in obs["chi4_cr"]:
            c = obs["chi4_cr"][name]
            per_side = c["subbox_per_side"][()]
            if 1 in per_side:
                w = list(per_side).index(1)
                chi_bf = n * q_k.var(axis=0, ddof=1)
                chi_rec = c["chi4"]["value"][-1][w]
                d = np.max(np.abs(chi_rec - chi_bf) / np.maximum(np.abs(chi_bf), 1e-300))
                check(d < 1e-9, f"chi4_cr/{name}: whole box, N var(Q) over origins, equals brute force "
                      f"(max rel diff {d:.2g})")
    if "msd_cr" in obs:
        small = species == np.min(species) if species.dtype.kind in "iu" else np.zeros(n, bool)
        for key, sel in (("msd_all", np.ones(n, bool)), ("msd_small", small)):
            m_bf = np.array([np.mean([np.mean(np.sum(dr_cr[k, j][sel] ** 2, axis=1)) for k in range(nk)])
                             for j in range(nj)])
            m_rec = obs["msd_cr"][key]["value"][-1]
            err = np.max(np.abs(m_rec - m_bf) / m_bf)
            check(err < 1e-12, f"msd_cr: {key} equals brute force (max rel diff {err:.2g})")
        short = obs["msd_cr"]["msd_all"]["value"][-1][0] / obs["msd"]["msd_all"]["value"][-1][0]
        # At the shortest lag the neighbours' displacements are nearly
        # independent of i's: <|dr^CR|^2> = <|dr|^2> (1 + <1/N_i>), about 7/6
        # with Voronoi cages.
        check(abs(short - (1 + inv_n)) < 0.1, f"msd_cr / msd at the shortest lag {short:.3f}: about 1 + <1/N_i> = "
              f"{1 + inv_n:.3f}")
    if "s4_cr" in obs:  # S4 of the cage-relative weights, by the exact sums of check_spatial.py
        lag = obs["schedule"]["lag_time"][()]
        for name, g in obs["s4_cr"].items():
            check_s4(f, name, g, unwrapped, L, origin_frame, pair_frame, lag,
                     dr_of=lambda k, j: dr_cr[k, j], overlap="overlap_cr", need_fit=False)
    if "clusters_cr" in obs:  # slow and fast clusters by |dr^CR|, by check_spatial.py's brute force
        scene = scene_of(f["parameters/scene_toml"][()])
        check_clusters(f, unwrapped, L, origin_frame, pair_frame, obs["schedule"]["lag_time"][()], scene,
                       group="clusters_cr", dr_of=lambda k, j: dr_cr[k, j])
    if "msd" in obs:
        small = species == np.min(species)
        radius = f["parameters/run_info"].attrs.get("radius") if "parameters/run_info" in f else None
        for group, dr_of in (("msd", lambda k, j: unwrapped[pair_frame[k, j]] - unwrapped[origin_frame[k]]),
                             ("msd_cr", lambda k, j: dr_cr[k, j])):
            if group not in obs:
                continue
            g = obs[group]
            q = g["fs_q"][()]
            if radius is not None:
                r0, r1 = float(radius[0]), float(radius[1])
                check(np.allclose(q[:3], 2 * np.pi / np.array([2 * r0, r0 + r1, 2 * r1]), rtol=1e-14),
                      f"{group}: F_s at q = 2 pi / sigma_11, sigma_12, sigma_22 ({np.round(q[:3], 4)})")
            r2 = {(k, j): np.sum(dr_of(k, j) ** 2, axis=1) for k in range(nk) for j in range(nj)}
            for key, sel in (("all", np.ones(n, bool)), ("small", small)):
                fs_bf = np.array([[np.mean([np.mean(j0(qq * np.sqrt(r2[k, j][sel]))) for k in range(nk)])
                                   for j in range(nj)] for qq in q])
                d = np.max(np.abs(g["fs_" + key]["value"][-1] - fs_bf))
                check(d < 1e-12, f"{group}: F_s of {key} particles at {len(q)} q equals brute force (max diff {d:.2g})")
                m4 = np.array([np.mean([np.mean(r2[k, j][sel] ** 2) for k in range(nk)]) for j in range(nj)])
                m2 = np.array([np.mean([np.mean(r2[k, j][sel]) for k in range(nk)]) for j in range(nj)])
                a2_bf = m4 / (2 * m2 ** 2) - 1
                d = np.max(np.abs(g["alpha2_" + key]["value"][-1] - a2_bf) / np.maximum(np.abs(a2_bf), 1e-3))
                check(d < 1e-9, f"{group}: alpha_2 of {key} particles equals brute force (max rel diff {d:.2g})")
            fs = g["fs_all"]["value"][-1]
            check(np.all(np.abs(fs[:, 0] - 1) < 0.05) and np.all(fs[:, -1] < fs[:, 0]),
                  f"{group}: F_s starts near 1 and decays ({np.round(fs[:, -1], 3)} at the last lag)")
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
