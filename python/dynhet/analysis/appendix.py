"""The appendix: chi0 of the OZ fits against chi4, and the fit range."""
import math

import matplotlib.pyplot as plt
import numpy as np

from .config import A_MAIN
from .quantities import chi4_at_tau, cut, oz_fit, oz_resolved, s4_at_tau, whole_box_s4
from .plotting import errorbar
from .verdicts import fmt


def whole_box(r, key):
    """(value, error) of a per-grid S4 result `key` for the run's whole box;
    an OZ chi0 only where its fit is resolved (oz_resolved: at least
    MIN_SHELLS q shells below q xi = 1)."""
    c = cut(r)
    g = whole_box_s4(c)
    if key != "s4_chi4" and not oz_resolved(c, g, c["s4_oz_xi"][g]):
        return math.nan, math.nan
    return c[key][g], c[key + "_err"][g]


def appendix_results(A):
    """chi0 of the whole box's S4 fits (fit 2: OZ, fit 3: with A^2; the finest
    q) against chi4 of the same whole box (N var(Q) over origins, the s4
    node's at t_s4): estimators of one box on both sides (an earlier version
    set the 455-particle sub-box's eq. (14) chi4, biased low, against the
    whole box's chi0); the largest proper sub-box's pooled chi4 is drawn
    beside them. And the OZ refit at tau_alpha over 0 < q <= q_m for
    several q_m, against the same whole-box chi4."""
    pts = A.series()
    fig, ax = plt.subplots(1, 2, figsize=(12, 4.5))
    rat = []
    qms = (0.1, 0.2, 0.3, 0.5, 1.0)
    x, c4, c4s, oz, a2 = [], [], [], [], []
    for p in pts:
        c = cut(p.runs[0])
        gw = whole_box_s4(c)
        x.append(p.phi)
        # each run's own whole box (the factor of points.calibration pools
        # these functions over a study whose points may have other grids)
        c4.append(p.mean(lambda r: whole_box(r, "s4_chi4")))
        c4s.append(p.mean(lambda r: chi4_at_tau(r)))
        oz.append(p.mean(lambda r: whole_box(r, "s4_oz_chi0")))
        a2.append(p.mean(lambda r: whole_box(r, "s4_a2_chi0")))
        row = []
        per_run = [(s4_at_tau(r, A_MAIN, gw), cut(r)["s4_chi4"][gw]) for r in p.runs]  # once, for every q_m
        for qm in qms:
            vals = []
            for (q, s), ref in per_run:
                ch0, _ = oz_fit(q, s, qm)
                vals.append(ch0 / ref if np.isfinite(ch0) and ref > 0 else math.nan)
            row.append(np.nanmean(vals) if np.any(np.isfinite(vals)) else math.nan)
        rat.append(row)
    x = np.array(x)
    for arr, m, lab in ((c4, "-", "χ4, whole box (N var Q)"), (c4s, ":", "χ4 (pooled), largest proper sub-box"),
                        (oz, "^", "χ0, fit 2 (OZ), whole box"),
                        (a2, "o", "χ0, fit 3 (with A²), whole box")):
        arr = np.array([v[:2] for v in arr])
        errorbar(ax[0], x, arr[:, 0], arr[:, 1], fmt=m, label=lab, mfc="none")
    ax[0].set_yscale("log")
    ax[0].set_xlabel("φ")
    ax[0].set_ylabel("χ at the s4 node's t_s4 (= its τ_α)")
    ax[0].legend(fontsize=8)
    ax[0].set_title("χ0 of the OZ fits against χ4 (paper, appendix)")
    rat = np.array(rat)
    for k, qm in enumerate(qms):
        ax[1].plot(x, rat[:, k], "o-", ms=3, label=f"q_m = {qm:g}")
    ax[1].axhline(1, color="k", lw=0.6)
    ax[1].set_xlabel("φ")
    ax[1].set_ylabel("χ0 (OZ over 0 < q ≤ q_m) / χ4(τ_α), whole box")
    ax[1].legend(fontsize=8)
    ax[1].set_title("robustness to the fit range [0, q_m]")
    f = A.save(fig, "appendix_chi0.png")
    oz_r, oz_e = ratios(oz, c4)
    a2_r, a2_e = ratios(a2, c4)
    med = lambda v, e: (f"median {fmt(*median_error(v, e))} (range {v.min():.3g}-{v.max():.3g}, {len(v)} φ)"
                        if len(v) else "not determined")
    A.row("appendix: χ0 (fit 2, OZ) / χ4, both of the whole box", "appendix, fig. fitting", "≈ 1 for all φ", med(oz_r, oz_e),
          near_one(*median_error(oz_r, oz_e)) if len(oz_r) else "not determined", f, pts, CRITERION)
    A.row("appendix: χ0 (fit 3, with A²) / χ4, both of the whole box", "appendix, fig. fitting", "≈ 1 for all φ", med(a2_r, a2_e),
          near_one(*median_error(a2_r, a2_e)) if len(a2_r) else "not determined", f, pts, CRITERION)
    spread = np.nanmax(rat, axis=1) - np.nanmin(rat, axis=1) if rat.size else np.array([])
    spread = spread[np.isfinite(spread)]
    A.row("appendix: χ0 robust to the fit range q_m", "appendix, fig. fitting", "robust",
          f"max - min of χ0/χ4 over q_m = {', '.join(f'{q:g}' for q in qms)}: median {np.median(spread):.2g} over φ" if len(spread) else "not determined",
          "figure", f, pts)


CRITERION = ("criterion: the median within 15% of 1 (the paper's ≈), or within 2 of its errors; its error from "
             "the φ's own errors (parametric bootstrap)")


def near_one(m, err, tol=0.15):
    """The verdict on "≈ 1" for a median m ± err: agrees within tol of 1 or
    within 2 errors (a difference the errors cannot tell is not claimed);
    else differs, with the distance in errors."""
    d = abs(m - 1)
    if d < tol or (np.isfinite(err) and err > 0 and d <= 2 * err):
        return "agrees"
    return f"differs ({d / err:.1f} σ)" if np.isfinite(err) and err > 0 else "differs"


def ratios(num, den):
    """The ratios num/den of [(value, error, ...)] pairs where both are
    measured, and their errors (relative errors in quadrature)."""
    r, e = [], []
    for o, c in zip(num, den):
        if np.isfinite(o[0]) and np.isfinite(c[0]) and c[0] > 0:
            r.append(o[0] / c[0])
            e.append(o[0] / c[0] * math.hypot(o[1] / o[0] if o[0] else math.nan, c[1] / c[0]))
    return np.array(r), np.array(e)


def median_error(v, e, draws=4000, seed=1):
    """(median of v, its error): the spread of the median when each value is
    redrawn within its own error. The measurement error of the median, not
    the spread of the values (the range says that); NaN where a value has no
    error (holding it fixed would make the median's error too small)."""
    v, e = np.asarray(v, float), np.asarray(e, float)
    if not np.all(np.isfinite(e)):
        return float(np.median(v)), math.nan
    rng = np.random.default_rng(seed)
    meds = np.median(v[None, :] + e[None, :] * rng.standard_normal((draws, len(v))), axis=1)
    return float(np.median(v)), float(np.std(meds))
