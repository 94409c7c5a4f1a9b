#!/usr/bin/python3
"""tau_alpha(t0) of one run against the time t0 of its origins: does the
relaxation time still grow with the time since the state was made (ageing),
or has it levelled off? Reads run.h5 (or a reduced run.h5.gz of results/):
the overlap node's tau_alpha of each origin, standard and (where measured)
cage-relative, at cutoff a.

Prints, for each: the table of t0 and tau_alpha(t0); the straight line
through them (fits.slope_with_error: its error from the origins' scatter
about the line, valid where origins lie at least one tau_alpha apart) as
the change per 10^4 time units with its error; and the origins in thirds
of t0, each third's mean and its standard error (the origins taken as
independent, which they are where they lie more than tau_alpha apart).

Usage: bench/tau_t0.py RUN.h5[.gz] [--cutoff 0.6]
"""
import argparse
import gzip
import math
import os
import shutil
import sys
import tempfile

import h5py
import numpy as np

from dynhet.fits import slope_with_error  # bench/dynhet: the package


def series(f, group, cutoff):
    """(t0, tau_alpha(t0), tau_alpha of the run) of group at the cutoff, or None."""
    g = f.get(f"observables/{group}/a{cutoff:g}")
    if g is None:
        return None
    t0 = np.asarray(g["t0"], float)
    tt = np.asarray(g["tau_alpha_t0/value"], float)[-1]
    return t0, tt, float(np.asarray(g["tau_alpha/value"], float)[-1])


def report(name, t0, tt, tau):
    m = np.isfinite(tt)
    print(f"\n## {name}: tau_alpha = {tau:.4g} over {int(m.sum())} of {len(tt)} origins")
    print("| t0 | tau_alpha(t0) |\n|---|---|")
    for a, b in zip(t0, tt):
        print(f"| {a:.6g} | {b:.4g} |")
    if m.sum() < 4:
        print("fewer than 4 origins with a tau_alpha: no line")
        return
    b, e, n = slope_with_error(t0[m] / tau, tt[m] / tau)  # in units of tau_alpha on both axes
    err = (lambda x: f"+- {x:.2g}") if math.isfinite(e) else (lambda x: "(no error)")
    print(f"line: {1e4 * b:+.3g} {err(1e4 * e)} per 10^4 time units (in tau_alpha per tau_alpha of t0, "
          f"{b:+.3g} {err(e)}; {n - 2} dof)")
    if np.min(np.diff(t0[m])) < tau:
        print(f"origins lie {np.min(np.diff(t0[m])):.4g} apart, closer than tau_alpha: their tau_alpha(t0) are "
              "correlated, so the line has no error and the thirds' errors below understate theirs")
    thirds = np.array_split(np.flatnonzero(m), 3)
    for k, idx in enumerate(thirds):
        v = tt[idx]
        se = v.std(ddof=1) / math.sqrt(len(v)) if len(v) > 1 else math.nan
        print(f"third {k + 1}: t0 {t0[idx].min():.6g} to {t0[idx].max():.6g}: mean {v.mean():.4g} +- {se:.2g} "
              f"({len(v)} origins)")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run", help="run.h5 or run.h5.gz")
    ap.add_argument("--cutoff", type=float, default=0.6)
    a = ap.parse_args()
    path = a.run
    with tempfile.TemporaryDirectory() as tmp:
        if path.endswith(".gz"):
            plain = os.path.join(tmp, "run.h5")
            with gzip.open(path, "rb") as src, open(plain, "wb") as dst:
                shutil.copyfileobj(src, dst)
            path = plain
        try:
            f = h5py.File(path, "r")
        except OSError as err:
            sys.exit(f"tau_t0: cannot read {a.run}: {err}")
        with f:
            found = False
            for group, name in (("overlap", "standard"), ("overlap_cr", "cage-relative")):
                s = series(f, group, a.cutoff)
                if s is not None:
                    found = True
                    report(name, *s)
            if not found:
                sys.exit(f"tau_t0: {a.run} has no overlap at a = {a.cutoff:g}")


if __name__ == "__main__":
    main()
