#!/usr/bin/python3
"""Every figure of a dynhet run (HDF5, H5MD layout) in one process, as
run_scene.sh draws them at the end of a run: OUTDIR/<observable>.png for
chi4, msd, displacement, clusters and s4 where the run has them, and
overlap.png. Exits 1 if any figure failed (the others are still drawn).
One figure alone: launch_scripts/plot_<observable>.py RUN.h5 OUT.png.

Usage: plot_run.py RUN.h5 OUTDIR
"""

import matplotlib

matplotlib.use("Agg")  # figures to files: no display needed
from dynhet.figures.common import cli  # noqa: E402 (after matplotlib.use)
from dynhet.figures.run_figures import draw_all  # noqa: E402 (after matplotlib.use)

if __name__ == "__main__":
    cli(draw_all, __doc__)
