#!/usr/bin/python3
"""Plot the clusters of slow and fast particles of a dynhet run (HDF5, H5MD
layout), one row per cutoff a: g_ab(r) with the neighbour cutoffs; R_g
against N_c (geometric bin means) with the d_f fit; P(N_c) with the power
law (slow) and the log-normal (fast); the mean cluster size against the lag
with tau_alpha and the chosen lag.

Usage: plot_clusters.py RUN.h5 OUT.png
"""

import matplotlib

matplotlib.use("Agg")  # figures to files: no display needed
from dynhet.figures.common import cli  # noqa: E402 (after matplotlib.use)
from dynhet.figures.clusters import main  # noqa: E402 (after matplotlib.use)

if __name__ == "__main__":
    cli(main, __doc__)
