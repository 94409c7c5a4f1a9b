"""Section 3.4: chi4(t), tau4, S4, xi, the joint critical fit, the finite-size scaling of chi4^P."""
import math

import matplotlib.pyplot as plt
import numpy as np

from .. import fits as sf
from .config import XI_MIN_DF
from .points import fit_series, seeds_of, series_arrays
from .quantities import chi0_at_tau, chi4_at_tau, cut, interior_note, proper_subbox, s4_at_tau, tau, tau4_of, xi_at_tau
from .verdicts import fit_verdict, fixed_xc_row, fmt, range_scan
from .plotting import colours, errorbar


def chi4_results(A, phi_c_tau, joint=None):
    pts = A.series()
    fig, ax = plt.subplots(1, 3, figsize=(16, 4.5))
    for p, col in zip(pts, colours(len(pts))):
        c = cut(p.runs[0])
        g = proper_subbox(c, p.N)
        cm = np.nanmean([cut(r)["chi4"][g] for r in p.runs], axis=0)
        ax[0].semilogx(c["chi4_lag"], cm, "-", color=col, label=f"{p.phi:g}")
    ax[0].set_xlabel("t")
    ax[0].set_ylabel("χ4(t)")
    if pts:
        c = cut(pts[0].runs[0])
        ax[0].set_title(f"χ4(t) (paper, sec. 3.4), sub-box N = {c['chi4_N'][proper_subbox(c, pts[0].N)]:.4g}")
    ax[0].legend(fontsize=6, ncol=2)
    t4 = lambda r: tau4_of(r, proper_subbox(cut(r), r["N"]))
    sub = [p for p in pts if p.phi <= 0.80 + 1e-9]
    f4 = A.fit("tau4_tau_alpha", fit_series(sub, t4, sf.power, xrun=tau))
    x, y, e = [], [], []
    for p in pts:
        x.append(p.mean(tau)[0])
        m = p.mean(t4)
        y.append(m[0])
        e.append(m[1])
    errorbar(ax[1], x, y, e, fmt="o", ms=4)
    if f4.ok:
        xx = np.geomspace(*f4.x_range, 20)
        ax[1].plot(xx, f4.p["A"] * xx ** f4.p["s"], "k--", label=f"τ4 ∝ τ_α^{f4.p['s']:.3g}")
    ax[1].set_xscale("log")
    ax[1].set_yscale("log")
    ax[1].set_xlabel("τ_α")
    ax[1].set_ylabel("τ4")
    ax[1].legend()
    ax[1].set_title("τ4 against τ_α (paper, sec. 3.4)")
    fc = A.fit("chi4_tau_phi", fit_series(pts, chi4_at_tau, sf.critical))
    x, y, e = series_arrays(pts, chi4_at_tau)
    errorbar(ax[2], x, y, e, fmt="o", ms=4)
    if fc.ok:
        xx = np.linspace(x.min(), x.max(), 100)
        ax[2].plot(xx, fc.p["A"] * (fc.p["xc"] - xx) ** -fc.p["g"], "--", label=f"φc = {fc.p['xc']:.4f}, γχ = {fc.p['g']:.3g}")
    ax[2].set_yscale("log")
    ax[2].set_xlabel("φ")
    ax[2].set_ylabel("χ4(τ_α)")
    ax[2].legend(fontsize=8)
    ax[2].set_title("χ4(τ_α) against φ")
    f = A.save(fig, "chi4.png")
    A.row("χ4(t) for all φ", "3.4, fig. chi4", "figure only", f"{len(pts)} densities", "figure", f, pts)
    A.row("τ4 ∝ τ_α^z (φ ≤ 0.80)", "3.4, inset of fig. chi4", "1.19", fmt(f4.p["s"], f4.error("s")), fit_verdict(f4, "s", 1.19), f, sub,
          "; ".join(x for x in (f4.note, interior_note(sub, lambda r: proper_subbox(cut(r), r["N"]))) if x))
    whole = lambda r: int(np.argmax(cut(r)["chi4_N"]))
    t4w = lambda r: tau4_of(r, whole(r))
    f4w = A.fit("tau4_box_tau_alpha", fit_series(sub, t4w, sf.power, xrun=tau))
    A.row("the same with τ4 of the whole box (no sub-box)", "3.4, inset of fig. chi4", "1.19", fmt(f4w.p["s"], f4w.error("s")),
          fit_verdict(f4w, "s", 1.19), f, sub, "; ".join(x for x in (f4w.note, interior_note(sub, whole)) if x))
    A.row("χ4(τ_α) ∝ (φ_c - φ)^-γχ: γχ (own φ_c)", "3.4 (from ref. AvilaPRL2014)", "≈ 2.5", fmt(fc.p["g"], fc.error("g")),
          fit_verdict(fc, "g", 2.5), f, pts, fc.note)
    A.row("χ4(τ_α) ∝ (φ_c - φ)^-γχ: φ_c", "3.4", "≈ 0.82", fmt(fc.p["xc"], fc.error("xc"), 4), fit_verdict(fc, "xc", 0.82), f, pts, fc.note)
    fixed_xc_row(A, "chi4_tau_phi_xc_joint", "χ4(τ_α) ∝ (φ_c - φ)^-γχ: γχ", "3.4 (from ref. AvilaPRL2014)", "≈ 2.5",
                 chi4_at_tau, pts, joint, f)
    # The sub-box chi4 saturates once xi^2 approaches the sub-box; the whole
    # box's OZ chi0 (S4 extrapolated to q -> 0) has no sub-box: the same fit on it.
    f0 = A.fit("chi0_tau_phi", fit_series(pts, chi0_at_tau, sf.critical))
    A.row("the same with χ0 of the whole box's OZ fit in place of χ4: γχ", "3.4 (eq. 18: χ0 = lim S4(q→0))", "≈ 2.5",
          fmt(f0.p["g"], f0.error("g")), fit_verdict(f0, "g", 2.5), f, pts, f0.note)


def s4_results(A, joint):
    pts = A.series()
    fig, ax = plt.subplots(1, 2, figsize=(12, 4.5))
    for p, col in zip(pts, colours(len(pts))):
        qs = [s4_at_tau(r) for r in p.runs]
        q = qs[0][0]
        s = np.nanmean([x[1] for x in qs], axis=0)
        ax[0].loglog(q, s, "-o", ms=2, color=col, label=f"{p.phi:g}")
        xi = p.mean(xi_at_tau)[0]
        ch = p.mean(lambda r: chi0_at_tau(r))[0]
        if np.isfinite(xi) and np.isfinite(ch):
            ax[1].loglog(q * xi, s / ch, "o", ms=3, color=col)
    u = np.geomspace(0.05, 30, 100)
    ax[1].loglog(u, 1 / (1 + u * u), "k-", lw=0.8, label="OZ 1/(1+(qξ)²)")
    ax[0].set_xlabel("q")
    ax[0].set_ylabel("S4(q, τ_α), whole box")
    ax[0].legend(fontsize=6, ncol=2)
    ax[0].set_title("S4(q, τ_α) (paper, sec. 3.4)")
    ax[1].set_xlabel("q ξ")
    ax[1].set_ylabel("S4 / χ0")
    ax[1].legend()
    ax[1].set_title("S4/χ0 against qξ (paper, sec. 3.4; χ0: the OZ fit's q → 0 value)")
    f = A.save(fig, "s4.png")
    fx = A.fit("xi_phi", fit_series(pts, xi_at_tau, sf.critical))
    fz = A.fit("tau_xi", fit_series(pts, tau, sf.power, xrun=xi_at_tau))
    # d_f' over xi >= 3 (below, xi is a few particle sizes and the sub-box
    # chi4 is not yet in its scaling regime), with the lower bound scanned.
    fd = A.fit("chi4_xi", fit_series(pts, chi4_at_tau, sf.power, xrun=xi_at_tau, x_range=(XI_MIN_DF, math.inf)))
    fd_scan = {lo: fit_series(pts, chi4_at_tau, sf.power, xrun=xi_at_tau, x_range=(lo, math.inf)) for lo in (1.0, 2.0, 3.0, 4.0, 5.0)}
    fd_note, _ = range_scan(fd_scan, "s", "ξ_min")
    fig, ax = plt.subplots(1, 3, figsize=(16, 4.5))
    x, y, e = series_arrays(pts, xi_at_tau)
    errorbar(ax[0], x, y, e, fmt="o")
    if fx.ok:
        xx = np.linspace(x.min(), x.max(), 100)
        ax[0].plot(xx, fx.p["A"] * (fx.p["xc"] - xx) ** -fx.p["g"], "--", label=f"φc = {fx.p['xc']:.4f}, γξ = {fx.p['g']:.3g}")
    ax[0].set_yscale("log")
    ax[0].set_xlabel("φ")
    ax[0].set_ylabel("ξ(τ_α)")
    ax[0].legend(fontsize=8)
    for k, (fn, f_, lab) in enumerate(((tau, fz, "τ_α"), (chi4_at_tau, fd, "χ4(τ_α)"))):
        xs, ys, es = [], [], []
        for p in pts:
            xs.append(p.mean(xi_at_tau)[0])
            m = p.mean(fn)
            ys.append(m[0])
            es.append(m[1])
        errorbar(ax[k + 1], xs, ys, es, fmt="o")
        if f_.ok:
            xx = np.geomspace(*f_.x_range, 20)
            ax[k + 1].plot(xx, f_.p["A"] * xx ** f_.p["s"], "k--", label=f"∝ ξ^{f_.p['s']:.3g}")
        ax[k + 1].set_xscale("log")
        ax[k + 1].set_yscale("log")
        ax[k + 1].set_xlabel("ξ(τ_α)")
        ax[k + 1].set_ylabel(lab)
        ax[k + 1].legend()
    ax[0].set_title("ξ(φ)")
    ax[1].set_title("τ_α against ξ")
    ax[2].set_title("χ4(τ_α) against ξ(τ_α) (paper, sec. 3.4)")
    f2 = A.save(fig, "xi.png")
    nx = sum(1 for p in pts if np.isfinite(p.mean(xi_at_tau)[0]))
    A.row("S4(q, τ_α) for all φ; S4/χ4 against qξ collapse", "3.4, figs. S4, scalingS4", "figure only", f"{nx} of {len(pts)} densities with ξ", "figure", f, pts)
    A.row("ξ(τ_α) ∝ (φ_c - φ)^-γξ: γξ (own φ_c)", "3.4", "1.6", fmt(fx.p["g"], fx.error("g")), fit_verdict(fx, "g", 1.6), f2, pts, fx.note)
    A.row("τ_α ∝ ξ^z: z", "3.4 (z = γ_τ/γ_ξ)", "not given", fmt(fz.p["s"], fz.error("s")), "—", f2, pts, fz.note)
    A.row(f"χ4(τ_α) ∝ ξ^d_f': d_f' (ξ ≥ {XI_MIN_DF:g})", "3.4, fig. xi-chi_4-2", "≈ 1.6", fmt(fd.p["s"], fd.error("s")), fit_verdict(fd, "s", 1.6),
          f2, pts, "; ".join(x for x in (fd.note, fd_note) if x))
    fixed_xc_row(A, "xi_phi_xc_joint", "ξ(τ_α) ∝ (φ_c - φ)^-γξ: γξ", "3.4", "1.6", xi_at_tau, pts, joint, f2)
    fd0 = A.fit("chi0_xi", fit_series(pts, chi0_at_tau, sf.power, xrun=xi_at_tau, x_range=(XI_MIN_DF, math.inf)))
    A.row(f"the same with the whole box's OZ χ0 in place of the sub-box χ4: d_f' (ξ ≥ {XI_MIN_DF:g})", "3.4 (eq. 18)", "≈ 1.6",
          fmt(fd0.p["s"], fd0.error("s")), fit_verdict(fd0, "s", 1.6), f2, pts, fd0.note)
    if joint is not None and joint.ok:
        for k, paper in (("tau", "not given"), ("chi4", "2.5"), ("xi", "1.6")):
            g = joint.p[f"g_{k}"]
            A.row(f"joint fit of τ_α, χ4(τ_α), ξ(τ_α) with one φ_c: γ_{k}", "3.3 (φ_c from the simultaneous fit)", paper,
                  fmt(g, joint.error(f"g_{k}")), fit_verdict(joint, f"g_{k}", float(paper)) if paper[0].isdigit() else "—", f2, pts)
        A.row("joint fit: φ_c", "3.3", "0.82", fmt(joint.p["xc"], joint.error("xc"), 4), fit_verdict(joint, "xc", 0.82), f2, pts, joint.note)
    return fx


def fss_results(A, joint):
    pts = A.series()
    fig, ax = plt.subplots(1, 2, figsize=(12, 4.5))
    gc, gc_err = joint.derived(lambda q: q["g_chi4"] / q["g_xi"]) if joint is not None and joint.ok else (math.nan, math.nan)
    for p, col in zip(pts, colours(len(pts))):
        c = cut(p.runs[0])
        ns = np.asarray(c["chi4_N"], float)
        pk = np.nanmean([cut(r)["chi4_peak"] for r in p.runs], axis=0)
        ax[0].loglog(ns, pk, "-o", ms=3, color=col, label=f"{p.phi:g}")
        xi = p.mean(xi_at_tau)[0]
        if np.isfinite(xi) and np.isfinite(gc):
            ax[1].loglog(np.sqrt(ns) / xi, pk * xi ** -gc, "-o", ms=3, color=col)
    ax[0].set_xlabel("N (sub-box)")
    ax[0].set_ylabel("χ4^P")
    ax[0].legend(fontsize=6, ncol=2)
    ax[0].set_title("χ4 peak against the sub-box size (paper, sec. 3.4)")
    ax[1].set_xlabel("√N / ξ")
    ax[1].set_ylabel(f"χ4^P ξ^-(γχ/γξ), γχ/γξ = {gc:.3g} (joint fit)")
    ax[1].set_title("χ4 peak: finite-size collapse (paper, sec. 3.4)")
    f = A.save(fig, "chi4_peak_fss.png")
    A.row("finite-size scaling: χ4^P against sub-box N; collapse against √N/ξ", "3.4, fig. chi4P", "figure only",
          f"exponent ratio γχ/γξ = {fmt(gc, gc_err)} from our joint fit", "figure", f, pts)


def joint_fit(A):
    pts = A.series()
    seeds = seeds_of(pts)

    def one(drop):
        ser = {}
        for k, fn in (("tau", tau), ("chi4", chi4_at_tau), ("xi", xi_at_tau)):
            ser[k] = series_arrays(pts, fn, drop)
        return sf.critical_joint(ser)
    fit = sf.jackknife_over_seeds(one, seeds)
    # points of one seed (scale's largest N): the jackknife misses their noise (points.fit_series)
    fit.jk_partial = any(0 < p.mean(fn)[3] < 2 for p in pts for fn in (tau, chi4_at_tau, xi_at_tau))
    return A.fit("joint_tau_chi4_xi", fit)
