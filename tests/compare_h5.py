#!/usr/bin/python3
"""Two run.h5 files of the same scene, seed and build: equal bit for bit in every dataset and attribute but the
wall-clock ones? Prints each difference; exit 0 if none.

What a run's wall clock decides, and so is compared only where it is not the clock's:
- nodes/<node>/wall_time (seconds since the first node status recorded);
- the sim's status (observables/sim): it is published once a second, so which frames have a record is the
  clock's; its last record (the sim's last word: Z, collision counts, frames) is compared, but
  collisions_per_second and eta_seconds, which are rates of the clock;
- s4 and displacement (and their _cr) publish at most once a second before their final message: their last record is
  compared (the final result), the earlier ones are the clock's.

Usage: compare_h5.py A.h5 B.h5 [--verbose] [--ignore PATH]...
  --ignore PATH  leave out a dataset (parameters/scene_toml), an attribute (parameters/system@initial_state) or a
                 group and all it holds (parameters/reanalysis, which only a re-analysis has): runs of two study
                 directories name their own prepared states
"""
import sys

import h5py
import numpy as np

THROTTLED = ("observables/sim/", "observables/s4/", "observables/s4_cr/", "observables/displacement/",
             "observables/displacement_cr/")
WALL = ("/wall_time/", "observables/sim/collisions_per_second/", "observables/sim/eta_seconds/")


def items(f):
    out = {}

    def visit(name, obj):
        out[name] = obj

    f.visititems(visit)
    return out


def same_array(a, b):
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape or a.dtype != b.dtype:
        return False
    if a.dtype.kind in "fc":
        return a.tobytes() == b.tobytes()
    return np.array_equal(a, b)


def compare(pa, pb, verbose=False, ignore=()):
    bad = []
    with h5py.File(pa, "r") as fa, h5py.File(pb, "r") as fb:
        ia, ib = items(fa), items(fb)
        for k in sorted(ia.keys() ^ ib.keys()):
            if any(k == i or k.startswith(i + "/") for i in ignore):
                continue
            bad.append(f"{k}: only in {'A' if k in ia else 'B'}")
        for k in sorted(ia.keys() & ib.keys()):
            a, b = ia[k], ib[k]
            for an in sorted(set(a.attrs) | set(b.attrs)):
                if f"{k}@{an}" in ignore:
                    continue
                if an not in a.attrs or an not in b.attrs:
                    bad.append(f"{k} @{an}: only in one")
                elif not same_array(a.attrs[an], b.attrs[an]):
                    bad.append(f"{k} @{an}: {a.attrs[an]!r} != {b.attrs[an]!r}")
            if not isinstance(a, h5py.Dataset) or k in ignore:
                continue
            path = k + "/"
            if any(w in "/" + path for w in WALL):
                continue
            if path.startswith(THROTTLED) and path.rsplit("/", 2)[-2] in ("value", "step", "time"):
                if a.shape[:1] == (0,) or b.shape[:1] == (0,):
                    if a.shape != b.shape:
                        bad.append(f"{k}: one of them is empty")
                    continue
                if not same_array(a[-1], b[-1]):
                    bad.append(f"{k}: last record differs")
                continue
            if not same_array(a[()], b[()]):
                detail = ""
                if verbose and a.shape == b.shape and a.dtype.kind in "fi":
                    diff = np.argwhere(np.asarray(a[()]) != np.asarray(b[()]))
                    detail = f" (first at {diff[0].tolist() if len(diff) else '?'}; shapes {a.shape})"
                bad.append(f"{k}: differs{detail}" if a.shape == b.shape else f"{k}: shape {a.shape} != {b.shape}")
    return bad


def main(argv):
    if len(argv) < 2 or argv[0] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if argv and argv[0] in ("-h", "--help") else 2
    ignore = [argv[i + 1] for i, x in enumerate(argv[:-1]) if x == "--ignore"]
    bad = compare(argv[0], argv[1], "--verbose" in argv, ignore)
    for line in bad[:60]:
        print("DIFF", line)
    if len(bad) > 60:
        print(f"... and {len(bad) - 60} more")
    print(f"{'EQUAL' if not bad else 'DIFFERENT'}: {argv[0]} and {argv[1]} ({len(bad)} differences)")
    return 0 if not bad else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
