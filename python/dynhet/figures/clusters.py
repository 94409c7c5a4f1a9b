"""The figure of the clusters of slow and fast particles of a dynhet run (HDF5, H5MD
layout), one row per cutoff a: g_ab(r) with the neighbour cutoffs; R_g
against N_c (geometric bin means) with the d_f fit; P(N_c) with the power
law (slow) and the log-normal (fast); the mean cluster size against the lag
with tau_alpha and the chosen lag. Where the run has clusters_cr
(observables.cage_relative), the cage-relative P(N_c) and mean sizes in
the same panels, open squares and dashed lines.

"""
import math
import sys

from .common import pm, legend_below, save, tidy_log
import matplotlib.pyplot as plt
import numpy as np

from .. import schema
from ..run import open_run


def plot_g(ax, g):
    if "r" not in g:
        ax.text(0.5, 0.5, "no g_ab yet", transform=ax.transAxes, ha="center")
        return
    r = g["r"][()]
    cut = g["neighbour_cutoff"]
    for k, (name, colour) in enumerate((("g11", "C0"), ("g12", "C1"), ("g22", "C2"))):
        ax.plot(r, g[name], color=colour, lw=1, label=f"{name}, r_min = {cut[k]:.3g}")
        if math.isfinite(cut[k]):
            ax.axvline(cut[k], color=colour, ls="--", lw=0.8)
    ax.set_xlabel("r")
    ax.set_ylabel(r"$g_{ab}(r)$")
    ax.set_title(f"g_ab over {int(g['g_frames'])} origin frames")
    legend_below(ax)


def plot_rg(ax, g):
    if "rg_slow" not in g:
        return
    for kind, colour in (("slow", "C3"), ("fast", "C7")):
        n, rg, err = g[f"rg_size_{kind}"], g[f"rg_{kind}"], g[f"rg_{kind}_err"]
        ok = np.isfinite(n) & np.isfinite(rg)
        d_f, d_f_err = float(g[f"{kind}_d_f"]), float(g[f"{kind}_d_f_err"])
        ax.errorbar(n[ok], rg[ok], yerr=np.nan_to_num(err[ok]), fmt="o", ms=3, capsize=2, color=colour,
                    label=f"{kind}: d_f = {pm(d_f, d_f_err)}")
        if math.isfinite(d_f) and ok.sum() >= 2:
            c = np.mean(np.log(rg[ok]) - np.log(n[ok]) / d_f)  # the line through the bin means
            nn = np.geomspace(n[ok].min(), n[ok].max(), 20)
            ax.plot(nn, np.exp(c) * nn ** (1 / d_f), color=colour, lw=1)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(r"$N_c$")
    ax.set_ylabel(r"$R_g$")
    ax.set_title(r"radius of gyration, $R_g \sim N_c^{1/d_f}$")
    tidy_log(ax)
    legend_below(ax)


def plot_p(ax, g, cr=None):
    if "p_slow" not in g:
        return
    if cr is not None and "p_slow" in cr:  # the cage-relative P(N_c), open markers
        for kind, colour in (("slow", "C3"), ("fast", "C7")):
            p, err, count = cr[f"p_{kind}"], cr[f"p_{kind}_err"], cr[f"count_{kind}"]
            ok = count > 0
            ax.errorbar(cr["size_centre"][()][ok], p[ok], yerr=np.nan_to_num(err[ok]), fmt="s", mfc="none", ms=3,
                        capsize=2, color=colour, label=f"{kind}, cage-relative")
    centre = g["size_centre"][()]
    n_lo, n_hi = int(g.attrs["kappa_n_min"]), int(g.attrs["kappa_n_max"])
    for kind, colour in (("slow", "C3"), ("fast", "C7")):
        p, err, count = g[f"p_{kind}"], g[f"p_{kind}_err"], g[f"count_{kind}"]
        ok = count > 0
        ax.errorbar(centre[ok], p[ok], yerr=np.nan_to_num(err[ok]), fmt="o", ms=3, capsize=2, color=colour,
                    label=kind)
    kappa, kappa_err = float(g["slow_kappa"]), float(g["slow_kappa_err"])
    p, count = g["p_slow"], g["count_slow"]
    sel = (count > 0) & (g["size_lo"][()] >= n_lo) & (g["size_hi"][()] <= n_hi)
    if math.isfinite(kappa) and sel.any():
        c = np.mean(np.log(p[sel]) + kappa * np.log(centre[sel]))  # amplitude for the picture
        nn = np.geomspace(centre[sel].min(), centre[sel].max(), 20)
        ax.plot(nn, np.exp(c) * nn ** -kappa, "C3-", lw=1, label=f"kappa = {pm(kappa, kappa_err)}")
    p0, n_sigma, sigma = (float(g[k]) for k in ("fast_p0", "fast_n_sigma", "fast_sigma"))
    if all(map(math.isfinite, (p0, n_sigma, sigma))):
        ok = g["count_fast"] > 0
        nn = np.geomspace(centre[ok].min(), centre[ok].max(), 50)
        ax.plot(nn, p0 * np.exp(-np.log(nn / n_sigma) ** 2 / (2 * sigma ** 2)), "C7-", lw=1,
                label=f"log-normal N0 = {float(g['fast_n0']):.3g}, sigma = {sigma:.3g}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(r"$N_c$")
    ax.set_ylabel(r"$P(N_c)$")
    ax.set_title("cluster sizes at the lag used")
    tidy_log(ax)
    legend_below(ax)


def plot_lags(ax, g, cr=None):
    t = g["lag_time"][()]
    for kind, colour in (("slow", "C3"), ("fast", "C7")):
        ax.errorbar(t, g[f"mean_size_{kind}"], yerr=np.nan_to_num(g[f"mean_size_{kind}_err"]),
                    marker="o", ms=3, capsize=2, color=colour, label=f"{kind} <N_c>")
        if cr is not None:
            ax.errorbar(t, cr[f"mean_size_{kind}"], yerr=np.nan_to_num(cr[f"mean_size_{kind}_err"]), marker="s",
                        mfc="none", ls="--", ms=3, capsize=2, color=colour, label=f"{kind}, cage-relative")
    if cr is not None and math.isfinite(float(cr["tau_alpha"])):
        ax.axvline(float(cr["tau_alpha"]), color="C4", ls=":", lw=1,
                   label=f"cage-relative tau_alpha = {float(cr['tau_alpha']):.3g}")
    tau, lag = float(g["tau_alpha"]), float(g["lag"])
    if math.isfinite(tau):
        ax.axvline(tau, color="k", ls=":", lw=1, label=f"tau_alpha = {tau:.3g}")
    if math.isfinite(lag):
        ax.axvline(lag, color="k", ls="--", lw=1, label=f"lag used = {lag:.3g}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("t")
    ax.set_ylabel(r"mean $N_c$")
    ax.set_title("mean cluster size against the lag")
    tidy_log(ax)
    legend_below(ax, ncol=2)


def main(path, png):
    with open_run(path) as run:
        if "clusters" not in run.observables():
            print(f"plot_clusters: {path} has no cluster results", file=sys.stderr)
            return 1
        groups = [(a, run.clusters(a)) for a in run.cutoffs("clusters")]
        fig, axes = plt.subplots(len(groups), 4, figsize=(18, 5.2 * len(groups)), squeeze=False,
                                 layout="constrained")
        for row, (name, g) in zip(axes, groups):
            clusters_cr = schema.cage_relative("clusters")
            cr = run.observable(clusters_cr, name) if name in run.cutoffs(clusters_cr) else None
            plot_g(row[0], g)
            plot_rg(row[1], g)
            plot_p(row[2], g, cr)
            plot_lags(row[3], g, cr)
            for ax in row:  # each panel names its cutoff
                ax.set_title(f"a = {g.attrs.get('cutoff_a', name)}: " + ax.get_title())
        save(fig, run, png, 100)
    print(f"plot_clusters: wrote {png}", file=sys.stderr)
    return 0

