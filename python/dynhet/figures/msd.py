"""The figure of the mean square displacement Delta(t) of a dynhet run (HDF5, H5MD
layout), all particles (solid) and small ones (dashed), with 4 D t + b over
its fit range, and the MSD of the instantaneous fastest (red) and slowest
(blue) fractions of each set (paper fig. MSD).

"""
import math
import sys

from .common import legend_right, save, tidy_log
import matplotlib.pyplot as plt
import numpy as np

from ..run import open_run


def main(path, png):
    with open_run(path) as run:
        if "msd" not in run.observables():
            print(f"plot_msd: {path} has no MSD results", file=sys.stderr)
            return 1
        g = run.msd()
        t = g["lag_time"][()]
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
        D = float(g["diffusion"])
        t0, t1 = float(g["fit_t_min"]), float(g["fit_t_max"])
        if math.isfinite(D):
            tt = np.geomspace(t0, t1, 50)
            ax.plot(tt, 4 * D * tt, "k--", lw=1, label=f"4Dt, D = {D:.4g} (fit {t0:.3g}..{t1:.3g})")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("t")
        ax.set_ylabel(r"$\Delta(t)$")
        tidy_log(ax)
        legend_right(ax)
        save(fig, run, png, 110)
    print(f"plot_msd: wrote {png}", file=sys.stderr)
    return 0

