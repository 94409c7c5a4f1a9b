"""The figure of chi4(t) of a dynhet run (HDF5, H5MD layout): one panel per cutoff a,
one curve per sub-box size N, the peak chi4^P at tau4 marked.

"""
import math
import sys

from .common import legend_right, save, tidy_log
import matplotlib.pyplot as plt
import numpy as np

from ..run import open_run


def main(path, png):
    with open_run(path) as run:
        if "chi4" not in run.observables():
            print(f"plot_chi4: {path} has no chi4 results", file=sys.stderr)
            return 1
        groups = [(a, run.chi4(a)) for a in run.cutoffs("chi4")]
        fig, axes = plt.subplots(1, len(groups), figsize=(7.6 * len(groups), 4.8), squeeze=False,
                                 layout="constrained")
        for ax, (name, g) in zip(axes[0], groups):
            t = g["lag_time"][()]
            sizes = g["subbox_particles"][()]
            chi, err = g["chi4"], g["chi4_err"]  # [grid][lag]
            peak, tau4 = g["chi4_peak"], g["tau4"]
            for i, n in enumerate(sizes):
                line = ax.errorbar(t, chi[i], yerr=np.nan_to_num(err[i]), marker="o", ms=2.5, capsize=2,
                                   label=f"N = {n:.0f}")
                if math.isfinite(tau4[i]):
                    ax.plot([tau4[i]], [peak[i]], "*", ms=10, color=line[0].get_color())
            ax.set_xscale("log")
            ax.set_yscale("log")
            # The data's range down to 1e-3 of the peak: a value near zero
            # (chi4 of a few origins can nearly vanish) would squash the rest.
            top = np.nanmax(chi) if np.isfinite(chi).any() else 1.0
            low = chi[np.isfinite(chi) & (chi > 0)]
            if low.size and top > 0:
                ax.set_ylim(max(low.min(), top * 1e-3) / 1.5, top * 2)
            ax.set_xlabel("t")
            ax.set_ylabel(r"$\chi_4(t)$")
            ax.set_title(f"a = {g.attrs.get('cutoff_a', name)} (star: peak at $\\tau_4$)")
            tidy_log(ax)
            legend_right(ax, title="sub-boxes of")
        save(fig, run, png, 110)
    print(f"plot_chi4: wrote {png}", file=sys.stderr)
    return 0

