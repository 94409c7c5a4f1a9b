#!/usr/bin/python3
"""Plot the mean square displacement Delta(t) of a dynhet run (HDF5, H5MD
layout), all particles (solid) and small ones (dashed), with 4 D t + b over
its fit range, and the MSD of the instantaneous fastest (red) and slowest
(blue) fractions of each set (paper fig. MSD).

Usage: plot_msd.py RUN.h5 OUT.png
"""

import matplotlib

matplotlib.use("Agg")  # figures to files: no display needed
from dynhet.figures.common import cli  # noqa: E402 (after matplotlib.use)
from dynhet.figures.msd import main  # noqa: E402 (after matplotlib.use)

if __name__ == "__main__":
    cli(main, __doc__)
