"""What the brute-force checks of a run file share (check_run.py,
check_spatial.py, check_cage_relative.py): one list of failures, the node's
definitions of tau's crossing and of the lag bracket, and the estimators
over origins, and a run's scene with its defaults filled in."""
import math
import tomllib

import numpy as np

from dynhet.scene import DEFAULTS

failures = []


def scene_of(text):
    """A run's scene (its parameters/scene_toml) with every table's defaults
    filled in: the simulator's (dynhet.scene), not copies here."""
    scene = tomllib.loads(text.decode() if isinstance(text, bytes) else str(text))
    return {t: dict(DEFAULTS[t], **scene.get(t, {})) for t in DEFAULTS if t != "model"}


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        failures.append(what)


def crossing_time(t, q, level):
    """Same definition as the node: first downward crossing, linear in ln t."""
    prev = None
    for j in range(len(q)):
        if math.isnan(q[j]):
            continue
        if q[j] < level:
            if prev is None:
                return math.nan
            f = (q[prev] - level) / (q[prev] - q[j])
            return math.exp(math.log(t[prev]) + f * (math.log(t[j]) - math.log(t[prev])))
        prev = j
    return math.nan


def bracket(t, tau):
    """The node's bracket (lag_interpolation.hpp): adjacent lags lo, hi = lo + 1 with
    t[lo] <= tau <= t[hi], w = ln(tau/t_lo)/ln(t_hi/t_lo), and the third lag (the
    neighbour on tau's side, else the other); None outside the lags."""
    n = len(t)
    if not (math.isfinite(tau) and t[0] <= tau <= t[-1]) or n < 2:
        return None
    lo = 0
    while lo + 2 < n and t[lo + 1] <= tau:
        lo += 1
    hi = lo + 1
    w = math.log(tau / t[lo]) / math.log(t[hi] / t[lo])
    below, above = (lo - 1 if lo > 0 else None), (hi + 1 if hi + 1 < n else None)
    third = (below if below is not None else above) if w < 0.5 else (above if above is not None else below)
    return lo, hi, w, third


def quad_minus_lin(t, tau, lo, hi, third, v_lo, v_hi, v_3):
    """The quadratic in ln t through the three lags minus the linear interpolation, at tau."""
    x = np.log([t[lo], t[hi], t[third], tau])
    c = np.polyfit(x[:3], np.array([v_lo, v_hi, v_3], dtype=float), 2)
    return np.polyval(c, x[3]) - (v_lo + (x[3] - x[0]) / (x[1] - x[0]) * (v_hi - v_lo))


def origin_mean(x):
    """Mean over origins (axis 0) and its standard error, as the node's BlockAverage."""
    return x.mean(axis=0), x.std(axis=0, ddof=1) / math.sqrt(x.shape[0])


def jackknife(v):
    v = np.asarray(v)
    return math.sqrt((len(v) - 1) / len(v) * np.sum((v - v.mean()) ** 2))
