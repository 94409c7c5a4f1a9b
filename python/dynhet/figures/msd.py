"""The figure of the mean square displacement Delta(t) of a dynhet run (HDF5, H5MD
layout), all particles (solid) and small ones (dashed), with 4 D t + b over
its fit range, and the MSD of the instantaneous fastest (red) and slowest
(blue) fractions of each set (paper fig. MSD); the cage-relative MSD of all
particles where the run has it; below, F_s(q, t) and alpha_2(t), standard
and cage-relative, where the run has them.

"""
import math
import sys

from .common import pm, legend_right, save, tidy_log
import matplotlib.pyplot as plt
import numpy as np

from .. import schema
from ..run import open_run


def self_panels(ax_fs, ax_a2, t, g, cr):
    """F_s(q, t) of all particles at each q, and alpha_2(t) of all and small
    particles: standard solid, cage-relative dashed (open markers)."""
    sets = [("", g, "-", None)] + ([(", cage-relative", cr, "--", "none")] if cr is not None else [])
    if "fs_q" in g:
        q = g["fs_q"][()]
        colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
        for label, h, ls, mfc in sets:
            fs, err = np.atleast_2d(h["fs_all"]), np.atleast_2d(h["fs_all_err"])
            for i, qq in enumerate(q):
                ax_fs.errorbar(t, fs[i], yerr=np.nan_to_num(err[i]), ls=ls, color=colours[i % len(colours)],
                               marker="o", mfc=mfc, ms=2.5, capsize=2, lw=1, label=f"q = {qq:.3g}{label}")
        ax_fs.axhline(math.exp(-1), color="gray", ls=":", lw=1)
        ax_fs.set_xscale("log")
        ax_fs.set_xlabel("t")
        ax_fs.set_ylabel(r"$F_s(q, t)$ (all particles)")
        tidy_log(ax_fs)
        ax_fs.legend(fontsize=8)
    for label, h, ls, mfc in sets:
        for name, colour in (("all", "green"), ("small", "orange")):
            ax_a2.errorbar(t, h[f"alpha2_{name}"], yerr=np.nan_to_num(h[f"alpha2_{name}_err"]), ls=ls, color=colour,
                           marker="o", mfc=mfc, ms=2.5, capsize=2, lw=1, label=f"{name}{label}")
    ax_a2.axhline(0, color="gray", ls=":", lw=1)
    ax_a2.set_xscale("log")
    ax_a2.set_xlabel("t")
    ax_a2.set_ylabel(r"$\alpha_2(t)$")
    tidy_log(ax_a2)
    ax_a2.legend(fontsize=8)


def main(path, png):
    with open_run(path) as run:
        if "msd" not in run.observables():
            print(f"plot_msd: {path} has no MSD results", file=sys.stderr)
            return 1
        g = run.msd()
        t = g["lag_time"][()]
        msd_cr = schema.cage_relative("msd")
        cr = run.observable(msd_cr) if msd_cr in run.observables() else None
        self_part = "alpha2_all" in g
        if self_part:  # the MSD above, F_s(q, t) and alpha_2(t) below
            fig = plt.figure(figsize=(11.0, 9.0), layout="constrained")
            grid = fig.add_gridspec(2, 2, height_ratios=[1.1, 1])
            ax = fig.add_subplot(grid[0, :])
            ax_fs, ax_a2 = fig.add_subplot(grid[1, 0]), fig.add_subplot(grid[1, 1])
        else:
            fig, ax = plt.subplots(figsize=(9.6, 5.0), layout="constrained")
        fractions = {k: float(g.attrs.get(f"fraction_{k}", math.nan)) for k in ("all", "small")}
        for name, ls in (("all", "-"), ("small", "--")):
            curves = [(f"msd_{name}", "green", name)]
            if f"msd_fast_{name}" in g:
                curves += [(f"msd_{kind}_{name}", colour, f"{kind}est {fractions[name]:.0%} of {name}")
                           for kind, colour in (("fast", "red"), ("slow", "blue"))]
            for key, colour, label in curves:
                ax.errorbar(t, g[key], yerr=np.nan_to_num(g[key + "_err"]), ls=ls,
                            color=colour, marker="o" if name == "all" else "s", ms=2.5, capsize=2, lw=1,
                            label=label)
        if cr is not None:  # the cage-relative MSD of all particles (observables.cage_relative)
            ax.errorbar(t, cr["msd_all"], yerr=np.nan_to_num(cr["msd_all_err"]), ls=":", color="purple", marker="o",
                        mfc="none", ms=2.5, capsize=2, lw=1.2, label="all, cage-relative")
        if self_part:
            self_panels(ax_fs, ax_a2, t, g, cr)
        D = float(g["diffusion"])
        t0, t1 = float(g["fit_t_min"]), float(g["fit_t_max"])
        if math.isfinite(D):
            tt = np.geomspace(t0, t1, 50)
            ax.plot(tt, 4 * D * tt, "k--", lw=1, label=f"4Dt, D = {pm(D, g['diffusion_err'], 4)} (fit {t0:.3g}..{t1:.3g})")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("t")
        ax.set_ylabel(r"$\Delta(t)$")
        tidy_log(ax)
        legend_right(ax)
        save(fig, run, png, 110)
    print(f"plot_msd: wrote {png}", file=sys.stderr)
    return 0

