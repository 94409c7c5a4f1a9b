#!/usr/bin/python3
"""Plot the clusters of slow and fast particles of a dynhet run (HDF5, H5MD
layout), one row per cutoff a: g_ab(r) with the neighbour cutoffs; R_g
against N_c (geometric bin means) with the d_f fit; P(N_c) with the power
law (slow) and the log-normal (fast); the mean cluster size against the lag
with tau_alpha and the chosen lag.

Usage: plot_clusters.py RUN.h5 OUT.png
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")  # figures to files: no display needed
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
from dynhet.figures.common import cli  # noqa: E402
from dynhet.figures.clusters import main  # noqa: E402

if __name__ == "__main__":
    cli(main, __doc__)
