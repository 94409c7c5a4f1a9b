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
        # One panel above the other, each with its legend at its right,
        # outside the data: a column per panel would squeeze the legends.
        fig, axes = plt.subplots(2, 1, figsize=(11, 9.5), sharex=True, layout="constrained")
        for s, (ax, name) in enumerate(zip(axes, ("all", "small"))):
            groups = []  # the legend: per lag its data, then its fits
            for l_ in range(nt):
                i = (s, l_)  # per-series values are [set][target]
                if not math.isfinite(lag[l_]):
                    continue
                ok = p[i] > 0
                what = f"{mult[l_]:g} $\\tau_\\alpha$" if math.isfinite(mult[l_]) else "fixed"
                err = np.nan_to_num(p_err[i][ok])
                line = ax.errorbar(x[ok], p[i][ok], yerr=[np.minimum(err, 0.9 * p[i][ok]), err], fmt="o", ms=2.5,
                                   capsize=1.5, lw=0.8)
                group = [(line, f"t = {lag[l_]:.3g} ({what})")]
                colour = line[0].get_color()
                d, x0, amp = (float(last(g, k)[i]) for k in ("gauss_d", "tail_x0", "tail_amplitude"))
                t = lag[l_]
                xx = np.linspace(x[ok].min(), x[ok].max(), 400) if ok.any() else x
                if math.isfinite(d):
                    h, = ax.plot(xx, np.exp(-xx ** 2 / (4 * d * t)) / np.sqrt(4 * math.pi * d * t), "-.",
                                 color=colour, lw=1)
                    group.append((h, f"Gaussian: D = {d:.3g} ± {float(last(g, 'gauss_d_err')[i]):.2g}"))
                if math.isfinite(x0):
                    lo, hi = float(last(g, "tail_x_min")[i]), float(last(g, "tail_x_max")[i])
                    for sign in (-1, 1):
                        xt = sign * np.linspace(lo, hi, 50)
                        h, = ax.plot(xt, amp * np.exp(-np.abs(xt) / x0), "-", color=colour, lw=1.6)
                    group.append((h, f"exp. tail: $x_0$ = {x0:.3g} ± {float(last(g, 'tail_x0_err')[i]):.2g}\n"
                                     f"    over |$\\Delta x$| in [{lo:.2g}, {hi:.2g}]"))
                groups.append(group)
            ax.set_yscale("log")
            if (p[s] > 0).any():  # the data's range: a fit's Gaussian far below it would squash the data
                ax.set_ylim(bottom=0.3 * p[s][p[s] > 0].min())
            ax.set_ylabel(r"$P(\Delta x, t)$")
            ax.set_title(f"{name} particles ($\\tau_\\alpha$ = {tau:.3g})")
            entries = [e for gr in groups for e in gr]
            if entries:
                ax.legend([h for h, _ in entries], [t for _, t in entries], loc="center left",
                          bbox_to_anchor=(1.02, 0.5), frameon=False)
        axes[1].set_xlabel(r"$\Delta x$")
        save(fig, f, png, 100)
    print(f"plot_displacement: wrote {png}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    cli(main, __doc__)
