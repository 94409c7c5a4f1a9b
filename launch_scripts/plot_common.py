"""What every plot_<observable>.py shares: matplotlib without a display,
the newest record of an H5MD time series, and the command line
(plot_<observable>.py RUN.h5 OUT.png)."""
import sys

import matplotlib

matplotlib.use("Agg")


def last(group, name):
    """The newest record of the time series group/name."""
    return group[name]["value"][-1]


def save(fig, f, png, dpi):
    """Saves the figure; an incomplete run (the file's `complete` is not 1)
    says so in red across the top, with what is missing."""
    if int(f.attrs.get("complete", 0)) != 1:
        missing = f.attrs.get("missing", "")
        missing = missing.decode() if isinstance(missing, bytes) else str(missing)
        text = "INCOMPLETE RUN" + (": " + missing[:150] if missing else "")
        fig.suptitle(text, color="red", fontsize=9, y=1.03)
        fig.savefig(png, dpi=dpi, bbox_inches="tight")
        return
    fig.savefig(png, dpi=dpi)


def cli(main, doc):
    """Runs main(RUN.h5, OUT.png) from the command line and exits with its
    status; -h or --help prints the usage (the script's docstring)."""
    if len(sys.argv) == 2 and sys.argv[1] in ("-h", "--help"):
        print(doc)
        sys.exit(0)
    if len(sys.argv) != 3:
        print(doc, file=sys.stderr)
        sys.exit(2)
    sys.exit(main(sys.argv[1], sys.argv[2]))
