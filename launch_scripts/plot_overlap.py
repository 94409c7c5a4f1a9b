#!/usr/bin/python3
"""Plot the overlap Q(t) of a dynhet run (HDF5, H5MD layout) with its error
bars, the 1/e line, tau_alpha and the fit 1/((t/tau0)^beta + 1), one curve
per cutoff a; beside it tau_alpha against the waiting time t0 (aging check).

Usage: plot_overlap.py RUN.h5 OUT.png
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")  # figures to files: no display needed
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
from dynhet.figures.common import cli  # noqa: E402
from dynhet.figures.overlap import main  # noqa: E402

if __name__ == "__main__":
    cli(main, __doc__)
