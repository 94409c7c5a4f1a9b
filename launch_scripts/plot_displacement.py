#!/usr/bin/python3
"""Plot P(dx, t), the distribution of x displacements of a dynhet run (HDF5,
H5MD layout), log-linear, at each lag the run chose (multiples of tau_alpha
and fixed times), for all particles and for small ones (paper fig. "tails"),
with the Gaussian fit (dash-dotted, D free) and the exponential-tail fit
(solid, drawn over its fit range |dx| >= x_min).

Usage: plot_displacement.py RUN.h5 OUT.png
"""
import math
import sys

import h5py
from plot_common import cli, last, save
import matplotlib.pyplot as plt  # after plot_common, which sets the Agg backend
import numpy as np


def main(path, png):
    with h5py.File(path, "r") as f:
        if "observables/displacement" not in f:
            print(f"plot_displacement: {path} has no P(dx, t) results", file=sys.stderr)
            return 1
        g = f["observables/displacement"]
        x = g["x"][()]
        lag, mult = last(g, "lag_time"), last(g, "target_tau_alpha")
        nt = len(lag)
        p, p_err = last(g, "p"), last(g, "p_err")  # [set][target][bin]
        tau = float(last(g, "tau_alpha"))
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.4), sharey=True)
        for s, (ax, name) in enumerate(zip(axes, ("all", "small"))):
            for l_ in range(nt):
                i = (s, l_)  # per-series values are [set][target]
                if not math.isfinite(lag[l_]):
                    continue
                ok = p[i] > 0
                what = f"{mult[l_]:g} $\\tau_\\alpha$" if math.isfinite(mult[l_]) else "fixed"
                err = np.nan_to_num(p_err[i][ok])
                line = ax.errorbar(x[ok], p[i][ok], yerr=[np.minimum(err, 0.9 * p[i][ok]), err], fmt="o", ms=2, capsize=1.5, lw=0.8,
                                   label=f"t = {lag[l_]:.3g} ({what})")
                colour = line[0].get_color()
                d, x0, amp = (float(last(g, k)[i]) for k in ("gauss_d", "tail_x0", "tail_amplitude"))
                t = lag[l_]
                xx = np.linspace(x[ok].min(), x[ok].max(), 400) if ok.any() else x
                if math.isfinite(d):
                    ax.plot(xx, np.exp(-xx ** 2 / (4 * d * t)) / np.sqrt(4 * math.pi * d * t), "-.", color=colour,
                            lw=1, label=f"Gaussian D = {d:.3g} $\\pm$ {float(last(g, 'gauss_d_err')[i]):.2g}")
                if math.isfinite(x0):
                    lo, hi = float(last(g, "tail_x_min")[i]), float(last(g, "tail_x_max")[i])
                    for sign in (-1, 1):
                        xt = sign * np.linspace(lo, hi, 50)
                        ax.plot(xt, amp * np.exp(-np.abs(xt) / x0), "-", color=colour, lw=1.4,
                                label=f"exp. tail $x_0$ = {x0:.3g} $\\pm$ "
                                      f"{float(last(g, 'tail_x0_err')[i]):.2g}, |dx| in [{lo:.2g}, {hi:.2g}]"
                                if sign > 0 else None)
            ax.set_yscale("log")
            ax.set_xlabel(r"$\Delta x$")
            ax.set_title(f"{name} particles ($\\tau_\\alpha$ = {tau:.3g})")
            ax.legend(fontsize=6)
        axes[0].set_ylabel(r"$P(\Delta x, t)$")
        fig.tight_layout()
        save(fig, f, png, 120)
    print(f"plot_displacement: wrote {png}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    cli(main, __doc__)
