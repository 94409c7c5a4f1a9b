#!/usr/bin/python3
"""Plot P(dx, t), the distribution of x displacements of a dynhet run (HDF5,
H5MD layout), log-linear, at each lag the run chose (multiples of tau_alpha
and fixed times), for all particles and for small ones (paper fig. "tails"),
with the Gaussian fit (dash-dotted, D free) and the exponential-tail fit
(solid, drawn over its fit range |dx| >= x_min).

Usage: plot_displacement.py RUN.h5 OUT.png
"""

import matplotlib

matplotlib.use("Agg")  # figures to files: no display needed
from dynhet.figures.common import cli  # noqa: E402 (after matplotlib.use)
from dynhet.figures.displacement import main  # noqa: E402 (after matplotlib.use)

if __name__ == "__main__":
    cli(main, __doc__)
