"""Reading a run: run.h5 as arrays with their errors and metadata.

    import dynhet
    run = dynhet.open_run("runs/default/run.h5")
    ov = run.overlap()                  # a = 0.6 unless asked otherwise
    ov.lag_time, ov.q, ov.q_err         # Q(t) and its error (the final record)
    run.tau_alpha()                     # (value, error)

Every observable group of run.h5 (recorder/, docs: README "Output") reads
the same way, with no per-observable code: a time series (step, time,
value) gives its last record, the final result, as an array named like
the dataset (`.history(name)` gives every record with its time); a fixed
dataset (lag_time, q, r, size_centre, ...) is itself; the group's
attributes are `.attrs`. `value_error(name)` pairs `name` with `name_err`.
Names are the datasets' own: docs/run_h5.md and help(run.chi4) say what
each is, its shape and unit (dynhet.schema, from the observables'
declarations).

open_run takes a run directory or its run.h5 and nothing else: another
HDF5 file (a checkpoint, a study's study.h5), a truncated file or one a
recorder still writes is refused at open with what it is (RunFileError).
An incomplete run opens with an IncompleteRunWarning naming what it lacks,
unless allow_incomplete=True says that partial results are meant.
"""
import math
import os
import re
import warnings

import h5py
import numpy as np

from . import scene, schema

A_DEFAULT = scene.default("observables", "cutoff_a")[0]  # the scene's, the paper's "unless stated otherwise"
CUTOFF_REL_TOL = 1e-6  # a cutoff asked for matches the run's within this (labels and floats round)
HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


class RunFileError(OSError):
    """A path that is not a readable run: no run.h5, not a run file, truncated."""


class IncompleteRunWarning(UserWarning):
    """The run did not finish (run.h5's complete = 0): its results cover part of it."""


def _text(v):
    return v.decode() if isinstance(v, bytes) else v


def _scalar(v):
    """A 0-d array as the Python number it is; anything else unchanged."""
    a = np.asarray(v)
    if a.ndim == 0 and a.dtype.kind in "fiub":
        return a.item()
    return v


def _field(kind, name):
    d = schema.declaration(kind)
    for f in (d or {}).get("fields", []):
        if f["name"] == name:
            return f
    raise KeyError(f"{kind}: no declared dataset {name!r}")


class Observable:
    """One group of run.h5's observables (e.g. chi4 at a = 0.6)."""

    def __init__(self, group):
        self._g = group
        self.name = group.name.rsplit("observables/", 1)[-1]
        self.attrs = {k: _text(v) for k, v in group.attrs.items()}

    def names(self):
        """Every dataset of the group, series and fixed."""
        return sorted(self._g.keys())

    def __contains__(self, name):
        return name in self._g

    def __getitem__(self, name):
        """The dataset's final record (a series) or itself (fixed): an array,
        or a Python float or int where it is one number."""
        d = self._g.get(name)
        if d is None:
            raise KeyError(f"{self.name}: no dataset {name!r}; it has {', '.join(self.names())}")
        return self._final(d)

    def get(self, name, default=None):
        """self[name], or default where the group has no such dataset (one
        lookup in the file, where `name in` and then [name] take two)."""
        d = self._g.get(name)
        return default if d is None else self._final(d)

    @staticmethod
    def _final(d):
        if isinstance(d, h5py.Group):  # an H5MD time series: the last record
            v = d["value"]
            return _scalar(v[-1] if v.shape[0] else np.full(v.shape[1:], np.nan))
        return _scalar(d[()])

    def __dir__(self):
        """The datasets with the methods: tab completion offers ov.q, ov.tau_alpha, ..."""
        return sorted(set(super().__dir__()) | {n for n in self._g.keys() if n.isidentifier()})

    def describe(self, name=None):
        """What the group (or one dataset of it) is: kind, shape, dtype, unit
        and meaning, from the observables' declarations."""
        text = schema.describe(self.name.split("/")[0])
        if name is None:
            return text
        lines = [line for line in text.splitlines() if line.strip().startswith(name + ":")]
        if not lines:
            raise KeyError(f"{self.name}: no declared dataset {name!r}")
        return lines[0].strip()

    def unit(self, name):
        """The unit of a dataset (length, time, 1, ...), from its declaration."""
        return _field(self.name.split("/")[0], name)["unit"]

    def to_xarray(self, history=False):
        """The group as an xarray.Dataset with named dimensions, units and
        meanings (dynhet.xarray_view): the final record, or every record
        along "record" with history=True."""
        from .xarray_view import to_xarray
        return to_xarray(self, history)

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        try:
            return self[name]
        except KeyError as e:
            raise AttributeError(str(e)) from None

    def value_error(self, name):
        """(name, name_err): floats where the value is one number, else
        arrays (the error NaN where the run has none)."""
        v = np.asarray(self[name], float)
        e = np.asarray(self[name + "_err"], float) if name + "_err" in self._g else np.full_like(v, np.nan)
        return (float(v), float(e)) if v.ndim == 0 else (v, e)

    def history(self, name):
        """Every record of a time series: (time of each record, values [record][...])."""
        d = self._g[name]
        if not isinstance(d, h5py.Group):
            raise ValueError(f"{self.name}/{name} is fixed, not a series")
        if "time" not in d:  # a results archive's entry keeps the final record, its time an attribute
            return np.atleast_1d(d.attrs.get("time", np.nan)), d["value"][()]
        return d["time"][()], d["value"][()]

    def __repr__(self):
        return f"Observable({self.name}: {', '.join(self.names())})"


class Run:
    """A run's run.h5, read-only. Use as a context manager or call close()."""

    def __init__(self, path, allow_incomplete=False):
        self.path = _run_path(str(path))
        try:
            self._f = h5py.File(self.path, "r")
        except OSError as e:
            raise RunFileError(unreadable(self.path, e)) from None
        a = self._f.attrs
        if "complete" not in a:  # the recorder writes it first, 0, and at the end
            found = describe_h5(self._f)
            self._f.close()
            raise RunFileError(f"{self.path} is not a run file (a recorder's run.h5 has the attribute 'complete'): "
                               f"it holds {found}")
        self.complete = int(a.get("complete", 0)) == 1
        self.missing = _text(a.get("missing", ""))
        if not self.complete and not allow_incomplete:
            warnings.warn(f"{self.path}: an incomplete run ({self.missing or 'no reason recorded'}): its results "
                          "cover only part of it; open_run(..., allow_incomplete=True) reads it without this warning",
                          IncompleteRunWarning, stacklevel=3)
        self.run_id = int(a["run_id"]) if "run_id" in a else None
        self.parameters = {k: {n: _text(v) for n, v in g.attrs.items()}
                           for k, g in self._f.get("parameters", {}).items() if isinstance(g, h5py.Group)}
        s = self.parameters.get("system", {})
        self.n_particles = int(s["n_particles"]) if "n_particles" in s else None
        self.packing_fraction = float(s["packing_fraction"]) if "packing_fraction" in s else math.nan
        self.restitution = float(s["restitution"]) if "restitution" in s else math.nan
        self.seed = int(s["seed"]) if "seed" in s else None

    def close(self):
        self._f.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def observables(self):
        """The observable groups the run has: overlap, chi4, msd, ..."""
        return sorted(self._f.get("observables", {}).keys())

    def cutoffs(self, kind="overlap"):
        """The cutoffs a an observable family was computed for."""
        g = self._f.get(f"observables/{kind}")
        return sorted(float(k[1:]) for k in g.keys() if k.startswith("a")) if g is not None else []

    def observable(self, kind, a=None):
        """One observable group; kind is overlap, chi4, clusters, s4 (per
        cutoff a) or msd, displacement, sim, nodes/<node>."""
        g = self._f.get(f"observables/{kind}")
        if g is None:
            raise KeyError(f"{self.path}: no observable {kind!r}; the run has {', '.join(self.observables())}")
        if a is not None or any(k.startswith("a") and k[1:2].isdigit() for k in g.keys()):
            a = A_DEFAULT if a is None else a
            near = sorted((abs(_label(k[1:]) - a), k) for k in g.keys()
                          if k.startswith("a") and _same(k[1:], a))
            if not near:
                raise KeyError(f"{self.path}: {kind} has no cutoff a = {a!r} (nor within a relative "
                               f"{CUTOFF_REL_TOL:g} of it); it has {self.cutoffs(kind)}")
            g = g[near[0][1]]
        return Observable(g)

    def has_frames(self):
        """Whether the run kept its frames (observables.keep_frames)."""
        return "particles" in self._f and "position" in self._f["particles/all"]

    def frames(self, start=0, stop=None, step=1):
        """The kept frames [start:stop:step] (observables.keep_frames), one
        dynhet.frames.Frame each: time, box, positions, images, radii,
        species. export_gsd(path) writes them for MDAnalysis, OVITO, HOOMD."""
        from .frames import frames
        return frames(self, start, stop, step)

    def export_gsd(self, path, start=0, stop=None, step=1):
        """The kept frames as a GSD file (dynhet.frames.export_gsd); returns the frames written."""
        from .frames import export_gsd
        return export_gsd(self, path, start, stop, step)

    def tau_alpha(self, a=A_DEFAULT):
        """tau_alpha of cutoff a with its error: (value, error)."""
        v, e = self.overlap(a).value_error("tau_alpha")
        return float(v), float(e)

    def __repr__(self):
        return (f"Run({self.path}: N = {self.n_particles}, phi = {self.packing_fraction:g}, eps = {self.restitution:g}, "
                f"{'complete' if self.complete else 'incomplete: ' + self.missing})")


def _reader(kind):
    """Run.<kind>(a) (per cutoff) or Run.<kind>(): the group, with what it
    holds as the docstring (dynhet.schema.describe)."""
    if schema.declaration(kind)["per_cutoff"]:
        def read(self, a=A_DEFAULT):
            return self.observable(kind, a)
    else:
        def read(self):
            return self.observable(kind)
    read.__name__ = read.__qualname__ = kind
    read.__doc__ = schema.describe(kind)
    return read


# One reader per declared observable and cage-relative variant: run.overlap(a),
# run.chi4_cr(a), run.msd(), ... (help(run.chi4) lists its datasets).
for _kind in schema.kinds():
    setattr(Run, _kind, _reader(_kind))


def _label(label):
    try:
        return float(label)
    except ValueError:
        return math.nan


def _same(label, a):
    return math.isclose(_label(label), a, rel_tol=CUTOFF_REL_TOL, abs_tol=1e-12)


def _run_path(path):
    """run.h5 itself, or a run directory's."""
    if os.path.isdir(path):
        f = os.path.join(path, "run.h5")
        if not os.path.exists(f):
            there = sorted(os.listdir(path))
            raise RunFileError(f"{path} holds no run.h5 (it holds {', '.join(there[:10]) or 'nothing'}"
                               f"{', ...' if len(there) > 10 else ''})")
        return f
    return path


def unreadable(path, e):
    """What is wrong with a file h5py could not open, in words."""
    if not os.path.exists(path):
        return f"{path}: no such file"
    size = os.path.getsize(path)
    with open(path, "rb") as fh:
        head = fh.read(8)
    if head != HDF5_SIGNATURE:
        return f"{path} is not an HDF5 file ({size} bytes, beginning {head!r}), so not a run.h5"
    m = re.search(r"truncated file: eof = (\d+).*stored_eof = (\d+)", str(e))
    if m:
        return (f"{path} is truncated: {m.group(1)} bytes on disk of the {m.group(2)} it was written with "
                "(a copy or a write cut short, a full disk): copy it again from where the run ran")
    if "lock" in str(e):
        return (f"{path} is open for writing by another process (a recorder still running?): read it once the "
                "run has ended")
    return f"{path}: cannot be read as a run file ({e})"


def describe_h5(f):
    """An HDF5 file's top level in words, with what it looks like."""
    groups = sorted(f.keys())
    attrs = sorted(f.attrs.keys())
    what = ""
    if "format" in f.attrs:
        what = f" (format {_text(f.attrs['format'])!r}: a checkpoint, read by sim_node --resume)"
    elif "points" in groups and "fits" in groups:
        what = " (a study analysis's study.h5: dynhet.open_study reads the study directory)"
    return (f"groups [{', '.join(groups)}] and attributes [{', '.join(attrs)}]{what}")


def open_run(path, allow_incomplete=False):
    """A run: its directory or its run.h5 (see Run). An incomplete run warns
    (IncompleteRunWarning) unless allow_incomplete=True."""
    return Run(path, allow_incomplete)
