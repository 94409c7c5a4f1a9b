#!/usr/bin/python3
"""Checks a dynhet run file against the H5MD 1.1 rules the recorder keeps
(README, "Output (HDF5, H5MD)"):

- h5md: version [1, 1]; author/name, creator/name and creator/version are
  fixed-length strings (author/name equal to --author NAME if given);
- no variable-length string anywhere (datasets and attributes of every
  object): every string is fixed-length, as H5MD asks;
- every time series (a group with step, time and value) has integer step
  and time of equal length, value's first dimension that length, step
  strictly increasing, and time the simulation time of frame `step` of the
  schedule (observables/schedule/frame_time[step]);
- particles/all/image/{step,time} are the same HDF5 objects (hard links)
  as particles/all/position/{step,time};
- multi-dimensional observables keep their dimensions: chi4 [record][grid][lag],
  S4 per lag [record][lag][value] and [record][lag][grid], P(dx)
  [record][set][target][bin] and its per-series values [record][set][target],
  the schedule's pair_frame [origin][lag].

Usage: check_h5md.py RUN.h5 [--author NAME]
"""
import argparse
import sys


import h5py
import numpy as np

from dynhet import schema

failures = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        failures.append(what)


def string_kind(tid):
    """'fixed', 'variable' or None (not a string) for an HDF5 type id."""
    if tid.get_class() != h5py.h5t.STRING:
        return None
    return "variable" if tid.is_variable_str() else "fixed"


def all_strings(f):
    """(where, kind) of every string-typed dataset and attribute in the file."""
    out = []

    def attrs_of(name, obj):
        for a in obj.attrs:
            kind = string_kind(obj.attrs.get_id(a).get_type())
            if kind:
                out.append((f"{name or '/'} @{a}", kind))

    attrs_of("", f)

    def visit(name, obj):
        attrs_of(name, obj)
        if isinstance(obj, h5py.Dataset):
            kind = string_kind(obj.id.get_type())
            if kind:
                out.append((name, kind))

    f.visititems(visit)
    return out


def fixed_string_attr(f, path, attr):
    """The attribute's text if it is a fixed-length string, else None."""
    if path not in f or attr not in f[path].attrs:
        return None
    if string_kind(f[path].attrs.get_id(attr).get_type()) != "fixed":
        return None
    v = f[path].attrs[attr]
    return v.decode() if isinstance(v, bytes) else None


def time_series(f):
    """name -> group of every H5MD time series (a group holding a `value` dataset)."""
    out = {}

    def visit(name, obj):
        if isinstance(obj, h5py.Group) and isinstance(obj.get("value", getlink=True), h5py.HardLink):
            out[name] = obj

    f.visititems(visit)
    return out


def check_series(f):
    sched = f.get("observables/schedule/frame_time")
    frame_time = sched[()] if sched is not None else None
    series = time_series(f)
    check(len(series) > 0, f"{len(series)} time series")
    bad = []
    for name, g in sorted(series.items()):
        if "step" not in g or "time" not in g:
            bad.append(f"{name}: no step or time")
            continue
        step, time, value = g["step"], g["time"], g["value"]
        if step.ndim != 1 or time.ndim != 1 or step.dtype.kind not in "iu" or time.dtype.kind != "f":
            bad.append(f"{name}: step {step.dtype}{step.shape}, time {time.dtype}{time.shape}")
            continue
        s, t = step[()], time[()]
        if len(s) != len(t) or value.shape[0] != len(s):
            bad.append(f"{name}: {len(s)} steps, {len(t)} times, {value.shape[0]} values")
            continue
        if not np.all(np.diff(s) > 0):
            dup = int(np.sum(np.diff(s) <= 0))
            bad.append(f"{name}: step not strictly increasing ({dup} repeats or steps back)")
            continue
        if frame_time is not None:
            if len(s) and (s[0] < 0 or s[-1] >= len(frame_time)):
                bad.append(f"{name}: steps {s[0]}..{s[-1]} outside the schedule's {len(frame_time)} frames")
            elif not np.array_equal(t, frame_time[s]):
                bad.append(f"{name}: time is not the schedule's frame_time[step]")
    for b in bad[:20]:
        print("     " + b)
    check(not bad, f"every time series: step and time of one length, value of that many records, step strictly "
          f"increasing, time = frame_time[step] ({len(bad)} of {len(series)} bad)")


def check_links(f):
    base = "particles/all"
    if f"{base}/image" not in f:
        check(f"{base}/position" not in f, "no particles/all/position without image")
        return
    for d in ("step", "time"):
        a, b = f[f"{base}/position/{d}"], f[f"{base}/image/{d}"]
        same = h5py.h5o.get_info(a.id).addr == h5py.h5o.get_info(b.id).addr and a.id == b.id
        check(same, f"particles/all/image/{d} is the same HDF5 object as particles/all/position/{d} (hard link)")
        check(isinstance(f[f"{base}/image"].get(d, getlink=True), h5py.HardLink),
              f"particles/all/image/{d} is a hard link")


def check_dimensions(f):
    """Every observable group against the schema generated from the
    observables' declarations (dynhet.schema); the schedule's own pair table."""
    problems = schema.check(f.filename)
    for line in problems[:20]:
        print("     " + line)
    check(not problems, f"the observables fit the schema of run.h5 (docs/run_h5.md): {len(problems)} problem(s)")
    if "observables/schedule" in f:
        s = f["observables/schedule"]
        check(s["pair_frame"].shape == (len(s["origin_frame"]), len(s["lag_time"])),
              f"schedule/pair_frame [origin][lag] {s['pair_frame'].shape}")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("run_h5")
    p.add_argument("--author", help="the author name the file must carry")
    args = p.parse_args()
    f = h5py.File(args.run_h5, "r")
    check("h5md" in f and list(f["h5md"].attrs.get("version", [])) == [1, 1], "h5md version [1, 1]")
    author = fixed_string_attr(f, "h5md/author", "name")
    check(author is not None and author != "", f"h5md/author name {author!r} is a fixed-length string")
    if args.author is not None:
        check(author == args.author, f"h5md/author name is {args.author!r}")
    for a in ("name", "version"):
        v = fixed_string_attr(f, "h5md/creator", a)
        check(v is not None and v != "", f"h5md/creator {a} {v!r} is a fixed-length string")
    strings = all_strings(f)
    variable = [w for w, kind in strings if kind == "variable"]
    for w in variable[:20]:
        print("     variable-length: " + w)
    check(len(strings) > 0 and not variable,
          f"no variable-length string in the file ({len(strings)} strings, {len(variable)} variable-length)")
    check_series(f)
    check_links(f)
    check_dimensions(f)
    if failures:
        print(f"check_h5md: {len(failures)} check(s) failed")
        return 1
    print("check_h5md: the file keeps the H5MD rules")
    return 0


if __name__ == "__main__":
    sys.exit(main())
