"""The figure of P(dx, t), the distribution of x displacements of a dynhet run (HDF5,
H5MD layout), log-linear, at each lag the run chose (multiples of tau_alpha
and fixed times), for all particles and for small ones (paper fig. "tails"),
with the Gaussian fit (dash-dotted, D free) and the exponential-tail fit
(solid, drawn over its fit range |dx| >= x_min).

"""
import math
import sys

from .common import pm, save
import matplotlib.pyplot as plt
import numpy as np

from ..run import open_run


def main(path, png):
    with open_run(path) as run:
        if "displacement" not in run.observables():
            print(f"plot_displacement: {path} has no P(dx, t) results", file=sys.stderr)
            return 1
        g = run.displacement()
        x = g["x"][()]
        lag, mult = g["lag_time"], g["target_tau_alpha"]
        nt = len(lag)
        p, p_err = g["p"], g["p_err"]  # [set][target][bin]
        tau = float(g["tau_alpha"])
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
                what = (f"{lag[l_] / tau:.3g} $\\tau_\\alpha$, the lag nearest {mult[l_]:g} $\\tau_\\alpha$"
                        if math.isfinite(mult[l_]) and math.isfinite(tau) and tau > 0 else "fixed")
                err = np.nan_to_num(p_err[i][ok])
                line = ax.errorbar(x[ok], p[i][ok], yerr=[np.minimum(err, 0.9 * p[i][ok]), err], fmt="o", ms=2.5,
                                   capsize=1.5, lw=0.8)
                group = [(line, f"t = {lag[l_]:.3g} ({what})")]
                colour = line[0].get_color()
                d, x0, amp = (float(g[k][i]) for k in ("gauss_d", "tail_x0", "tail_amplitude"))
                t = lag[l_]
                xx = np.linspace(x[ok].min(), x[ok].max(), 400) if ok.any() else x
                if math.isfinite(d):
                    h, = ax.plot(xx, np.exp(-xx ** 2 / (4 * d * t)) / np.sqrt(4 * math.pi * d * t), "-.",
                                 color=colour, lw=1)
                    group.append((h, f"Gaussian: D = {pm(d, g['gauss_d_err'][i])}"))
                if math.isfinite(x0):
                    lo, hi = float(g["tail_x_min"][i]), float(g["tail_x_max"][i])
                    for sign in (-1, 1):
                        xt = sign * np.linspace(lo, hi, 50)
                        h, = ax.plot(xt, amp * np.exp(-np.abs(xt) / x0), "-", color=colour, lw=1.6)
                    group.append((h, f"exp. tail: $x_0$ = {pm(x0, g['tail_x0_err'][i])}\n"
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
        save(fig, run, png, 100)
    print(f"plot_displacement: wrote {png}", file=sys.stderr)
    return 0

