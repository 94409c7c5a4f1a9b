"""What every plot_<observable>.py shares: matplotlib without a display,
the newest record of an H5MD time series, and the command line
(plot_<observable>.py RUN.h5 OUT.png)."""
import sys

import matplotlib

matplotlib.use("Agg")


def last(group, name):
    """The newest record of the time series group/name."""
    return group[name]["value"][-1]


def cli(main, doc):
    """Runs main(RUN.h5, OUT.png) from the command line and exits with its status."""
    if len(sys.argv) != 3:
        print(doc, file=sys.stderr)
        sys.exit(2)
    sys.exit(main(sys.argv[1], sys.argv[2]))
