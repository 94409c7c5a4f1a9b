"""Data collapse: the exponent that lays curves with different cutoffs onto one.

The paper's kappa (sec. 3.3, fig. dist-collapse) is not the slope of one
density's P(N_c) but the exponent of a collapse over densities: P(N_c)
N_c^kappa against N_c / N*. Each curve is a histogram (n = N_c, bin
widths w, P, error of P); N* = <N_c^3>/<N_c^2> of its P (below). The quality of a
collapse at kappa is the mean, over every point of every curve that lies
inside another curve's x = N_c / N* range, of the squared difference
between its ln(P n^kappa) and the other curve's (linear in ln x between
that curve's two points around it), over the sum of both variances
(Houdayer and Hartmann, PRB 70, 014418 (2004)): about 1 where the curves
agree within their errors (somewhat below: an interpolated point is less
noisy than the variance interpolated). Interpolation is linear and the
overlaps do not depend on kappa, so the quality is a parabola in kappa and
its minimum is found in closed form. The error: a parametric bootstrap,
each curve's P drawn again within its errors and N* recomputed from the
draw. (The width at which the quality rises by 1 overstates the error
several times: the terms are not independent.)
"""
import math

import numpy as np

from .fits import Fit

M = 4  # N* = <N_c^M>/<N_c^(M-1)>
KAPPA_RANGE = (0.5, 3.5)   # an exponent outside is no collapse of a size distribution


def n_star(n, w, p):
    """<N_c^M>/<N_c^(M-1)> of a histogram (P per unit N_c, bin widths w)."""
    p = np.where(np.isfinite(p) & (p > 0), p, 0.0)
    s1, s2 = np.sum(p * n ** (M - 1) * w), np.sum(p * n ** M * w)
    return s2 / s1 if s1 > 0 else math.nan


def prepare(curves, lo):
    """Histograms [(n, w, P, sP)] -> [(ln x, ln n, ln P, sigma of ln P)]:
    x = n / N*, bins with n >= lo, P > 0 and an error below P (a bin whose
    error exceeds its value says nothing of ln P); curves with >= 2 bins."""
    out = []
    for n, w, p, sp in curves:
        n, w, p, sp = (np.asarray(v, float) for v in (n, w, p, sp))
        ns = n_star(n, w, p)
        if not (np.isfinite(ns) and ns > 0):
            continue
        m = (n >= lo) & np.isfinite(p) & (p > 0) & np.isfinite(sp) & (sp > 0) & (sp < p)
        if m.sum() >= 2:
            o = np.argsort(n[m])
            out.append((np.log(n[m] / ns)[o], np.log(n[m])[o], np.log(p[m])[o], (sp[m] / p[m])[o]))
    return out


def _sums(curves):
    """The parabola: quality(k) = (c + 2 b k + a k^2) / cnt."""
    a = b = c = 0.0
    cnt = 0
    for i, (ui, li, yi, si) in enumerate(curves):
        for j, (uj, lj, yj, sj) in enumerate(curves):
            if i == j:
                continue
            m = (ui >= uj[0]) & (ui <= uj[-1])
            if not m.any():
                continue
            dy = yi[m] - np.interp(ui[m], uj, yj)
            dl = li[m] - np.interp(ui[m], uj, lj)
            d = si[m] ** 2 + np.interp(ui[m], uj, sj) ** 2
            a += float(np.sum(dl * dl / d))
            b += float(np.sum(dy * dl / d))
            c += float(np.sum(dy * dy / d))
            cnt += int(m.sum())
    return a, b, c, cnt


def quality(curves, k):
    """(the collapse's quality at exponent k, the number of terms) for prepared curves."""
    a, b, c, cnt = _sums(curves)
    return ((c + 2 * b * k + a * k * k) / cnt if cnt else math.nan), cnt


def best(curves):
    """(kappa of the best collapse, its quality, terms); NaN kappa where
    the curves do not overlap or the minimum lies outside KAPPA_RANGE."""
    a, b, c, cnt = _sums(curves)
    if cnt == 0 or a <= 0:
        return math.nan, math.nan, cnt
    k = -b / a
    q = (c + 2 * b * k + a * k * k) / cnt
    return (k if KAPPA_RANGE[0] <= k <= KAPPA_RANGE[1] else math.nan), q, cnt


def exponent(curves, lo=1.0, resamples=0, seed=1):
    """A Fit("collapse", ["kappa"]) of histograms [(n, w, P, sP)], bins
    with n >= lo: kappa at the best collapse; with resamples > 0, err =
    the bootstrap's standard deviation (fixed seed: the same data give the
    same error). The quality goes to fit.quality (it is not a chi^2:
    each pair is counted both ways and the terms share points), chi2 and
    dof stay unset."""
    pc = prepare(curves, lo)
    fit = Fit("collapse", ["kappa"])
    fit.quality = math.nan
    if len(pc) < 2:
        fit.note = f"{len(pc)} curve(s) with data: no collapse"
        return fit
    k, q, cnt = best(pc)
    if not np.isfinite(k):
        fit.note = (f"no overlap of the curves' N_c / N*" if cnt == 0 else
                    f"the best collapse lies outside κ in [{KAPPA_RANGE[0]:g}, {KAPPA_RANGE[1]:g}]")
        return fit
    fit.p["kappa"], fit.quality, fit.n = k, q, cnt
    fit.note = f"{len(pc)} curves, {cnt} overlapping points, quality {q:.2g} at the minimum"
    if resamples > 0:
        rng = np.random.default_rng(seed)
        ks = []
        for _ in range(resamples):
            drawn = [(n, w, np.asarray(p, float) + rng.normal(0.0, 1.0, len(p)) * np.nan_to_num(np.asarray(sp, float)), sp)
                     for n, w, p, sp in curves]
            ks.append(best(prepare(drawn, lo))[0])
        ks = np.array(ks)
        ok = np.isfinite(ks)
        if ok.sum() >= max(10, int(0.9 * resamples)):
            fit.err["kappa"] = float(ks[ok].std(ddof=1))
            fit.note += f"; bootstrap over the bins' errors, N* redrawn ({ok.sum()} resamples)"
        else:
            fit.note += f"; bootstrap: only {ok.sum()} of {resamples} resamples collapse, no error"
    return fit
