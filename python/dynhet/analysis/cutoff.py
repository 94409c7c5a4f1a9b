"""Section 3.4: the cutoff a."""
import math

import matplotlib.pyplot as plt
import numpy as np

from .. import fits as sf
from .config import A_MAIN, A_THREE, EPS_MAIN, XI_MIN_DF
from .points import fit_series, series_arrays
from .quantities import XI_MIN, chi4_at_tau, cut, proper_subbox, xi_at_tau
from .verdicts import fit_verdict, fmt
from .plotting import colours, errorbar


def df_fit(pts, cfn, xfn):
    """d_f' of one cutoff: chi4 against xi over xi >= XI_MIN_DF, the range of
    every d_f' of the analysis (the main series', the driving rules')."""
    return fit_series(pts, cfn, sf.power, xrun=xfn, x_range=(XI_MIN_DF, math.inf))


def cutoff_candidates(A):
    """The main series' points that ran several cutoffs, per study and
    density the largest N: every point, not only A.series(), since where
    --largest-n took a larger N of a study with one cutoff, this study's own
    point still holds the others (a promoted point, in both dicts, counts once)."""
    top = {}
    for q in list(A.points.values()) + list(A.extra.values()):
        if q.pairs == "neighbours" and abs(q.eps - EPS_MAIN) < 1e-9 and len(q.runs[0]["cut"]) > 1:
            k = (getattr(q, "study", None) or A.study_name, q.phi)
            if k not in top or q.N > top[k].N:
                top[k] = q
    return list(top.values())


def cutoff_results(A):
    """The cutoff a. Each a is taken at its own tau_alpha(a) where the run's
    lags reach it (solid), and all at tau_alpha of a = 0.6 (dashed); the
    d_f' rows use each a's own tau_alpha."""
    # the study (this one or an --also one) whose lags reach furthest in tau_alpha(0.6), all its densities
    cands = cutoff_candidates(A)
    reach = lambda p: cut(p.runs[0])["lag"][-1] / max(cut(p.runs[0])["tau_alpha"], 1e-300)
    by_study = {}
    for p in cands:
        by_study.setdefault(getattr(p, "study", None) or A.study_name, []).append(p)
    pts = []
    if by_study:
        best = max(by_study.values(), key=lambda ps: min(reach(p) for p in ps))
        pts = sorted(best, key=lambda p: p.phi)
    src = sorted({getattr(p, "study", None) or A.study_name for p in pts})
    if not pts:
        A.row("cutoff a: ξ(τ_α) against a, χ4(t) for several a, ξ(φ) and χ4 against ξ at a = 0.6, 1.4, 3.0",
              "3.4, figs. xi-vs-a, diff-a, chi4-diff-a", "figure only", "the study computes one cutoff", "not run", "", [])
        return
    cuts = sorted(pts[0].runs[0]["cut"])
    fig, ax = plt.subplots(2, 2, figsize=(12, 9))
    ax = ax.ravel()
    reached = {}
    for p, col in zip(pts, colours(len(pts))):
        own = [p.mean(lambda r, a=a: xi_at_tau(r, a, own=True))[0] for a in cuts]
        fixed = [p.mean(lambda r, a=a: xi_at_tau(r, a))[0] for a in cuts]
        ax[0].plot(cuts, own, "-o", ms=3, color=col, label=f"{p.phi:g}")
        ax[0].plot(cuts, fixed, "--", lw=0.8, color=col)
        for a, v in zip(cuts, own):
            reached[a] = reached.get(a, 0) + int(np.isfinite(v))
    ax[0].set_xlabel("a")
    ax[0].set_ylabel(f"ξ: at τ_α(a) (solid), at τ_α({A_MAIN:g}) (dashed)")
    ax[0].set_yscale("log")
    ax[0].legend(fontsize=6, ncol=2, title="φ", title_fontsize=7)
    ax[0].set_title("ξ(τ_α(a)) against the cutoff a (paper, sec. 3.4)")
    mid = A.nearest(pts, 0.78)
    for a, col in zip(cuts, colours(len(cuts))):
        c = cut(mid.runs[0], a)
        g = proper_subbox(c, mid.N)
        cm = np.nanmean([cut(r, a)["chi4"][g] for r in mid.runs], axis=0)
        ax[1].semilogx(c["chi4_lag"], cm, "-", color=col, label=f"a = {a:g}")
    ax[1].set_xlabel("t")
    ax[1].set_ylabel("χ4(t)")
    ax[1].legend(fontsize=7)
    ax[1].set_title(f"χ4(t) for several cutoffs a (φ = {mid.phi:g}; lags to {reach(mid):.3g} τ_α({A_MAIN:g}))")
    outs = []
    for a, m in zip(A_THREE, ("o", "s", "^")):
        if a not in cuts:
            continue
        xfn = lambda r, a=a: xi_at_tau(r, a, own=True)
        cfn = lambda r, a=a: chi4_at_tau(r, a, own=True)
        x, y, e = series_arrays(pts, xfn)
        errorbar(ax[2], x, y, e, fmt=m + "-", ms=4, label=f"a = {a:g}")
        fd = A.fit(f"chi4_xi_a{a:g}", df_fit(pts, cfn, xfn))
        xs, ys = [p.mean(xfn)[0] for p in pts], [p.mean(cfn)[0] for p in pts]
        ax[3].loglog(xs, ys, m, label=f"a = {a:g}: d_f' = {fd.p['s']:.3g}")
        if fd.ok:
            xx = np.geomspace(*fd.x_range, 10)
            ax[3].plot(xx, fd.p["A"] * xx ** fd.p["s"], "k--", lw=0.6)
        outs.append((a, fd))
    ax[2].set_yscale("log")
    ax[2].set_xlabel("φ")
    ax[2].set_ylabel("ξ(τ_α(a))")
    ax[2].legend()
    ax[2].set_title("τ_α(a) against a (paper, sec. 3.4)")
    ax[3].set_xlabel("ξ(τ_α(a))")
    ax[3].set_ylabel("χ4(τ_α(a))")
    ax[3].legend(fontsize=8)
    ax[3].set_title("χ4 against ξ for each cutoff a (paper, sec. 3.4)")
    f = A.save(fig, "cutoff.png")
    short = [f"{a:g}" for a in cuts if reached.get(a, 0) < len(pts)]
    lags = min(reach(p) for p in pts)
    A.row(f"ξ(τ_α) against a ({cuts[0]:g} to {cuts[-1]:g}) for all φ; χ4(t) for several a", "3.4, figs. xi-vs-a, chi4-diff-a",
          "figure only", f"{len(cuts)} cutoffs, {len(pts)} densities (φ {pts[0].phi:g}-{pts[-1].phi:g}), study {', '.join(src)} (lags to {lags:.3g} τ_α({A_MAIN:g}))" +
          (f"; ξ at τ_α(a) not determined at some φ for a = {', '.join(short)} (τ_α(a) beyond the lags, "
           f"{lags:.3g} τ_α({A_MAIN:g}), or ξ < {XI_MIN:g})" if short else ""), "figure", f, pts)
    # At the main cutoff the same fit is the main series' d_f' row, whose
    # points may come from larger boxes (--largest-n): said beside it.
    main = A.fits.get("chi4_xi")
    sizes = sorted({p.N for p in A.series()})
    span = f"{sizes[0]}" + (f"-{sizes[-1]}" if sizes and sizes[-1] != sizes[0] else "") if sizes else "?"
    for a, fd in outs:
        note = (fd.note + ("; " if fd.note else "") + f"ξ ≥ {XI_MIN_DF:g}, as the main series"
                + (f"; N = {', '.join(str(n) for n in sorted({p.N for p in pts}))} ({', '.join(src)})" if pts else ""))
        if abs(a - A_MAIN) < 1e-9 and main is not None and main.ok:
            note += (f"; the main series' d_f' at a = {A_MAIN:g} (ξ ≥ {XI_MIN_DF:g}, N {span}): "
                     f"{fmt(main.p['s'], main.error('s'))}, {fit_verdict(main, 's', 1.6)}")
        A.row(f"χ4 ∝ ξ^d_f' at a = {a:g} (at τ_α(a))", "3.4, fig. diff-a(b)", "similar for all a (≈ 1.6)", fmt(fd.p["s"], fd.error("s")),
              fit_verdict(fd, "s", 1.6), f, pts, note)
