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
Names are the datasets' own (docs/analysis.md says what each is).
"""
import math

import h5py
import numpy as np

A_DEFAULT = 0.6  # the paper's cutoff, "unless stated otherwise"


def _text(v):
    return v.decode() if isinstance(v, bytes) else v


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
        if name not in self._g:
            raise KeyError(f"{self.name}: no dataset {name!r}; it has {', '.join(self.names())}")
        d = self._g[name]
        if isinstance(d, h5py.Group):  # an H5MD time series: the last record
            v = d["value"]
            return v[-1] if v.shape[0] else np.full(v.shape[1:], np.nan)
        return d[()]

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        try:
            return self[name]
        except KeyError as e:
            raise AttributeError(str(e)) from None

    def value_error(self, name):
        """(name, name_err) as arrays (the error NaN where the run has none)."""
        v = np.asarray(self[name], float)
        e = np.asarray(self[name + "_err"], float) if name + "_err" in self._g else np.full_like(v, np.nan)
        return v, e

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

    def __init__(self, path):
        self.path = str(path)
        try:
            self._f = h5py.File(self.path, "r")
        except OSError as e:
            raise OSError(f"{self.path}: cannot be read as a run file ({e})") from None
        a = self._f.attrs
        self.complete = int(a.get("complete", 0)) == 1
        self.missing = _text(a.get("missing", ""))
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
            key = next((k for k in g.keys() if k.startswith("a") and _same(k[1:], a)), None)
            if key is None:
                raise KeyError(f"{self.path}: {kind} has no cutoff a = {a:g}; it has {self.cutoffs(kind)}")
            g = g[key]
        return Observable(g)

    def overlap(self, a=A_DEFAULT):
        return self.observable("overlap", a)

    def chi4(self, a=A_DEFAULT):
        return self.observable("chi4", a)

    def clusters(self, a=A_DEFAULT):
        return self.observable("clusters", a)

    def s4(self, a=A_DEFAULT):
        return self.observable("s4", a)

    def msd(self):
        return self.observable("msd")

    def displacement(self):
        return self.observable("displacement")

    def has_frames(self):
        """Whether the run kept its frames (observables.keep_frames)."""
        return "particles" in self._f and "position" in self._f["particles/all"]

    def tau_alpha(self, a=A_DEFAULT):
        """tau_alpha of cutoff a with its error: (value, error)."""
        v, e = self.overlap(a).value_error("tau_alpha")
        return float(v), float(e)

    def __repr__(self):
        return (f"Run({self.path}: N = {self.n_particles}, phi = {self.packing_fraction:g}, eps = {self.restitution:g}, "
                f"{'complete' if self.complete else 'incomplete: ' + self.missing})")


def _same(label, a):
    try:
        return abs(float(label) - a) < 1e-9
    except ValueError:
        return False


def open_run(path):
    """A run's run.h5 (see Run)."""
    return Run(path)
