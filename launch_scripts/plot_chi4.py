#!/usr/bin/python3
"""Plot chi4(t) of a dynhet run (HDF5, H5MD layout): one panel per cutoff a,
one curve per sub-box size N, the peak chi4^P at tau4 marked.

Usage: plot_chi4.py RUN.h5 OUT.png
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")  # figures to files: no display needed
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
from dynhet.figures.common import cli  # noqa: E402
from dynhet.figures.chi4 import main  # noqa: E402

if __name__ == "__main__":
    cli(main, __doc__)
