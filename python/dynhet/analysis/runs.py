"""Reading a run's run.h5 into the arrays the study analysis uses (one dict per run, its cutoffs in r['cut'])."""
import math

import h5py
import numpy as np

from .. import schema
from ..run import open_run


def last(g, name):
    """The final record of a dataset of an Observable (dynhet.run), None if
    the group lacks it."""
    return g.get(name)


def fnum(v):
    return float(v) if v is not None else math.nan


MIN_JACKKNIFE_BLOCKS = 4   # kMinJackknifeBlocks of analysis_nodes/kernels/include/dynhet/analysis/fits.hpp


def run_plan(path):
    """((origins, origin spacing) or None, equilibration time or NaN) of a
    run: parameters/schedule and parameters/run of run.h5, where recorded."""
    with h5py.File(path, "r") as f:
        g, r = f.get("parameters/schedule"), f.get("parameters/run")
        schedule = (int(g.attrs["origins"]), float(g.attrs["origin_spacing"])) \
            if g is not None and "origins" in g.attrs and "origin_spacing" in g.attrs else None
        t_equil = float(r.attrs["equilibration_time"]) if r is not None and "equilibration_time" in r.attrs \
            else math.nan
    return schedule, t_equil


def blocks_span(longest_lag, schedule):
    """The nodes' origin_blocks_span: whether jackknife blocks of origins that
    span `longest_lag` fit at least MIN_JACKKNIFE_BLOCKS times into the
    origins; where they do not, the blocks are correlated and a quoted error
    is too small (docs/analysis.md, "a run quotes no tau_B error it cannot
    back"). True where it cannot be told."""
    if schedule is None or not np.isfinite(longest_lag) or longest_lag <= 0 or schedule[1] <= 0:
        return True
    n, spacing = schedule
    return math.ceil(longest_lag / spacing - 1e-9) <= max(1, n // MIN_JACKKNIFE_BLOCKS)


def cutoff_groups(run, kind):
    """{a: Observable} of an observable family (empty where the run lacks it)."""
    return {a: run.observable(kind, a) for a in run.cutoffs(kind)}


def read_cutoffs(run, cage_relative=False):
    """{a: the cutoff's arrays} of the overlap, chi4, S4 and clusters groups
    (their cage-relative versions with cage_relative; empty where the run has none)."""
    kind = schema.cage_relative if cage_relative else (lambda k: k)
    ov, ch, s4g, cl = (cutoff_groups(run, kind(k)) for k in ("overlap", "chi4", "s4", "clusters"))
    out = {}
    for a, g in ov.items():
        c = {"lag": g["lag_time"][:], "q": last(g, "q"), "q_err": last(g, "q_err")}
        for k in ("tau_alpha", "tau_alpha_err", "beta", "beta_err", "tau0", "tau0_err"):
            c[k] = fnum(last(g, k))
        c["tau_t0"] = last(g, "tau_alpha_t0")
        c["t0"] = g["t0"][:] if "t0" in g else None
        if a in ch:
            h = ch[a]
            n_sub = h["subbox_particles"][:]
            nl = len(h["lag_time"][:])
            c["chi4_lag"] = h["lag_time"][:]
            c["chi4_N"] = n_sub
            c["chi4"] = last(h, "chi4").reshape(len(n_sub), nl)
            c["chi4_err"] = last(h, "chi4_err").reshape(len(n_sub), nl)
            for k in ("chi4_peak", "chi4_peak_err", "tau4", "tau4_err"):
                c[k] = last(h, k)
            # Older files lack it: their peaks count as interior.
            c["tau4_interior"] = (last(h, "tau4_interior").astype(bool) if "tau4_interior" in h
                                  else np.ones(len(n_sub), bool))
        if a in s4g:
            s = s4g[a]
            q = s["q"][:]
            lag = s["lag_time"][:]
            ng = len(s["subbox_particles"][:])
            c["s4_q"], c["s4_lag"] = q, lag
            c["s4_nshells"] = s["n_shells"][:]
            c["s4_N"] = s["subbox_particles"][:]
            c["s4_t"] = last(s, "s4_lag").reshape(len(lag), len(q))
            c["xi_t"] = last(s, "xi_lag").reshape(len(lag), ng)
            c["chi0_t"] = last(s, "chi0_lag").reshape(len(lag), ng)
            for k in ("oz_chi0", "oz_chi0_err", "a2_chi0", "a2_chi0_err", "chi4", "chi4_err", "oz_xi", "oz_xi_err",
                      "oz_q_fit_max"):
                c["s4_" + k] = last(s, k)
            for k in ("t_s4", "xi", "xi_err", "chi0", "chi0_err"):
                c["s4_" + k] = fnum(last(s, k))
        if a in cl:
            g2 = cl[a]
            if "size_centre" in g2:  # absent where this cutoff's tau_alpha was never reached
                c["cl_size"] = g2["size_centre"][:]
                c["cl_width"] = (g2["size_hi"][:] - g2["size_lo"][:] + 1).astype(float)
            for k in ("p_slow", "p_fast", "rg_slow", "rg_fast", "rg_size_slow", "rg_size_fast"):
                c["cl_" + k] = last(g2, k)
            c["cl_p_slow_err"] = last(g2, "p_slow_err") if "p_slow_err" in g2 else np.full_like(c["cl_p_slow"], np.nan)
            for k in ("slow_d_f", "slow_d_f_err", "fast_d_f", "fast_d_f_err", "slow_kappa", "slow_kappa_err",
                      "fast_sigma", "fast_n_sigma", "fast_p0", "lag"):
                c["cl_" + k] = fnum(last(g2, k))
        out[a] = c
    return out


def read_run(path, meta):
    """Everything the analysis uses from one run.h5, as plain numpy."""
    r = dict(meta)
    with open_run(path) as run:
        r["complete"] = int(run.complete)
        obs = run.observables()
        r["N"] = int(meta["n_particles"])
        r["cut"] = read_cutoffs(run)
        r["schedule"], r["t_equil"] = run_plan(path)
        # The same of the cage-relative displacements (observables.cage_relative),
        # and their tau_alpha beside the standard one.
        r["cut_cr"] = read_cutoffs(run, cage_relative=True)
        for a, c in r["cut"].items():
            if a in r["cut_cr"]:
                c["tau_cr"], c["tau_cr_err"] = r["cut_cr"][a]["tau_alpha"], r["cut_cr"][a]["tau_alpha_err"]
                c["q_cr"] = r["cut_cr"][a]["q"]
        if schema.cage_relative("msd") in obs:  # the cage-relative D, which the cage-relative view takes
            mc = run.observable(schema.cage_relative("msd"))
            r["D_cr"], r["D_cr_err"] = fnum(last(mc, "diffusion")), fnum(last(mc, "diffusion_err"))
        m = run.msd() if "msd" in obs else None
        if m is not None:
            r["D"], r["D_err"] = fnum(last(m, "diffusion")), fnum(last(m, "diffusion_err"))
            r["D_t"] = (fnum(last(m, "fit_t_min")), fnum(last(m, "fit_t_max")))
            r["msd_lag"], r["msd"] = m["lag_time"][:], last(m, "msd_all")
        if "displacement" in obs:
            d = run.displacement()
            x = d["x"][:]
            lt = last(d, "lag_time")
            r["pdx_x"], r["pdx_lag"] = x, lt
            r["pdx"] = last(d, "p").reshape(-1, len(lt), len(x))
            r["pdx_target"] = last(d, "target_tau_alpha")
        if "bond_breaking" in obs:
            b = run.observable("bond_breaking")
            r["tau_b"], r["tau_b_err"] = fnum(last(b, "tau_b")), fnum(last(b, "tau_b_err"))
            if not blocks_span(r["tau_b"], r["schedule"]):
                r["tau_b_err"] = math.nan  # a run recorded before the node applied the same rule
            r["c_b_lag"], r["c_b"] = b["lag_time"][:], last(b, "c_b")
            r["c_b_err"] = last(b, "c_b_err") if "c_b_err" in b else np.full(len(r["c_b"]), np.nan)
        if "sim" in obs:
            s = run.observable("sim")
            r["Z"], r["Z_err"] = fnum(last(s, "reduced_pressure")), fnum(last(s, "reduced_pressure_err"))
        r["has_frames"] = run.has_frames()
    return r


def snapshot(path, a, t_target):
    """Positions at an origin frame and slow/fast flags over the pair whose lag
    is nearest t_target: (xy, radius of each disk, slow, fast, box, lag). The
    radii are the run's own (parameters/run_info, as the simulator resolved
    them), whatever its radius ratio."""
    with h5py.File(path, "r") as f:
        pos = f["particles/all/position/value"]
        img = f["particles/all/image/value"]
        ftime = f["particles/all/position/time"][:]
        box = f["particles/all/box/edges"][:]
        radii = np.asarray(f["parameters/run_info"].attrs["radius"], float)[f["particles/all/species"][:]]
        i0 = 0
        j = int(np.argmin(np.abs(np.log(np.maximum(ftime - ftime[i0], 1e-300)) - math.log(t_target))))
        u0 = pos[i0].reshape(-1, 2) + img[i0].reshape(-1, 2) * box
        u1 = pos[j].reshape(-1, 2) + img[j].reshape(-1, 2) * box
        d = np.linalg.norm(u1 - u0, axis=1)
        return pos[i0].reshape(-1, 2), radii, d < a, d > 3 * a, box, float(ftime[j] - ftime[i0])
