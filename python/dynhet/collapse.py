"""Data collapse: the exponent that lays curves with different cutoffs onto one.

The paper's kappa (sec. 3.3, fig. dist-collapse) is not the slope of one
density's P(N_c) but the exponent of a collapse over densities: P(N_c)
N_c^kappa against N_c / N*. Here each curve is (x = N_c / N*, n = N_c,
P, error of P); the quality of a collapse at kappa is the mean, over
every point of every curve that lies inside another curve's x range, of
the squared difference between its ln(P n^kappa) and the other curve's
(linear in ln x between that curve's two points around it), over the sum
of both variances (Houdayer and Hartmann's measure, PRB 70, 014418
(2004)): about 1 where the curves agree within their errors. kappa is its
minimum; its error is a parametric bootstrap (each P drawn again within
its error, the minimum found again; ln P drawn within sigma_P / P), since the quality is not a chi^2 of
independent terms: the width at which it rises by 1 overstates the error
several times (seen against independent seeds: docs/reproduction_findings.md).
"""
import math

import numpy as np
from scipy.optimize import minimize_scalar

from .fits import Fit

GRID = np.arange(0.5, 3.5001, 0.02)   # exponents scanned before the minimum is refined


def prepare(curves):
    """[(x, n, P, sP)] -> [(ln x, ln n, ln P, sigma of ln P)], bins with P > 0
    and an error below P only, curves with at least 2 such bins."""
    out = []
    for x, n, p, sp in curves:
        x, n, p, sp = (np.asarray(v, float) for v in (x, n, p, sp))
        m = np.isfinite(x) & (x > 0) & np.isfinite(n) & (n > 0) & np.isfinite(p) & (p > 0) & np.isfinite(sp) & (sp > 0) & (sp < p)
        if m.sum() >= 2:
            o = np.argsort(x[m])
            out.append((np.log(x[m])[o], np.log(n[m])[o], np.log(p[m])[o], (sp[m] / p[m])[o]))
    return out


def quality(curves, k):
    """(the collapse's quality at exponent k, the number of terms) for prepared curves."""
    num, cnt = 0.0, 0
    for i, (ui, li, yi, si) in enumerate(curves):
        for j, (uj, lj, yj, sj) in enumerate(curves):
            if i == j:
                continue
            m = (ui >= uj[0]) & (ui <= uj[-1])
            if not m.any():
                continue
            yint = np.interp(ui[m], uj, yj + k * lj)
            sint = np.interp(ui[m], uj, sj)
            num += float(np.sum((yi[m] + k * li[m] - yint) ** 2 / (si[m] ** 2 + sint ** 2)))
            cnt += int(m.sum())
    return (num / cnt if cnt else math.nan), cnt


def best(curves, near=None):
    """The exponent of the best collapse: the grid's minimum (within 0.3 of
    `near` where given), refined between its neighbours."""
    grid = GRID if near is None else GRID[np.abs(GRID - near) <= 0.3]
    s = np.array([quality(curves, k)[0] for k in grid])
    if not np.isfinite(s).any():
        return math.nan
    i = int(np.nanargmin(s))
    if i == 0 or i == len(grid) - 1:
        return math.nan   # no minimum inside the scanned exponents
    r = minimize_scalar(lambda k: quality(curves, k)[0], bounds=(grid[i - 1], grid[i + 1]), method="bounded",
                        options={"xatol": 1e-4})
    return float(r.x)


def exponent(curves, resamples=0, seed=1):
    """A Fit("collapse", ["kappa"]) of raw curves [(x, n, P, sP)]: kappa at the
    best collapse; with resamples > 0 its error from a parametric bootstrap
    (fixed seed: the same data give the same error). chi2 / dof is the
    quality at the minimum (Fit.error then widens the error where the
    curves do not collapse within their errors)."""
    pc = prepare(curves)
    fit = Fit("collapse", ["kappa"])
    if len(pc) < 2:
        fit.note = f"{len(pc)} curve(s) with data: no collapse"
        return fit
    k = best(pc)
    if not np.isfinite(k):
        fit.note = f"no minimum of the collapse's quality for kappa in [{GRID[0]:g}, {GRID[-1]:g}]"
        return fit
    q, cnt = quality(pc, k)
    fit.p["kappa"] = k
    fit.chi2, fit.n, fit.dof = q * (cnt - 1), cnt, cnt - 1
    fit.note = f"{len(pc)} curves, {cnt} overlapping points, quality {q:.2g} at the minimum"
    if resamples > 0:
        rng = np.random.default_rng(seed)
        ks = []
        for _ in range(resamples):
            drawn = [(u, ln, y + rng.normal(0.0, 1.0, len(y)) * s, s) for u, ln, y, s in pc]
            ks.append(best(drawn, near=k))
        ks = np.array([v for v in ks if np.isfinite(v)])
        if len(ks) >= max(10, resamples // 2):
            fit.err["kappa"] = float(ks.std(ddof=1))
            fit.note += f"; error: bootstrap over the bins' errors ({len(ks)} resamples)"
    return fit
