#!/usr/bin/python3
"""Writes the positions of a run's checkpoint as an H5MD file, which a scene
takes as system.initial_state (velocities drawn afresh): a new run, with
other observables or lags, of the structure a run reached.

Usage: launch_scripts/positions_from_checkpoint.py RUN OUT.h5
  RUN     a run directory (its checkpoint.h5, and run.h5 for the box) or a
          checkpoint.h5
  OUT.h5  particles/all/position/value (1 x N x 2, by particle id, the order
          the scene's species follow), particles/all/box/edges where the run
          file gives them; the checkpoint's time, path and sha256 as
          attributes"""
import argparse
import os
import sys

import h5py
import numpy as np

from dynhet.archive import sha256_of


def read_checkpoint(path):
    """(x, y, time) of a sim checkpoint; SystemExit naming what is wrong."""
    try:
        f = h5py.File(path, "r")
    except OSError as e:
        raise SystemExit(f"positions_from_checkpoint: {path}: not an HDF5 file ({e})")
    with f:
        if f.attrs.get("format", b"") not in (b"dynhet checkpoint 1", "dynhet checkpoint 1"):
            raise SystemExit(f"positions_from_checkpoint: {path}: not a sim checkpoint (no 'dynhet checkpoint' format)")
        if "x" not in f or "y" not in f:
            raise SystemExit(f"positions_from_checkpoint: {path}: no positions (x, y)")
        x, y = np.asarray(f["x"], float), np.asarray(f["y"], float)
        t = float(np.ravel(f.attrs.get("time", [np.nan]))[0])
    if x.shape != y.shape or x.ndim != 1 or not len(x):
        raise SystemExit(f"positions_from_checkpoint: {path}: x and y are not two lists of one length")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
        raise SystemExit(f"positions_from_checkpoint: {path}: a position is not a number")
    return x, y, t


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 epilog=__doc__.split("\n\n", 1)[1], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run")
    ap.add_argument("out")
    a = ap.parse_args(argv)
    ckpt = os.path.join(a.run, "checkpoint.h5") if os.path.isdir(a.run) else a.run
    if not os.path.isfile(ckpt):
        raise SystemExit(f"positions_from_checkpoint: {ckpt}: no such file")
    if os.path.exists(a.out):
        raise SystemExit(f"positions_from_checkpoint: {a.out} exists: not overwritten")
    x, y, t = read_checkpoint(ckpt)
    run_h5 = os.path.join(os.path.dirname(os.path.abspath(ckpt)), "run.h5")
    edges = None
    if os.path.isfile(run_h5):
        with h5py.File(run_h5, "r") as r:
            if "particles/all/box/edges" in r:
                edges = np.asarray(r["particles/all/box/edges"], float)
    tmp = f"{a.out}.tmp.{os.getpid()}"
    with h5py.File(tmp, "w") as f:
        g = f.create_group("particles/all")
        g.create_dataset("position/value", data=np.stack([x, y], axis=1)[None, :, :])
        if edges is not None:
            g.create_dataset("box/edges", data=edges)
        f.attrs["source_checkpoint"] = os.path.abspath(ckpt)
        f.attrs["source_sha256"] = sha256_of(ckpt)
        f.attrs["source_time"] = t
    os.replace(tmp, a.out)
    print(f"positions_from_checkpoint: {len(x)} positions at t = {t:.6g} from {ckpt} -> {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
