#!/usr/bin/python3
"""Plot chi4(t) of a dynhet run (HDF5, H5MD layout): one panel per cutoff a,
one curve per sub-box size N, the peak chi4^P at tau4 marked.

Usage: plot_chi4.py RUN.h5 OUT.png
"""

import matplotlib

matplotlib.use("Agg")  # figures to files: no display needed
from dynhet.figures.common import cli  # noqa: E402 (after matplotlib.use)
from dynhet.figures.chi4 import main

if __name__ == "__main__":
    cli(main, __doc__)
