"""The figure of S4(q,t) of a dynhet run (HDF5, H5MD layout): per cutoff a, a grid
of panels (at most three a row), one per sub-box grid: S4(q) at the lag
t_s4 nearest that cutoff's tau_alpha, log-log, with the OZ fit
chi0/(1 + (q xi)^2) and the fit with A^2 (q xi)^4 over their ranges (the
dotted lines end them), chi4 at the same t as a square at the left; and a
last panel with xi(t) of the OZ fit of every grid at every computed lag,
with its error.
Where the run has s4_cr (observables.cage_relative), the cage-relative S4(q)
at its own t_s4 (the cage-relative tau_alpha) is in the same panels, open
markers, with its OZ fit (dash-dot) and chi4 (open square); its xi(t) dashed.

"""
import math
import sys
import textwrap

from .common import pm, legend_below, save, tidy_log
import matplotlib.pyplot as plt
import numpy as np

from .. import schema
from ..run import open_run
from ..scene import default


def plot_cage_relative(ax, c, gi, qmin):
    """The cage-relative S4(q) of grid gi at its t_s4, its OZ fit and chi4."""
    start = np.concatenate([[0], np.cumsum(c["n_shells"][()])])
    sl = slice(start[gi], start[gi + 1])
    q, s, e = c["q"][()][sl], c["s4"][sl], c["s4_err"][sl]
    ok = (q > 0) & np.isfinite(s) & (s > 0)
    t = float(c["t_s4"])
    ax.errorbar(q[ok], s[ok], yerr=np.nan_to_num(e[ok]), fmt="o", mfc="none", color="C4", ms=3.5, capsize=2,
                label=f"cage-relative $S_4(q)$ at t = {t:.3g}")
    chi4, chi4_err = c["chi4"][gi], c["chi4_err"][gi]
    if math.isfinite(chi4):
        ax.errorbar([qmin / 2], [chi4], yerr=[np.nan_to_num(chi4_err)], fmt="s", mfc="none", color="C4", ms=5,
                    capsize=2, label=rf"cage-relative $\chi_4$ = {chi4:.3g}")
    chi0, xi, xi_err = c["oz_chi0"][gi], c["oz_xi"][gi], c["oz_xi_err"][gi]
    if math.isfinite(xi) and math.isfinite(chi0):
        qq = np.geomspace(qmin / 2, q.max() if len(q) else 1.0, 100)
        ax.plot(qq, chi0 / (1 + (qq * xi) ** 2), "-.", color="C4",
                label=rf"cage-relative OZ: $\xi$ = {pm(xi, xi_err)}, $\chi_0$ = {pm(chi0, c['oz_chi0_err'][gi])}")


# What the s4 node's xi_lag_rule codes say (run.h5's xi_lag_rule attribute).
RULES = {1: "fewer than 3 q shells with q ξ ≤ 1", 2: "ξ below the q range (q ξ < 0.5 at the largest q fitted)",
         3: "the fit did not converge"}


def no_fit_reason(g, gi):
    """Why grid gi has no fit at t_s4, from what the run recorded: too few q
    shells in a sub-box that small, the node's rule at the lags around t_s4,
    or a jackknife error of ξ not below ξ (the rule the node applies at t_s4)."""
    n = int(g["n_shells"][gi])
    q_max = float(g.attrs.get("q_max", default("s4", "q_max")))
    if n < 3:
        return f"{n} q shell{'s' if n != 1 else ''} below q = {q_max:g} in a sub-box this small (3 needed)"
    rules = g["xi_lag_rule"]
    at = {int(rules[int(g[k]), gi]) for k in ("lag_lo", "lag_hi") if 0 <= int(g[k]) < len(rules)} - {0}
    if at:
        return "; ".join(RULES.get(r, f"rule {r}") for r in sorted(at)) + " (at the lags around $t_{s4}$)"
    return r"the jackknife error of $\xi$ at $t_{s4}$ is not below $\xi$"


def plot_grid(ax, g, gi, start, cr=None):
    """S4(q) of grid gi at t_s4 with both fits and chi4 at the same t (and
    the cage-relative ones of group cr, if given)."""
    sizes, sides = g["subbox_particles"][()], g["subbox_per_side"][()]
    q_all, s4, s4_err = g["q"][()], g["s4"], g["s4_err"]
    sl = slice(start[gi], start[gi + 1])
    q, s, e = q_all[sl], s4[sl], s4_err[sl]
    ok = (q > 0) & np.isfinite(s) & (s > 0)
    ax.errorbar(q[ok], s[ok], yerr=np.nan_to_num(e[ok]), fmt="o", ms=3.5, capsize=2, label="$S_4(q)$")
    chi4, chi4_err = g["chi4"][gi], g["chi4_err"][gi]
    qmin = q[ok].min() if ok.any() else 0.1
    if math.isfinite(chi4):
        ax.errorbar([qmin / 2], [chi4], yerr=[np.nan_to_num(chi4_err)], fmt="s", color="k", ms=5,
                    capsize=2, label=rf"$\chi_4$ = {chi4:.3g} at q = 0")
    missing = []
    for form, color in (("oz", "C1"), ("a2", "C2")):
        chi0, xi = g[f"{form}_chi0"][gi], g[f"{form}_xi"][gi]
        xi_err, chi0_err = g[f"{form}_xi_err"][gi], g[f"{form}_chi0_err"][gi]
        qf = g[f"{form}_q_fit_max"][gi]
        name = "OZ" if form == "oz" else "OZ + $A^2(q\\xi)^4$"
        if not (math.isfinite(xi) and math.isfinite(chi0)):
            missing.append(name)
            continue
        a = g["a2_a"][gi] if form == "a2" else 0.0
        qq = np.geomspace(qmin / 2, q.max() if len(q) else 1.0, 100)
        x2 = (qq * xi) ** 2
        extra = f", A = {a:.2g}" if form == "a2" else ""
        ax.plot(qq, chi0 / (1 + x2 + a * a * x2 * x2), "-" if form == "oz" else "--", color=color,
                label=rf"{name}: $\xi$ = {pm(xi, xi_err)}, $\chi_0$ = {pm(chi0, chi0_err)}{extra}")
        ax.axvline(qf, color=color, lw=0.8, ls=":")
    if cr is not None and gi < len(cr["subbox_per_side"]):
        plot_cage_relative(ax, cr, gi, qmin)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("q")
    ax.set_ylabel(r"$S_4(q, t_{s4})$")
    title = f"a = {g.attrs['cutoff_a']:g}: sub-boxes of N = {sizes[gi]:.0f} (m = {sides[gi]})"
    if missing:
        title += "\n" + textwrap.fill("no " + " or ".join(missing) + " fit: " + no_fit_reason(g, gi), 62)
    ax.set_title(title)
    tidy_log(ax)
    legend_below(ax)


def lag_error(g, gi):
    """xi_lag's error of grid gi per lag (0 where the node quotes none: the
    blocks of its jackknife cannot span the lag), or None for a run recorded
    before the node computed it."""
    return np.nan_to_num(g["xi_lag_err"][:, gi]) if "xi_lag_err" in g else None


def plot_xi(ax, g, cr=None):
    """OZ xi(t) of every grid at every computed lag with its error (a
    jackknife over blocks of origins spanning the lag; none where they
    cannot), t_s4 marked (and the cage-relative xi(t), dashed)."""
    sizes, lags = g["subbox_particles"][()], g["lag_time"][()]
    t_s4, tau_alpha = float(g["t_s4"]), float(g["tau_alpha"])
    xi_lag = g["xi_lag"]  # [lag][grid]
    for gi in range(len(sizes)):
        line = ax.errorbar(lags, xi_lag[:, gi], yerr=lag_error(g, gi), marker="o", ms=3, capsize=2,
                           label=f"sub-boxes of N = {sizes[gi]:.0f}")
        if cr is not None and gi < cr["xi_lag"].shape[1]:
            ax.errorbar(cr["lag_time"][()], cr["xi_lag"][:, gi], yerr=lag_error(cr, gi), marker="o", ls="--", ms=3,
                        mfc="none", capsize=2, color=line[0].get_color(), label=f"N = {sizes[gi]:.0f}, cage-relative")
    ax.axvline(t_s4, color="k", lw=0.8, ls=":", label=rf"$t_{{s4}}$ = {t_s4:.3g} ($\tau_\alpha$ = {tau_alpha:.3g})")
    ax.set_xscale("log")
    ax.set_xlabel("t")
    ax.set_ylabel(r"OZ $\xi(t)$")
    ax.set_title(f"a = {g.attrs['cutoff_a']:g}: OZ $\\xi$ against the lag" +
                 ("\n(bars: jackknife over blocks of origins spanning the lag;\nnone where the origins hold too few)"
                  if "xi_lag_err" in g else ""))
    tidy_log(ax)
    legend_below(ax)


def main(path, png):
    with open_run(path) as run:
        if "s4" not in run.observables() or not run.cutoffs("s4"):
            print(f"plot_s4: {path} has no s4 results", file=sys.stderr)
            return 1
        groups = [run.s4(a) for a in run.cutoffs("s4")]
        s4_cr = schema.cage_relative("s4")
        crs = [run.observable(s4_cr, a) if a in run.cutoffs(s4_cr) else None for a in run.cutoffs("s4")]
        # Per cutoff its grids' panels and the xi(t) panel, at most three a
        # row (two when there are four): a grid of panels, not a strip.
        panels = max(len(g["subbox_per_side"]) for g in groups) + 1
        cols = min(panels, 2 if panels == 4 else 3)
        rows_per = math.ceil(panels / cols)
        fig, axes = plt.subplots(rows_per * len(groups), cols, figsize=(5.2 * cols, 5.0 * rows_per * len(groups)),
                                 squeeze=False, layout="constrained")
        for k, (g, cr) in enumerate(zip(groups, crs)):
            block = axes[k * rows_per:(k + 1) * rows_per].ravel()
            ng = len(g["subbox_per_side"])
            start = np.concatenate([[0], np.cumsum(g["n_shells"][()])])
            for gi in range(ng):
                plot_grid(block[gi], g, gi, start, cr)
            plot_xi(block[ng], g, cr)
            for ax in block[ng + 1:]:
                ax.set_visible(False)
        save(fig, run, png, 100)
    print(f"plot_s4: wrote {png}", file=sys.stderr)
    return 0

