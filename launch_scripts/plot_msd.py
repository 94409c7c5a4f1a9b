#!/usr/bin/python3
"""Plot the mean square displacement Delta(t) of a dynhet run (HDF5, H5MD
layout), all particles (solid) and small ones (dashed), with 4 D t + b over
its fit range, and the MSD of the instantaneous fastest (red) and slowest
(blue) fractions of each set (paper fig. MSD).

Usage: plot_msd.py RUN.h5 OUT.png
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")  # figures to files: no display needed
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
from dynhet.figures.common import cli  # noqa: E402
from dynhet.figures.msd import main  # noqa: E402

if __name__ == "__main__":
    cli(main, __doc__)
