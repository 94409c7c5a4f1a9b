"""The figure of the overlap Q(t) of a dynhet run (HDF5, H5MD layout) with its error
bars, the 1/e line, tau_alpha and the fit 1/((t/tau0)^beta + 1), one curve
per cutoff a (and the cage-relative Q(t), open markers, where the run has
it) and the bond-breaking C_B(t) (where the run has it); beside it
tau_alpha against the waiting time t0 (aging check), each origin's with its
error, and the run's tau_alpha with its error as a band.

"""
import math
import sys

from .common import pm, system_title, legend_below, save, tidy_log
import matplotlib.pyplot as plt
import numpy as np

from .. import schema
from ..run import open_run


def main(path, png):
    with open_run(path) as run:
        if "overlap" not in run.observables():
            print(f"plot_overlap: {path} has no overlap results", file=sys.stderr)
            return 1
        fig, (ax, ax2) = plt.subplots(1, 2, figsize=(12, 6.0), gridspec_kw={"width_ratios": [3, 2]},
                                      layout="constrained")
        for name, g in ((a, run.overlap(a)) for a in run.cutoffs("overlap")):
            t = g["lag_time"][()]
            q, err = g["q"], g["q_err"]
            tau, tau_err = float(g["tau_alpha"]), float(g["tau_alpha_err"])
            a = g.attrs.get("cutoff_a", name)
            label = f"a = {a}"
            if math.isfinite(tau):
                label += rf", $\tau_\alpha$ = {pm(tau, tau_err, 4)}"
            line = ax.errorbar(t, q, yerr=np.nan_to_num(err), marker="o", ms=3, capsize=2, label=label)
            color = line[0].get_color()
            if math.isfinite(tau):
                ax.axvline(tau, color=color, ls=":", lw=1)
            if "beta" in g and math.isfinite(g["beta"]):
                beta, tau0 = float(g["beta"]), float(g["tau0"])
                tt = np.geomspace(t[0], t[-1], 200)
                ax.plot(tt, 1 / ((tt / tau0) ** beta + 1), "--", color=color, lw=1,
                        label=rf"fit $\beta$ = {pm(beta, g['beta_err'])}, $\tau_0$ = {pm(tau0, g['tau0_err'])}")
            overlap_cr = schema.cage_relative("overlap")
            if overlap_cr in run.observables() and name in run.cutoffs(overlap_cr):
                # The same of the cage-relative displacements (observables.cage_relative).
                c = run.observable(overlap_cr, name)
                tau_cr, tau_cr_err = float(c["tau_alpha"]), float(c["tau_alpha_err"])
                ax.errorbar(c["lag_time"][()], c["q"], yerr=np.nan_to_num(c["q_err"]), marker="o", ms=3, mfc="none",
                            capsize=2, color=color, ls="-.", lw=1,
                            label=f"a = {a}, cage-relative" +
                            (rf", $\tau_\alpha$ = {pm(tau_cr, tau_cr_err)}" if math.isfinite(tau_cr) else ""))
            if "tau_alpha_t0" in g:
                # Each origin's tau_alpha with its error: the spread of one
                # origin's (runs recorded before it was computed have none).
                t0_err = g["tau_alpha_t0_err"] if "tau_alpha_t0_err" in g else None
                ax2.errorbar(g["t0"], g["tau_alpha_t0"], yerr=None if t0_err is None else np.nan_to_num(t0_err),
                             marker="o", ms=3, capsize=2, color=color, label=label.split(",")[0])
                if math.isfinite(tau):  # the run's tau_alpha with its error: where each origin's should lie
                    ax2.axhline(tau, color=color, ls=":", lw=1)
                    if math.isfinite(tau_err):
                        ax2.axhspan(tau - tau_err, tau + tau_err, color=color, alpha=0.12, lw=0)
        if "bond_breaking" in run.observables():  # C_B(t), the other correlator from 1 to 0
            b = run.observable("bond_breaking")
            tau_b = float(b["tau_b"])
            ax.errorbar(b["lag_time"][()], b["c_b"], yerr=np.nan_to_num(b["c_b_err"]), color="black", marker="s",
                        ms=3, capsize=2, lw=1.2,
                        label=rf"$C_B$ (bonds {b.attrs.get('a1', '?')}, {b.attrs.get('a2', '?')} $\sigma$)" +
                        (rf", $\tau_B$ = {tau_b:.4g}" if math.isfinite(tau_b) else ""))
        ax.axhline(math.exp(-1), color="gray", ls="--", lw=1, label="1/e")
        ax.set_xscale("log")
        ax.set_xlabel("t")
        ax.set_ylabel("Q(t), $C_B(t)$" if "bond_breaking" in run.observables() else "Q(t)")
        ax.set_ylim(0, 1.05)
        ax.set_title("overlap" + system_title(run))
        tidy_log(ax)
        legend_below(ax, ncol=2)
        ax2.set_xlabel("waiting time $t_0$")
        ax2.set_ylabel(r"$\tau_\alpha(t_0)$")
        ax2.set_title("aging check: flat if stationary\n(bars: the spread of one origin's; band: "
                      r"$\tau_\alpha$ ± its error)")
        ax2.legend()
        save(fig, run, png, 110)
    print(f"plot_overlap: wrote {png}", file=sys.stderr)
    return 0

