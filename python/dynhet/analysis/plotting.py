"""Small helpers the figures share."""
import matplotlib.pyplot as plt
import numpy as np


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
