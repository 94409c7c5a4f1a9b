#!/usr/bin/python3
"""Plot S4(q,t) of a dynhet run (HDF5, H5MD layout), one row per cutoff a:
at the lag t_s4 nearest that cutoff's tau_alpha, log-log, one panel per
sub-box grid, with the OZ fit chi0/(1 + (q xi)^2) and the fit with
A^2 (q xi)^4 over their ranges, chi4 at the same t as a marker at the left;
a last panel in the row shows xi(t) of the OZ fit at every computed lag.

Usage: plot_s4.py RUN.h5 OUT.png
"""
import math
import sys

import h5py
from plot_common import cli, last, save
import matplotlib.pyplot as plt  # after plot_common, which sets the Agg backend
import numpy as np


def plot_grid(ax, g, gi, start):
    """S4(q) of grid gi at t_s4 with both fits and chi4 at the same t."""
    sizes, sides = g["subbox_particles"][()], g["subbox_per_side"][()]
    q_all, s4, s4_err = g["q"][()], last(g, "s4"), last(g, "s4_err")
    sl = slice(start[gi], start[gi + 1])
    q, s, e = q_all[sl], s4[sl], s4_err[sl]
    ok = (q > 0) & np.isfinite(s) & (s > 0)
    ax.errorbar(q[ok], s[ok], yerr=np.nan_to_num(e[ok]), fmt="o", ms=3, capsize=2, label="S4")
    chi4, chi4_err = last(g, "chi4")[gi], last(g, "chi4_err")[gi]
    qmin = q[ok].min() if ok.any() else 0.1
    if math.isfinite(chi4):
        ax.errorbar([qmin / 2], [chi4], yerr=[np.nan_to_num(chi4_err)], fmt="s", color="k", ms=5,
                    capsize=2, label=f"chi4 = {chi4:.3g}")
    lines = [f"a = {g.attrs['cutoff_a']:g}: N = {sizes[gi]:.0f} (m = {sides[gi]})"]
    for form, color in (("oz", "C1"), ("a2", "C2")):
        chi0, xi = last(g, f"{form}_chi0")[gi], last(g, f"{form}_xi")[gi]
        xi_err, chi0_err = last(g, f"{form}_xi_err")[gi], last(g, f"{form}_chi0_err")[gi]
        qf = last(g, f"{form}_q_fit_max")[gi]
        if not (math.isfinite(xi) and math.isfinite(chi0)):
            lines.append(f"{form}: no fit")
            continue
        a = last(g, "a2_a")[gi] if form == "a2" else 0.0
        qq = np.geomspace(qmin / 2, q.max() if len(q) else 1.0, 100)
        x2 = (qq * xi) ** 2
        ax.plot(qq, chi0 / (1 + x2 + a * a * x2 * x2), "-" if form == "oz" else "--", color=color,
                label="OZ" if form == "oz" else "OZ + A^2 (q xi)^4")
        ax.axvline(qf, color=color, lw=0.6, ls=":")
        extra = f", A={a:.2g}" if form == "a2" else ""
        lines.append(f"{form}: xi={xi:.3g}+-{xi_err:.2g}, chi0={chi0:.3g}+-{chi0_err:.2g}{extra}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("q")
    ax.set_ylabel(r"$S_4(q, t)$")
    ax.set_title("\n".join(lines), fontsize=7)
    ax.legend(fontsize=6)


def plot_xi(ax, g):
    """OZ xi(t) of every grid at every computed lag, t_s4 marked."""
    sizes, lags = g["subbox_particles"][()], g["lag_time"][()]
    t_s4, tau_alpha = float(last(g, "t_s4")), float(last(g, "tau_alpha"))
    xi_lag = last(g, "xi_lag")  # [lag][grid]
    for gi in range(len(sizes)):
        ax.plot(lags, xi_lag[:, gi], "o-", ms=2.5, label=f"N = {sizes[gi]:.0f}")
    ax.axvline(t_s4, color="k", lw=0.6, ls=":")
    ax.set_xscale("log")
    ax.set_xlabel("t")
    ax.set_ylabel(r"OZ $\xi(t)$")
    ax.set_title(f"a = {g.attrs['cutoff_a']:g}; fits at t = {t_s4:.3g} (tau_alpha = {tau_alpha:.3g})", fontsize=8)
    ax.legend(fontsize=6)


def main(path, png):
    with h5py.File(path, "r") as f:
        if "observables/s4" not in f or len(f["observables/s4"]) == 0:
            print(f"plot_s4: {path} has no s4 results", file=sys.stderr)
            return 1
        groups = sorted(f["observables/s4"].values(), key=lambda g: float(g.attrs["cutoff_a"]))
        cols = max(len(g["subbox_per_side"]) for g in groups) + 1
        fig, axes = plt.subplots(len(groups), cols, figsize=(4.2 * cols, 4.0 * len(groups)), squeeze=False)
        for row, g in zip(axes, groups):
            ng = len(g["subbox_per_side"])
            start = np.concatenate([[0], np.cumsum(g["n_shells"][()])])
            for gi in range(ng):
                plot_grid(row[gi], g, gi, start)
            plot_xi(row[ng], g)
            for ax in row[ng + 1:]:
                ax.set_visible(False)
        fig.tight_layout()
        save(fig, f, png, 120)
    print(f"plot_s4: wrote {png}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    cli(main, __doc__)
