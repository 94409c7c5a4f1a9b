"""Points (pairs, eps, phi, N) with their runs; per-point means over seeds and cross-run fits jackknifed over seeds."""
import math

import numpy as np

from .. import fits as sf


class Point:
    def __init__(self, key):
        self.pairs, self.eps, self.phi, self.N = key
        self.runs = []

    def values(self, fn):
        """[(seed, value, quoted error)] over the runs; fn(run) -> (value, error)."""
        out = []
        for r in self.runs:
            try:
                v, e = fn(r)
            except (KeyError, TypeError, IndexError, ValueError):
                v, e = math.nan, math.nan
            out.append((r["seed"], float(v), float(e)))
        return out

    def mean(self, fn, drop=None):
        """(mean over seeds, error from the quoted errors (or from the seeds' spread
        where no run quotes one), the seeds' own standard error, seeds used)."""
        vals = [(s, v, e) for s, v, e in self.values(fn) if s != drop and np.isfinite(v)]
        if not vals:
            return math.nan, math.nan, math.nan, 0
        m, sem, n = sf.seed_mean([v for _, v, _ in vals])
        q = sf.quoted_mean_error([e for _, _, e in vals])
        err = q if np.isfinite(q) else sem
        return m, err, sem, n


def series_arrays(points, fn, drop=None):
    """x = phi, the per-point means of fn and their errors (points with data only)."""
    return paired_arrays(points, fn, None, drop)


def point_error(m):
    """The error of a per-point mean (Point.mean): the quoted error, else the
    standard error over seeds, else 10%."""
    v, e, sem, _ = m
    return e if np.isfinite(e) and e > 0 else (sem if np.isfinite(sem) and sem > 0 else abs(v) * 0.1)


def paired_arrays(points, fn, xrun=None, drop=None, xpoint=lambda p: p.phi):
    """Per-point means of fn against x: a per-point function (xpoint) or the
    per-point mean of a per-run quantity (xrun, e.g. tau_alpha). With xrun,
    also the errors of x (a fourth array): x is then measured too."""
    xs, ys, es, sxs = [], [], [], []
    for p in points:
        mx = p.mean(xrun, drop) if xrun is not None else (xpoint(p), 0.0, 0.0, 1)
        my = p.mean(fn, drop)
        if my[3] and np.isfinite(mx[0]) and np.isfinite(my[0]):
            xs.append(mx[0])
            ys.append(my[0])
            es.append(point_error(my))
            sxs.append(point_error(mx) if xrun is not None else 0.0)
    if xrun is None:
        return np.array(xs), np.array(ys), np.array(es)
    return np.array(xs), np.array(ys), np.array(es), np.array(sxs)


def seeds_of(points):
    return sorted({r["seed"] for p in points for r in p.runs})


def fit_series(points, fn, form, xrun=None, xpoint=lambda p: p.phi, **kw):
    """A cross-run fit of the per-point means of fn against x (see
    paired_arrays), jackknifed over seeds: each seed left out of every point."""
    def one(drop):
        a = paired_arrays(points, fn, xrun, drop, xpoint)
        return form(*a[:3], sx=a[3], **kw) if len(a) == 4 else form(*a, **kw)
    return sf.jackknife_over_seeds(one, seeds_of(points))
