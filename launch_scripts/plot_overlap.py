#!/usr/bin/python3
"""Plot the overlap Q(t) of a dynhet run (HDF5, H5MD layout) with its error
bars, the 1/e line, tau_alpha and the fit 1/((t/tau0)^beta + 1), one curve
per cutoff a; beside it tau_alpha against the waiting time t0 (aging check).

Usage: plot_overlap.py RUN.h5 OUT.png
"""

import matplotlib

matplotlib.use("Agg")  # figures to files: no display needed
from dynhet.figures.common import cli  # noqa: E402 (after matplotlib.use)
from dynhet.figures.overlap import main  # noqa: E402 (after matplotlib.use)

if __name__ == "__main__":
    cli(main, __doc__)
