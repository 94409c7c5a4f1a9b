#!/usr/bin/python3
"""Plot S4(q,t) of a dynhet run (HDF5, H5MD layout): per cutoff a, a grid
of panels (at most three a row), one per sub-box grid: S4(q) at the lag
t_s4 nearest that cutoff's tau_alpha, log-log, with the OZ fit
chi0/(1 + (q xi)^2) and the fit with A^2 (q xi)^4 over their ranges (the
dotted lines end them), chi4 at the same t as a square at the left; and a
last panel with xi(t) of the OZ fit of every grid at every computed lag.

Usage: plot_s4.py RUN.h5 OUT.png
"""

import matplotlib

matplotlib.use("Agg")  # figures to files: no display needed
from dynhet.figures.common import cli  # noqa: E402 (after matplotlib.use)
from dynhet.figures.s4 import main

if __name__ == "__main__":
    cli(main, __doc__)
