"""Section 3.2: D against tau_alpha, P(dx)."""
import matplotlib.pyplot as plt
import numpy as np

from .. import fits as sf
from .config import A_MAIN, PHI_HIGH, PHI_INTERMEDIATE, PHI_PDX
from .points import fit_series
from .quantities import tau
from .verdicts import fit_verdict, fmt
from .plotting import errorbar


def d_results(A):
    pts = A.series()
    dfn = lambda r: (r["D"], r["D_err"])
    fi = A.fit("D_tau_intermediate", fit_series([p for p in pts if PHI_INTERMEDIATE[0] <= p.phi <= PHI_INTERMEDIATE[1]], dfn, sf.power, xrun=tau))
    fh = A.fit("D_tau_high", fit_series([p for p in pts if PHI_HIGH[0] <= p.phi <= PHI_HIGH[1]], dfn, sf.power, xrun=tau))
    fig, ax = plt.subplots(figsize=(6, 4.5))
    xs, ys, es = [], [], []
    for p in pts:
        xs.append(p.mean(tau)[0])
        m = p.mean(dfn)
        ys.append(m[0])
        es.append(m[1])
    errorbar(ax, xs, ys, es, fmt="o", ms=4, color="k")
    for f, ls, lab in ((fi, "-", "θ"), (fh, "--", "θ'")):
        if f.ok:
            xx = np.geomspace(*f.x_range, 20)
            ax.plot(xx, f.p["A"] * xx ** f.p["s"], ls, label=f"{lab} = {-f.p['s']:.3g} (τ_α {f.x_range[0]:.3g}-{f.x_range[1]:.3g})")
    if len(xs):
        xx = np.geomspace(min(xs), max(xs), 10)
        ax.plot(xx, ys[0] * xs[0] / xx, ":", color="gray", label="Stokes-Einstein D ∝ 1/τ_α")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("τ_α")
    ax.set_ylabel("D")
    ax.legend(fontsize=8)
    ax.set_title("D against τ_α (paper, sec. 3.2; D: long-time MSD/4t)")
    f = A.save(fig, "D_tau_alpha.png")
    sub_i = [p for p in pts if PHI_INTERMEDIATE[0] <= p.phi <= PHI_INTERMEDIATE[1]]
    sub_h = [p for p in pts if PHI_HIGH[0] <= p.phi <= PHI_HIGH[1]]
    A.row(f"D ∝ τ_α^-θ at intermediate densities (φ ≤ {PHI_INTERMEDIATE[1]})", "3.2, fig. D-vs-tau", "θ ≈ 1.47",
          fmt(-fi.p["s"], fi.error("s")), fit_verdict(fi, "s", 1.47, lambda v: -v), f, sub_i, fi.note)
    A.row(f"D ∝ τ_α^-θ' at the highest densities (φ ≥ {PHI_HIGH[0]})", "3.2, fig. D-vs-tau", "θ' ≈ 0.91",
          fmt(-fh.p["s"], fh.error("s")), fit_verdict(fh, "s", 0.91, lambda v: -v), f, sub_h, fh.note)


def pdx_results(A):
    pts = A.series()
    fig, ax = plt.subplots(figsize=(6, 4.5))
    used = []
    for phi, col in zip(PHI_PDX, ("C0", "C1", "C3")):
        p = A.nearest(pts, phi)
        if p is None or p in used or "pdx" not in p.runs[0]:
            continue
        used.append(p)
        r = p.runs[0]
        tgt = np.asarray(r["pdx_target"], float)
        li = int(np.nanargmin(np.abs(tgt - 1.0))) if np.any(np.isfinite(tgt)) else 1
        pm = np.nanmean([x["pdx"][1, li] for x in p.runs], axis=0)  # small particles, as the paper
        ax.semilogy(r["pdx_x"], pm, "-", color=col, label=f"φ = {p.phi:g}, t = {r['pdx_lag'][li]:.3g} (τ_α {r['cut'][A_MAIN]['tau_alpha']:.3g})")
    ax.set_xlim(-6, 6)
    ax.set_ylim(1e-5, None)
    ax.set_xlabel("Δx (small particles)")
    ax.set_ylabel("P(Δx, τ_α)")
    ax.legend(fontsize=8)
    ax.set_title("P(Δx) at τ_α (paper, sec. 3.2)")
    f = A.save(fig, "pdx.png")
    A.row("P(Δx) at τ_α for three densities: exponential tails", "3.2, fig. tails(a)", "figure only",
          ", ".join(f"φ = {p.phi:g}" for p in used), "figure", f, used)
