"""Small helpers the figures share."""
import matplotlib.pyplot as plt
import numpy as np


def errorbar(ax, x, y, yerr=None, *args, **kw):
    """ax.errorbar with a NaN error drawn as no bar: a value whose error no run
    determined (a single seed quoting none) is still a value, and matplotlib
    raises StopIteration when every error of a call is NaN."""
    if yerr is not None:
        yerr = np.nan_to_num(np.asarray(yerr, dtype=float), nan=0.0)
    return ax.errorbar(x, y, yerr, *args, **kw)


def log_axes(ax, xlabel, ylabel, title, legend=8):
    """Both axes logarithmic, labelled, with a legend."""
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.legend(fontsize=legend)
    ax.set_title(title)


def colours(n):
    return plt.cm.viridis(np.linspace(0, 0.95, max(n, 1)))


def fit_label(f, names, fmtp="{:.3g}"):
    return ", ".join(f"{n} = {fmtp.format(f.p[n])}" for n in names) if f.ok else "fit not made"
