"""Section 3.3: clusters of slow and fast particles, d_f, kappa, rho, snapshots."""
import math

import matplotlib.pyplot as plt
from matplotlib.collections import EllipseCollection
from matplotlib.patches import Patch
import numpy as np

from .. import collapse
from .. import fits as sf
from .config import A_MAIN, PHI_SNAP
from .runs import snapshot
from .points import fit_series, point_error, seeds_of, series_arrays
from .quantities import KAPPA_LO, cut, kappa_of, n_star
from .verdicts import fmt, verdict
from .plotting import colours, errorbar


def cluster_results(A, phi_c, phi_c_why=None, joint=None):
    pts = A.series()
    dfs = lambda r: (cut(r)["cl_slow_d_f"], cut(r)["cl_slow_d_f_err"])
    dff = lambda r: (cut(r)["cl_fast_d_f"], cut(r)["cl_fast_d_f_err"])
    fig, ax = plt.subplots(1, 3, figsize=(16, 4.5))
    top = pts[-1] if pts else None
    if top:
        for kind, col in (("slow", "C3"), ("fast", "C7")):
            rr, nn = [], []
            for r in top.runs:
                c = cut(r)
                rr.append(c[f"cl_rg_{kind}"])
                nn.append(c[f"cl_rg_size_{kind}"])
            ax[0].loglog(np.nanmean(nn, axis=0), np.nanmean(rr, axis=0), "o", color=col, label=f"{kind}, φ = {top.phi:g}")
        ax[0].set_xlabel("N_c")
        ax[0].set_ylabel("R_g")
        ax[0].legend(fontsize=8)
        ax[0].set_title("slow clusters: R_g against N_c (paper, sec. 3.3)")
    x, y, e = series_arrays(pts, dfs)
    errorbar(ax[1], x, y, e, fmt="o", color="C3", label="slow")
    x2, y2, e2 = series_arrays(pts, dff)
    errorbar(ax[1], x2, y2, e2, fmt="s", color="C7", label="fast")
    ax[1].set_xlabel("φ")
    ax[1].set_ylabel("d_f")
    ax[1].legend(fontsize=8)
    ax[1].set_title("d_f of slow and fast clusters against φ (paper, sec. 3.3)")
    for p, col in zip(pts, colours(len(pts))):
        cv = collapse_curves([p])
        if not cv:
            continue
        n, _, pm, _ = cv[0]
        m = pm > 0
        ax[2].loglog(n[m], pm[m], "-o", ms=2, color=col, label=f"{p.phi:g}")
    nn = np.geomspace(1, 1e3, 10)
    ax[2].loglog(nn, 0.4 * nn ** -1.8, "k:", label="N_c^-1.8 (paper)")
    ax[2].set_xlabel("N_c")
    ax[2].set_ylabel("P(N_c), slow")
    ax[2].legend(fontsize=6, ncol=2)
    ax[2].set_title("P(N_c) of slow clusters (paper, sec. 3.3)")
    f1 = A.save(fig, "clusters.png")
    lo, hi = (pts[0], pts[-1]) if pts else (None, None)
    if lo:
        m, e, sem, n = lo.mean(dfs)
        A.row(f"d_f of slow clusters at φ = {lo.phi:g}", "3.3, inset of fig. clusters-VF805", "1.65 (φ = 0.60)", fmt(m, e),
              verdict(m, e, 1.65) if abs(lo.phi - 0.60) < 1e-9 else "other φ", f1, [lo])
        m, e, sem, n = hi.mean(dfs)
        A.row(f"d_f of slow clusters at φ = {hi.phi:g} (highest run)", "3.3, fig. clusters-VF805(a)", "1.91 (φ = 0.805)", fmt(m, e),
              verdict(m, e, 1.91) + ("" if abs(hi.phi - 0.805) < 1e-9 else f"; our φ is {hi.phi:g}"), f1, [hi])
        m, e, sem, n = hi.mean(dff)
        A.row(f"d_f of fast clusters at φ = {hi.phi:g} (highest run)", "3.3, fig. clusters-VF805(b)", "1.73 (φ = 0.805)", fmt(m, e),
              verdict(m, e, 1.73) + ("" if abs(hi.phi - 0.805) < 1e-9 else f"; our φ is {hi.phi:g}"), f1, [hi])
    # kappa: P(N_c) ~ N_c^-kappa of slow clusters per run over
    # KAPPA_LO[1] <= N_c <= N* (the run's cutoff size), the weighted mean over
    # the densities from 0.76 up; the lower bound scanned (monomers in or out).
    # The clusters node's own kappa (N_c in [1, 100], fixed) is left aside.
    dense = [p for p in pts if p.phi >= 0.76]

    def kappa_mean(lo):
        ks = [p.mean(lambda r: kappa_of(r, lo)) for p in dense]
        kv = np.array([k[0] for k in ks])
        ke = np.array([point_error(k) for k in ks])
        m = np.isfinite(kv) & np.isfinite(ke) & (ke > 0)
        if not m.any():
            return math.nan, math.nan, 0
        return (float(np.sum(kv[m] / ke[m] ** 2) / np.sum(1 / ke[m] ** 2)), float(1 / math.sqrt(np.sum(1 / ke[m] ** 2))),
                int(m.sum()))
    scan = {lo: kappa_mean(lo) for lo in KAPPA_LO}
    kappa, kappa_e, nk = scan[KAPPA_LO[1]]
    vals = [v[0] for v in scan.values() if np.isfinite(v[0])]
    syst = (max(vals) - min(vals)) / 2 if len(vals) >= 2 else math.nan
    knote = (f"N_c from {KAPPA_LO[1]:g} to N* per run, {nk} densities; scan of the lower bound: "
             + (", ".join(f"{lo:g}: {v[0]:.3g}" for lo, v in scan.items() if np.isfinite(v[0])) or "no range fits")
             + (f" (systematic ± {syst:.2g})" if np.isfinite(syst) else ""))
    per_phi = [(p.phi, p.mean(lambda r: kappa_of(r, KAPPA_LO[1]))[0]) for p in dense]
    per_phi = [(ph, k) for ph, k in per_phi if np.isfinite(k)]
    if len(per_phi) >= 2:
        knote += "; per density " + ", ".join(f"{k:.3g} (φ {ph:g})" for ph, k in per_phi)
    A.row(f"κ: P(N_c) ∝ N_c^-κ, slow clusters (weighted mean over φ ≥ 0.76, {KAPPA_LO[1]:g} ≤ N_c ≤ N*)",
          "3.3, fig. dist(a), dist-collapse", "≈ 1.8", fmt(kappa, kappa_e), verdict(kappa, kappa_e, 1.8), f1, dense, knote)
    fc, fc_err, cpts, cnote = kappa_collapse_rows(A, pts)
    # rho: N* = <N_c^2>/<N_c> against (phi_c - phi), phi_c from the tau_alpha power law
    frho = None
    if np.isfinite(phi_c):
        frho = A.fit("n_star", fit_series([p for p in pts if p.phi < phi_c], n_star, sf.power, xpoint=lambda p: phi_c - p.phi))
    rho = -1 / frho.p["s"] if frho and frho.ok else math.nan
    rho_e = abs(frho.error("s")) / frho.p["s"] ** 2 if frho and frho.ok else math.nan
    k_fig = fc.p["kappa"] if fc.ok else kappa   # the figure shows the collapse's own exponent
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.5))
    for p, col in zip(pts, colours(len(pts))):
        c0 = cut(p.runs[0])
        cv = collapse_curves([p])  # the collapse's own curves and N*
        if cv and np.isfinite(k_fig):
            n, w, pm, _ = cv[0]
            ns = collapse.n_star(n, w, pm)
            mm = pm > 0
            if np.isfinite(ns):
                ax[0].loglog(n[mm] / ns, pm[mm] * n[mm] ** k_fig, "-o" if p in cpts else ":", ms=2, color=col,
                             label=f"{p.phi:g}")
        if "cl_p_fast" not in c0:
            continue
        pf = np.nanmean([cut(r)["cl_p_fast"] for r in p.runs], axis=0)
        sg, nsig, p0 = (p.mean(lambda r, k=k: (cut(r)[k], math.nan))[0] for k in ("cl_fast_sigma", "cl_fast_n_sigma", "cl_fast_p0"))
        mf = pf > 0
        if all(np.isfinite(v) and v > 0 for v in (sg, nsig, p0)):
            ax[1].semilogx(c0["cl_size"][mf] / nsig, (pf[mf] / p0) ** (2 * sg * sg), "o", ms=3, color=col, label=f"{p.phi:g}")
    u = np.geomspace(0.05, 50, 100)
    ax[1].semilogx(u, np.exp(-np.log(u) ** 2), "k-", lw=0.8, label="exp(-ln²(N_c/N_σ))")
    ax[0].set_xlabel("N_c / N*  (N* = <N_c³>/<N_c²>, the collapse's)")
    ax[0].set_ylabel(f"P(N_c) N_c^κ, κ = {k_fig:.3g}" + (" (the collapse's)" if fc.ok else " (the slopes')"))
    ax[0].set_title(f"P(N_c) collapse (paper, sec. 3.3); N* ∝ (φc-φ)^(-1/ρ), ρ = {rho:.3g}")
    ax[1].set_xlabel("N_c / N_σ")
    ax[1].set_ylabel("[P(N_c)/P_0]^(2σ²)")
    ax[1].set_title("fast clusters: log-normal collapse (paper, sec. 3.3)")
    for a_ in ax:
        a_.legend(fontsize=6, ncol=2)
    f2 = A.save(fig, "clusters_collapse.png")
    A.row(f"κ by the paper's collapse: P(N_c) N_c^κ against N_c / N*, slow clusters (every φ but the lowest, N_c ≥ {KAPPA_LO[0]:g})",
          "3.3, fig. dist-collapse", "≈ 1.8", fmt(fc.p["kappa"], fc_err),
          verdict(fc.p["kappa"], fc_err, 1.8) if fc.ok else "not determined", f2, cpts, cnote)
    # rho against (phi_c - phi): a phi_c on the edge of the data gives the
    # last point all the leverage, so that verdict is not judged; rho is also
    # given with the joint fit's phi_c.
    A.row("ρ: N* ∝ (φ_c - φ)^(-1/ρ), slow clusters (φ_c from τ_α's power law)", "3.3, fig. dist-collapse", "≈ 1.63",
          fmt(rho, rho_e), f"not judged: τ_α's power law: {phi_c_why}" if phi_c_why else verdict(rho, rho_e, 1.63),
          f2, pts, frho.note if frho else "no φ_c")
    xj = joint.p["xc"] if joint is not None and joint.ok else math.nan
    fj = (A.fit("n_star_xc_joint", fit_series([p for p in pts if p.phi < xj], n_star, sf.power, xpoint=lambda p: xj - p.phi))
          if np.isfinite(xj) else None)
    if fj is not None and fj.ok:
        rj, rje = -1 / fj.p["s"], abs(fj.error("s")) / fj.p["s"] ** 2
        why = sf.cannot_judge(joint, "xc")
        A.row(f"ρ with the joint fit's φ_c = {xj:.4f}", "3.3, fig. dist-collapse", "≈ 1.63", fmt(rj, rje),
              f"not judged: the joint fit: {why}" if why else verdict(rj, rje, 1.63), f2, pts, fj.note)
    A.row("fast clusters: log-normal collapse", "3.3, fig. lognormal-scaled", "figure only", "per-point fits of the clusters node",
          "figure", f2, pts)
    # snapshots
    fig, ax = plt.subplots(1, 3, figsize=(16, 5.4))
    shown = []
    for k, phi in enumerate(PHI_SNAP):
        # (the largest N with frames: a point --largest-n took may have none)
        cands = A.series_with(lambda p: any(r.get("has_frames") for r in p.runs))
        p = A.nearest(cands, phi)
        if p is None or p in shown:
            ax[k].set_axis_off()
            continue
        shown.append(p)
        r = next(r for r in p.runs if r.get("has_frames"))
        xy, radii, slow, fast, box, lag = snapshot(r["path"], A_MAIN, cut(r)["tau_alpha"])
        # every disk at its own radius (data units), slow and fast ones coloured
        shown_as = []
        for m, colour, label in ((~(slow | fast), "#dddddd", None), (slow, "#b2182b", f"slow ({slow.mean():.2f})"),
                                 (fast, "#555555", f"fast ({fast.mean():.2f})")):
            ax[k].add_collection(EllipseCollection(2 * radii[m], 2 * radii[m], 0.0, units="xy", offsets=xy[m],
                                                   offset_transform=ax[k].transData, facecolors=colour,
                                                   edgecolors="none"))
            if label:
                shown_as.append(Patch(color=colour, label=label))
        ax[k].set_aspect("equal")
        ax[k].set_xlim(0, box[0])
        ax[k].set_ylim(0, box[1])
        ax[k].set_title(f"φ = {p.phi:g}, t = {lag:.3g} (τ_α = {cut(r)['tau_alpha']:.3g})", fontsize=9)
        ax[k].legend(handles=shown_as, fontsize=7, loc="upper right")
    f3 = A.save(fig, "snapshots.png")
    A.row("snapshots of slow and fast particles at τ_α, three densities", "3.3, fig. SD-2", "figure only",
          ", ".join(f"φ = {p.phi:g}" for p in shown) or "no run kept its frames", "figure", f3, shown)
    return kappa


def has_clusters(r, like=None):
    """Whether run r has the slow clusters' P(N_c) (and, given another run,
    on the same sizes)."""
    c = cut(r)
    if not all(k in c for k in ("cl_size", "cl_width", "cl_p_slow", "cl_p_slow_err")):
        return False
    return like is None or np.array_equal(c["cl_size"], cut(like)["cl_size"])


def collapse_curves(pts, drop=None):
    """Per point the slow clusters' P(N_c), the mean over its seeds (seed
    `drop` left out) with the runs' errors combined: the histograms of fig.
    dist-collapse (collapse.py takes N* from each). A point of one seed
    keeps it (as Point.mean does: a replicate without the point would be a
    collapse over other densities, not over other seeds)."""
    curves = []
    for p in pts:
        runs = [r for r in p.runs if has_clusters(r)]
        runs = [r for r in runs if has_clusters(r, runs[0])] if runs else []   # the bins of its first run
        runs = [r for r in runs if r["seed"] != drop] if len(runs) > 1 else runs
        if not runs:
            continue
        cs = [cut(r) for r in runs]
        P, E = np.array([c["cl_p_slow"] for c in cs], float), np.array([c["cl_p_slow_err"] for c in cs], float)
        curves.append((cs[0]["cl_size"], cs[0]["cl_width"], P.mean(axis=0), np.sqrt((E ** 2).sum(axis=0)) / len(runs)))
    return curves


def collapse_fit(A, cpts, key, curves=None):
    """The collapse of cpts' slow-cluster P(N_c), N_c >= KAPPA_LO[0]
    (collapse.py), recorded as fit `key`: (fit, quoted error, the
    jackknife's words). The error: the larger of the bootstrap over the
    bins' errors and the jackknife over seeds, times sqrt(quality) where
    the curves do not collapse within their errors. (curves: collapse_curves(cpts), where made already.)"""
    f = collapse.exponent(collapse_curves(cpts) if curves is None else curves, KAPPA_LO[0], resamples=200)
    if not f.ok:
        return f, math.nan, ""
    seeds = seeds_of(cpts)
    reps = [collapse.exponent(collapse_curves(cpts, s), KAPPA_LO[0]).p["kappa"] for s in seeds] if len(seeds) >= 2 else []
    jk = (math.sqrt((len(reps) - 1) / len(reps) * np.sum((np.array(reps) - np.mean(reps)) ** 2))
          if reps and np.all(np.isfinite(reps)) else math.nan)
    f.jk["kappa"], f.jk_seeds = jk, len(reps) if np.isfinite(jk) else 0
    parts = [e for e in (f.err["kappa"], jk) if np.isfinite(e)]
    err = max(parts) * math.sqrt(max(f.quality, 1.0)) if parts else math.nan
    f.quoted = {"kappa": err}
    f.error_from = ("the larger of err_fit (a bootstrap over the bins' errors, N* redrawn) and the jackknife over "
                    "seeds, times sqrt(quality) where the quality exceeds 1")
    A.fit(key, f)
    words = (f"jackknife over {len(reps)} seeds " + (f"{jk:.2g}" if np.isfinite(jk) else
             "not taken (fewer than 2 seeds, or a replicate without a collapse)")
             + (f"; error × sqrt(quality) = {math.sqrt(f.quality):.2g}" if f.quality > 1 else ""))
    return f, err, words


def kappa_collapse_rows(A, pts):
    """kappa as the paper takes it: the exponent of the best collapse of
    P(N_c) N_c^kappa against N_c / N* over every density but the lowest
    (collapse_fit), the lower bound of N_c scanned as for the slopes.
    Returns (the fit, its error, its densities, its note)."""
    cpts = [p for p in pts[1:] if any(has_clusters(r) for r in p.runs)] if len(pts) >= 3 else []
    curves = collapse_curves(cpts)
    f, err, words = collapse_fit(A, cpts, "kappa_collapse", curves)
    if len(cpts) < 2 or not f.ok:
        return f, math.nan, cpts, (f.note if cpts else "fewer than 2 densities above the lowest")
    vals = {KAPPA_LO[0]: f.p["kappa"]}
    for lo in KAPPA_LO[1:]:
        g = collapse.exponent(curves, lo)
        if g.ok:
            vals[lo] = g.p["kappa"]
    note = (f"φ {cpts[0].phi:g}-{cpts[-1].phi:g}; {f.note}; {words}; scan of the lower bound: "
            + ", ".join(f"{lo:g}: {v:.3g}" for lo, v in vals.items()))
    if len(vals) >= 2:
        note += f" (systematic ± {(max(vals.values()) - min(vals.values())) / 2:.2g})"
    return f, err, cpts, note
