"""Every figure of one run, drawn in one process: run_scene.sh's plots.
One interpreter instead of one per figure (and one more per check of what
the run has) saves the imports, about 1.6 s a figure on the development
machine, which was most of a small run's wall time."""
import os
import sys
import traceback

import matplotlib.pyplot as plt

import importlib
import importlib.util

from .. import schema
from ..run import open_run


def _figures():
    """(name, module) of every declared observable that has a figure, a
    module of this package named after it (dynhet.schema)."""
    out = []
    for d in schema.OBSERVABLES:
        if d["name"] != "overlap" and importlib.util.find_spec(f"{__package__}.{d['name']}") is not None:
            out.append((d["name"], importlib.import_module(f".{d['name']}", __package__)))
    return tuple(out)


# The overlap figure is drawn last and whatever the run has (it says so
# when Q(t) is missing).
FIGURES = _figures()
overlap = importlib.import_module(".overlap", __package__)


def draw_all(path, outdir):
    """Writes OUTDIR/<observable>.png for every observable the run has, and
    overlap.png. Returns 0, or 1 if any figure failed (the others are still
    drawn, and each failure is named)."""
    if not os.path.isdir(outdir):
        raise OSError(f"{outdir}: no such directory (the figures go there)")
    with open_run(path) as run:
        have = set(run.observables())
    status = 0
    for name, module in FIGURES + (("overlap", overlap),):
        if name != "overlap" and name not in have:
            continue
        try:
            status |= 1 if module.main(path, os.path.join(outdir, f"{name}.png")) else 0
        except Exception as e:  # one figure's failure leaves the others drawn
            traceback.print_exc()
            print(f"plot_{name}: failed: {type(e).__name__}: {e}", file=sys.stderr)
            status = 1
        finally:
            plt.close("all")
    return status
