"""Section 3.1: Q(t), tau_alpha(phi) (power law and VFT), ageing."""
import math

import matplotlib.pyplot as plt
import numpy as np

from .. import fits as sf
from .config import A_MAIN, EPS_MAIN, PHI_AGE
from .points import fit_series, series_arrays
from .quantities import cut, tau
from .verdicts import fit_verdict, fixed_xc_row, fmt, verdict
from .plotting import colours, errorbar


def overlap_results(A):
    pts = A.series()
    cs = colours(len(pts))
    fig, ax = plt.subplots(1, 3, figsize=(16, 4.6))
    for p, col in zip(pts, cs):
        r = p.runs[0]
        c = cut(r)
        qm = np.nanmean([cut(x)["q"] for x in p.runs], axis=0)
        ax[0].semilogx(c["lag"], qm, "-o", ms=2, color=col, label=f"φ = {p.phi:g}")
        t = p.mean(tau)[0]
        ax[1].semilogx(c["lag"] / t, qm, "-", color=col)
    for a_ in ax[:2]:
        a_.axhline(1 / math.e, color="k", lw=0.6, ls=":")
        a_.set_ylabel("Q(t)")
    ax[0].set_xlabel("t")
    ax[1].set_xlabel("t / τ_α")
    ax[0].legend(fontsize=7, ncol=2)
    ax[0].set_title(f"Q(t), ε = {EPS_MAIN:g}, a = {A_MAIN:g} (paper, sec. 3.1)")
    ax[1].set_title("Q against t/τ_α (paper, sec. 3.1)")
    allp = [p for k, p in A.points.items() if k[0] == "neighbours"]
    xs = np.linspace(-6, 6, 200)
    for p in allp:
        b, t0 = p.mean(lambda r: (cut(r)["beta"], cut(r)["beta_err"]))[0], p.mean(lambda r: (cut(r)["tau0"], cut(r)["tau0_err"]))[0]
        if not (np.isfinite(b) and np.isfinite(t0)):
            continue
        c = cut(p.runs[0])
        qm = np.nanmean([cut(x)["q"] for x in p.runs], axis=0)
        ax[2].plot(b * np.log(c["lag"] / t0), qm, ".", ms=2, color=plt.cm.plasma((p.eps - 0.65) / 0.4))
    ax[2].plot(xs, 1 / (np.exp(xs) + 1), "k-", lw=1, label="1/(e^x + 1)")
    ax[2].plot(xs[xs > 0], np.exp(-xs[xs > 0]), "k--", lw=0.8, label="(t/τ0)^-β")
    ax[2].set_yscale("log")
    ax[2].set_ylim(1e-3, 1.2)
    ax[2].set_xlabel("x = β ln(t/τ0)")
    ax[2].set_ylabel("Q")
    ax[2].set_title("Q against β ln(t/τ0), all φ and ε (colour: ε; paper, sec. 3.1)")
    ax[2].legend(fontsize=8)
    fq = A.save(fig, "overlap.png")
    # beta(tau0), tau_alpha(tau0) (inset of the collapse figure), eps = 0.9
    fb = A.fit("beta_of_tau0", fit_series(pts, lambda r: (cut(r)["beta"], cut(r)["beta_err"]), sf.power,
                                          xrun=lambda r: (cut(r)["tau0"], cut(r)["tau0_err"])))
    ft = A.fit("tau_alpha_of_tau0", fit_series(pts, tau, sf.power, xrun=lambda r: (cut(r)["tau0"], cut(r)["tau0_err"])))
    fig, ax = plt.subplots(figsize=(5.5, 4.2))
    for fn, lab, m in ((lambda r: (cut(r)["beta"], cut(r)["beta_err"]), "β", "o"), (tau, "τ_α", "s")):
        x, y, e = [], [], []
        for p in pts:
            x.append(p.mean(lambda r: (cut(r)["tau0"], 0))[0])
            mm = p.mean(fn)
            y.append(mm[0])
            e.append(mm[1])
        errorbar(ax, x, y, e, fmt=m, ms=4, label=lab)
    for f, lab in ((fb, "β"), (ft, "τ_α")):
        if f.ok:
            xx = np.geomspace(*f.x_range, 50)
            ax.plot(xx, f.p["A"] * xx ** f.p["s"], "k-", lw=0.7)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("τ0")
    ax.legend()
    ax.set_title(f"inset: β ∝ τ0^{fb.p['s']:.3g}, τ_α ∝ τ0^{ft.p['s']:.3g} (ε = 0.9)")
    fi = A.save(fig, "beta_tau0.png")
    A.row("Q(t) for all φ; Q against t/τ_α (no time-density superposition)", "3.1, figs. Q-t, Qoftovertaualpha",
          "figure only", f"{len(pts)} densities, {sum(len(p.runs) for p in pts)} runs", "figure", fq, pts)
    A.row("Q against β ln(t/τ0): collapse for all φ and ε", "3.1, fig. Qofbetalntovertau0", "figure only",
          f"{len(allp)} points", "figure", fq, allp)
    A.row("β(τ0): power-law exponent (ε = 0.9)", "3.1, inset of fig. Qofbetalntovertau0", "figure only (power law)",
          fmt(fb.p["s"], fb.error("s")) + f", χ²/dof {fb.chi2_dof():.2g}", "figure", fi, pts, fb.note)
    A.row("τ_α(τ0): power-law exponent (ε = 0.9)", "3.1, inset of fig. Qofbetalntovertau0", "figure only (power law)",
          fmt(ft.p["s"], ft.error("s")) + f", χ²/dof {ft.chi2_dof():.2g}", "figure", fi, pts, ft.note)


def tau_fits(A, pts, tag, fn=tau):
    """Power law and VFT for a relaxation time against phi (fn: per run
    (value, error); tau_alpha by default), over every density of the series."""
    fp = A.fit(f"tau_power_{tag}", fit_series(pts, fn, sf.critical))
    fv = A.fit(f"tau_vft_{tag}", fit_series(pts, fn, sf.vft))
    return fp, fv


def better(fp, fv):
    """Which form fits better: the smaller chi2 over the same points (both have three parameters)."""
    if not (fp.ok and fv.ok):
        return "not compared"
    w = "VFT" if fv.chi2 < fp.chi2 else "power law"
    return f"{w} (χ²/dof {fv.chi2_dof():.2g} VFT, {fp.chi2_dof():.2g} power law, {fp.n} points)"


def tau_results(A, joint=None):
    pts = A.series()
    fp, fv = tau_fits(A, pts, "eps0.9")
    fig, ax = plt.subplots(figsize=(6, 4.5))
    x, y, e = series_arrays(pts, tau)
    errorbar(ax, x, y, e, fmt="o", ms=4, color="k", label="ε = 0.9, neighbour pairs")
    xx = np.linspace(x.min() if len(x) else 0.6, x.max() if len(x) else 0.8, 200)
    if fp.ok:
        ax.plot(xx, fp.p["A"] * (fp.p["xc"] - xx) ** -fp.p["g"], "--", label=f"(φc-φ)^-γ: φc = {fp.p['xc']:.4f}, γ = {fp.p['g']:.3g}")
    if fv.ok:
        ax.plot(xx, fv.p["A"] * np.exp(fv.p["B"] / (fv.p["x0"] - xx)), "-", label=f"exp[B/(φ0-φ)]: φ0 = {fv.p['x0']:.4f}, B = {fv.p['B']:.3g}")
    ax.set_yscale("log")
    ax.set_xlabel("φ")
    ax.set_ylabel("τ_α")
    ax.legend(fontsize=8)
    ax.set_title("τ_α(φ), ε = 0.9, with the power-law and VFT fits (paper, sec. 3.1)")
    f = A.save(fig, "tau_alpha_phi.png")
    A.row("τ_α(φ) power law: φ_c", "3.1, fig. taueps09", "0.82", fmt(fp.p["xc"], fp.error("xc"), 4), fit_verdict(fp, "xc", 0.82), f, pts, fp.note)
    A.row("τ_α(φ) power law: γ", "3.1, fig. taueps09", "not given", fmt(fp.p["g"], fp.error("g")), "—", f, pts, fp.note)
    fixed_xc_row(A, "tau_power_eps0.9_xc_joint", "τ_α(φ) power law: γ", "3.1, fig. taueps09", "not given", tau, pts, joint, f)
    A.row("τ_α(φ) VFT: φ_0", "3.1, fig. taueps09", "0.83", fmt(fv.p["x0"], fv.error("x0"), 4), fit_verdict(fv, "x0", 0.83), f, pts, fv.note)
    A.row("τ_α(φ) VFT: B", "3.1, fig. taueps09", "not given", fmt(fv.p["B"], fv.error("B")), "—", f, pts, fv.note)
    # "the inverse power law ... only works for a narrower range of values of phi": the densities from 0.74 up
    fn = A.fit("tau_power_eps0.9_narrow", fit_series(pts, tau, sf.critical, x_range=(0.74, 1.0)))
    A.row("τ_α(φ) power law over the narrower range φ ≥ 0.74: φ_c", "3.1, fig. taueps09", "0.82",
          fmt(fn.p["xc"], fn.error("xc"), 4) + f", γ {fmt(fn.p['g'], fn.error('g'))}, χ²/dof {fn.chi2_dof():.2g}",
          fit_verdict(fn, "xc", 0.82), f, [p for p in pts if p.phi >= 0.74], fn.note)
    # Which of two forms fits better says nothing when neither describes
    # the points (both chi2 improbable): not judged, with the reason.
    neither = fp.ok and fv.ok and sf.cannot_judge(fp) and sf.cannot_judge(fv)
    A.row("τ_α(φ): which form fits better (smaller χ² over the same points)", "3.1", "VFT", better(fp, fv),
          "not judged: neither form describes the points (both χ² improbable)" if neither else
          ("agrees" if "VFT (" in better(fp, fv) else "differs") if fp.ok and fv.ok else "not determined", f, pts)
    return fp, fv


def ageing_results(A):
    pts = A.series()
    fig, ax = plt.subplots(figsize=(6, 4.2))
    out = []
    used = []
    for phi in PHI_AGE:
        p = A.nearest(pts, phi)
        if p is None or p in used:
            continue
        used.append(p)
        fits = []
        for r in p.runs:
            c = cut(r)
            t0, tt = np.asarray(c["t0"], float), np.asarray(c["tau_t0"], float)
            m = np.isfinite(tt)
            ax.plot(t0[m], tt[m], "o-", ms=3, label=f"φ = {p.phi:g}, seed {r['seed']}")
            if m.sum() >= 3:
                tm = c["tau_alpha"]
                fits.append(sf.slope_with_error(t0[m] / tm, tt[m] / tm))
        s, se, n = sf.seed_mean([f[0] for f in fits])
        note = f"jackknife over {n} seeds" if n > 1 else ""
        own = [f[1] for f in fits if np.isfinite(f[0])]
        why = ""
        if 1 < n < sf.MIN_JK_SEEDS and all(np.isfinite(own)):
            # two or three seeds: their spread (one or two dof) is not taken alone, as for a
            # fit (sf.MIN_JK_SEEDS): at least the seeds' own errors (origins about the line) combined
            own_se = math.sqrt(sum(e * e for e in own)) / n
            if own_se > se:
                note += f"; the seeds' own errors combined, {own_se:.2g}, over their spread's {se:.2g}"
                se = own_se
        elif 1 < n < sf.MIN_JK_SEEDS:
            # a seed without an error of its own (fewer than 4 origins, or origins closer
            # than its tau_alpha: sf.slope_with_error): the spread alone would be all
            # there is, and it is not taken alone
            missing = sum(1 for e in own if not np.isfinite(e))
            why = (f"not judged: {n} seeds, {missing} of them with no error of its own (fewer than 4 "
                   f"origins, or origins closer than its τ_α), and the spread of {n} seeds ({n - 1} dof) "
                   f"is not taken alone")
        if n == 1 and np.isfinite(fits[0][1]):
            # one seed: the error from its origins' scatter about the line
            # (sf.slope_with_error takes it only where the origins lie at least
            # tau_alpha apart, so their tau_alpha(t0) are independent)
            s, se = fits[0][0], fits[0][1]
            note = f"one seed: error from its {fits[0][2]} origins' scatter about the line"
        out.append((p, s, se, note, why))
    ax.set_xlabel("t0")
    ax.set_ylabel("τ_α(t0)")
    ax.legend(fontsize=6, ncol=2)
    ax.set_title("τ_α(t0) against the waiting time: no ageing (paper, sec. 3.1)")
    f = A.save(fig, "tau_alpha_t0.png")
    for p, s, se, note, why in out:
        A.row(f"τ_α(t0) at φ = {p.phi:g}: slope d(τ_α/τ̄_α)/d(t0/τ̄_α)", "3.1, inset of fig. Q-t-t0", "0 (no ageing)",
              fmt(s, se, 2), why or verdict(s, se, 0.0), f, [p], note)

