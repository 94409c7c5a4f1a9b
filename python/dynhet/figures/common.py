"""What every figure of one run shares: type sizes legible at 100% (10 pt
text, 9 pt ticks and legends, at the 100-120 dpi the plots are written
with), log axes labelled legibly, legends below their panel instead of over
the data, saving with an incomplete run marked, and the command line of
launch_scripts/plot_<observable>.py (RUN.h5 OUT.png)."""
import os
import sys

import matplotlib

matplotlib.rcParams.update({"font.size": 10, "axes.titlesize": 10, "axes.labelsize": 10, "legend.fontsize": 9,
                            "xtick.labelsize": 9, "ytick.labelsize": 9, "legend.framealpha": 0.9})

from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter  # noqa: E402
import numpy as np  # noqa: E402


def tidy_log(ax):
    """Log axes labelled legibly: plain numbers (0.05, 1, 20) where they are
    short, and on an axis spanning less than about a decade the ticks at 2
    and 5 labelled too (matplotlib's default there, 2x10^1 3x10^1 ..., runs
    the labels into each other)."""
    plain = FuncFormatter(lambda v, _: f"{v:g}")
    for axis, scale in ((ax.xaxis, ax.get_xscale()), (ax.yaxis, ax.get_yscale())):
        if scale != "log":
            continue
        lo, hi = sorted(axis.get_view_interval())
        if lo <= 0:
            continue
        if hi / lo < 15:
            axis.set_minor_locator(LogLocator(subs=(2, 5)))
            axis.set_minor_formatter(plain)
        else:
            axis.set_minor_formatter(NullFormatter())
        if lo >= 1e-3 and hi <= 1e5:
            axis.set_major_formatter(plain)


def pm(v, err, digits=3):
    """A fitted number with its error: "1.23 ± 0.04", or the number and
    "(no error)" where the run quotes none."""
    v, err = float(v), float(err)
    if not np.isfinite(v):
        return "—"
    return f"{v:.{digits}g} ± {err:.2g}" if np.isfinite(err) else f"{v:.{digits}g} (no error)"


def system_title(run):
    """ (N = 4096, φ = 0.76, ε = 0.9): the run's system in words, for a title."""
    p = run.parameters.get("system", {})
    names = (("n_particles", "N = {}"), ("packing_fraction", "φ = {}"), ("restitution", "ε = {}"))
    bits = [fmt.format(p[k]) for k, fmt in names if k in p]
    return " (" + ", ".join(bits) + ")" if bits else ""


def legend_below(ax, ncol=1, **kw):
    """The panel's legend under its x label, outside the data."""
    return ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=ncol, frameon=False, **kw)


def legend_right(ax, **kw):
    """The panel's legend at its right, outside the data."""
    return ax.legend(loc="center left", bbox_to_anchor=(1.02, 0.5), frameon=False, **kw)


def save(fig, run, png, dpi):
    """Saves the figure; an incomplete run (the file's `complete` is not 1)
    says so in red across the top, with what is missing. A log axis with
    nothing positive on it (an incomplete run's empty panel) turns linear
    rather than fail the whole figure."""
    for ax in fig.axes:
        lim = ax.dataLim
        for scale, hi, setter in ((ax.get_xscale(), lim.x1, ax.set_xscale), (ax.get_yscale(), lim.y1, ax.set_yscale)):
            if scale == "log" and not (np.isfinite(hi) and hi > 0):
                setter("linear")
    if not run.complete:
        missing = run.missing
        text = "INCOMPLETE RUN" + (": " + missing[:150] if missing else "")
        fig.suptitle(text, color="red", fontsize=12, y=1.03)
        fig.savefig(png, dpi=dpi, bbox_inches="tight")
        return
    fig.savefig(png, dpi=dpi)


def cli(main, doc):
    """Runs main(RUN.h5, OUT.png) from the command line and exits with its
    status; -h or --help prints the usage (the script's docstring). Figures
    go to files: no display needed."""
    matplotlib.use("Agg")
    if len(sys.argv) == 2 and sys.argv[1] in ("-h", "--help"):
        print(doc)
        sys.exit(0)
    if len(sys.argv) != 3:
        print(doc, file=sys.stderr)
        sys.exit(2)
    try:
        sys.exit(main(sys.argv[1], sys.argv[2]))
    except (OSError, KeyError) as e:  # a file that is no run, or lacks what the figure needs
        print(f"{os.path.basename(sys.argv[0])}: {e}", file=sys.stderr)
        sys.exit(1)
