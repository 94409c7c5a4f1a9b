"""Points (pairs, eps, phi, N) with their runs; per-point means over seeds and cross-run fits jackknifed over seeds.

An error bar is a claim: where the seeds of a study scatter more than the
errors their runs quote (jackknife over origin blocks, which are correlated
when a run has few origins), a per-point error is the quoted one times the
study's pooled ratio of the two for that quantity (`calibration`)."""
import math

import numpy as np

from .. import fits as sf

MIN_CAL_DOF = 10    # the seeds' spread scales the quoted errors only with this many dof behind it


def spread_ratio(points, fn):
    """Are the quoted errors honest? The seeds' spread against the errors the
    runs quote, pooled over points as bench/seed_spread.py pools it:
    ratio^2 = sum_p sum_s (x_s - mean_p)^2 / e_p^2 / sum_p (K_p - 1), e_p the
    mean quoted error of point p's K_p seeds (runs without a finite error left
    out). About 1 for honest errors; its own uncertainty ratio / sqrt(2 dof).
    fn(run) -> (value, error). Returns (ratio, uncertainty, dof, runs without a
    quoted error)."""
    num, dof, unquoted = 0.0, 0, 0
    for p in points:
        vals = p.values(fn)
        unquoted += sum(1 for _, v, e in vals if np.isfinite(v) and not (np.isfinite(e) and e > 0))
        ok = [(v, e) for _, v, e in vals if np.isfinite(v) and np.isfinite(e) and e > 0]
        if len(ok) < 2:
            continue
        x = np.array([v for v, _ in ok])
        e = float(np.mean([e for _, e in ok]))
        num += float(((x - x.mean()) ** 2).sum()) / e ** 2
        dof += len(ok) - 1
    if dof == 0:
        return math.nan, math.nan, 0, unquoted
    r = math.sqrt(num / dof)
    return r, r / math.sqrt(2 * dof), dof, unquoted


def calibration(points, fn):
    """How much larger than quoted a quantity's errors are, pooled over
    `points`: (factor, ratio, uncertainty, dof). The factor is the ratio
    (spread_ratio) where it has at least MIN_CAL_DOF dof and lies more than two
    of its uncertainties above 1, else 1: quoted errors are never shrunk."""
    r, u, dof, _ = spread_ratio(points, fn)
    k = r if dof >= MIN_CAL_DOF and np.isfinite(r) and r - 2 * u > 1 else 1.0
    return k, r, u, dof


def fn_key(fn):
    """A per-run function's identity for the calibration cache: its code, its
    defaults (keyword-only too), what its closure holds and, for a bound
    method, its object (None where those are not hashable: then the factor
    is computed at every call)."""
    try:
        key = (fn.__code__, fn.__defaults__, tuple(sorted((fn.__kwdefaults__ or {}).items())),
               tuple(c.cell_contents for c in (fn.__closure__ or ())), getattr(fn, "__self__", None))
        hash(key)
        return key
    except (AttributeError, TypeError, ValueError):
        return None


class Population:
    """The points of one study, which share a protocol (run length, origins):
    the calibration of each quantity pooled over them. Where they have fewer
    than MIN_CAL_DOF dof for a quantity (a study of one or two seeds), the
    calibration of `parent` (every study analysed together) stands in."""

    def __init__(self, points, name="", parent=None):
        self.points, self.name, self.parent, self._cache = list(points), name, parent, {}

    def own(self, fn):
        key = fn_key(fn)
        if key is None:
            return calibration(self.points, fn)
        if key not in self._cache:
            self._cache[key] = calibration(self.points, fn)
        return self._cache[key]

    def borrows(self, fn):
        """Whether fn's calibration is the parent's (too few dof of its own)."""
        return self.parent is not None and self.own(fn)[3] < MIN_CAL_DOF

    def calibration(self, fn):
        """(factor, ratio, uncertainty, dof): the study's own, else the parent's."""
        return self.parent.own(fn) if self.borrows(fn) else self.own(fn)


def ensure_calibrated(points):
    """Give every point without a population the one of its study (points
    grouped by their .study, the primary study's having none), with all of
    them together as the parent. Returns the populations made."""
    points = list({id(p): p for p in points if p.population is None}.values())
    if not points:
        return []
    parent = Population(points, "all studies")
    groups = {}
    for p in points:
        groups.setdefault(getattr(p, "study", None), []).append(p)
    made = []
    for name, pts in groups.items():
        pop = Population(pts, name or "", parent if len(groups) > 1 else None)
        for p in pts:
            p.population = pop
        made.append(pop)
    return made


class Point:
    def __init__(self, key):
        self.pairs, self.eps, self.phi, self.N = key
        self.runs = []
        self.population = None  # set by ensure_calibrated

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

    def factor(self, fn):
        """The factor the quoted errors of fn take (calibration over the point's study; 1 without one)."""
        return self.population.calibration(fn)[0] if self.population is not None else 1.0

    def mean(self, fn, drop=None):
        """(mean over seeds, its error: the runs' quoted errors combined, times
        the study's calibration factor for fn, or the seeds' spread where no run
        quotes one; the seeds' own standard error; seeds used)."""
        vals = [(s, v, e) for s, v, e in self.values(fn) if np.isfinite(v)]
        # A jackknife over seeds leaves a seed out of every point that has
        # others; a point of one seed stays (left out, each replicate would
        # be a fit over other points, and the replicates' scatter no spread
        # of seeds). Its noise is then in the fit's own error only, which
        # Fit.error takes as a floor (jk_partial, fit_series).
        if len(vals) > 1:
            vals = [x for x in vals if x[0] != drop]
        if not vals:
            return math.nan, math.nan, math.nan, 0
        m, sem, n = sf.seed_mean([v for _, v, _ in vals])
        # The runs' quoted errors only where every seed quotes one: a mean
        # over seeds of which some quote none has no quoted error (the
        # others' would claim it), and takes the seeds' spread.
        quoted = all(np.isfinite(e) and e > 0 for _, _, e in vals)
        q = sf.quoted_mean_error([e for _, _, e in vals]) if quoted else math.nan
        err = q * self.factor(fn) if np.isfinite(q) else sem
        return m, err, sem, n


def series_arrays(points, fn, drop=None):
    """x = phi, the per-point means of fn and their errors (points with data only)."""
    return paired_arrays(points, fn, None, drop)


def point_error(m):
    """The error of a per-point mean (Point.mean): the quoted error, else the
    standard error over seeds, else 10%."""
    v, e, sem, _ = m
    return e if np.isfinite(e) and e > 0 else (sem if np.isfinite(sem) and sem > 0 else abs(v) * 0.1)


def measured_error(m):
    """The error of a per-point mean that was measured: the runs' quoted
    error, else the seeds' standard error; NaN where there is neither (one
    seed quoting none: tau_B where its blocks cannot span it). Not
    point_error's 10% stand-in, which the fits use as a weight."""
    _, e, sem, _ = m
    return e if np.isfinite(e) and e > 0 else (sem if np.isfinite(sem) and sem > 0 else math.nan)


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
    fit = sf.jackknife_over_seeds(one, seeds_of(points))
    # points measured by one seed: the jackknife cannot see their noise
    fit.jk_partial = any(0 < p.mean(fn)[3] < 2 or (xrun is not None and 0 < p.mean(xrun)[3] < 2) for p in points)
    return fit
