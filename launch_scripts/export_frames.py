#!/usr/bin/python3
"""Writes a run's kept frames (observables.keep_frames) as a GSD file, which
MDAnalysis (MDAnalysis.Universe(OUT)), OVITO and HOOMD read: 2D box
(dimensions 2), positions centred in [-L/2, L/2) with z = 0, images,
diameters, masses, types "small" and "large".

Usage: launch_scripts/export_frames.py RUN [OUT.gsd] [--every K]
  RUN      a run directory or its run.h5
  OUT.gsd  default: frames.gsd beside run.h5
  --every K  every K-th frame only"""
import argparse
import os
import sys

import dynhet


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 epilog=__doc__.split("\n\n", 1)[1], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run")
    ap.add_argument("out", nargs="?")
    ap.add_argument("--every", type=int, default=1)
    a = ap.parse_args()
    path = os.path.join(a.run, "run.h5") if os.path.isdir(a.run) else a.run
    if a.every < 1:
        ap.error(f"--every {a.every}: give a positive integer")
    out = a.out or os.path.join(os.path.dirname(os.path.abspath(path)), "frames.gsd")
    try:
        with dynhet.open_run(path) as run:
            n = run.export_gsd(out, step=a.every)
    except (OSError, ValueError, KeyError) as e:
        print(f"export_frames: {e}", file=sys.stderr)
        return 1
    print(f"export_frames: {n} frames -> {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
