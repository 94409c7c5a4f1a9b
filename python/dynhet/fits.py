"""The fits a study analysis makes across runs (dynhet.analysis), each with
its range, its quality and an error from independent runs.

Every fit takes points x with values y and standard errors sy (the error of
each point's mean over seeds) and returns a Fit: parameters, their errors
from the fit's covariance (scaled by nothing: the points' errors are taken
as they are), chi2 and degrees of freedom, the range of x it used, and a
note where it could not be made. `jackknife_over_seeds` repeats any fit
with one seed left out of every point at a time and gives the jackknife
error over seeds, the error a cross-run fit is quoted with.

Forms (the paper's eqs. and section 3):
  critical   y = A (xc - x)^-g            (tau_alpha, chi4, xi against phi)
  vft        y = A exp(B / (x0 - x))      (tau_alpha against phi)
  power      y = A x^s                    (D against tau_alpha, tau4 against tau_alpha, ...)
  critical_joint: one xc shared by several critical series
  critical_fixed: critical with xc given (the joint fit's)
`cannot_judge` says why a fit may not carry a verdict in sigma (an
improbable chi2, a singular point on the edge of the data).
"""
import math

import numpy as np
from scipy import odr
from scipy.optimize import least_squares


MIN_JK_SEEDS = 4   # below this a jackknife over seeds is not taken alone (Fit.error)


class Fit:
    def __init__(self, form, names, x_range=(math.nan, math.nan), note=""):
        self.form = form
        self.names = list(names)
        self.p = {n: math.nan for n in names}
        self.err = {n: math.nan for n in names}     # from the covariance of the fit
        self.jk = {n: math.nan for n in names}      # jackknife over seeds (set by jackknife_over_seeds)
        self.jk_seeds = 0                           # the seeds behind jk
        self.jk_partial = False                     # some points have one seed: jk misses their noise
        self.jk_p = []                              # the jackknife replicas' parameters (derived())
        self.cov, self.cov_names = None, []         # the fit's covariance, where it keeps it (derived())
        self.chi2 = math.nan
        self.dof = 0
        self.n = 0
        self.x_range = x_range
        self.xs = np.array([])   # the distinct x the fit used (singular forms: for the edge test)
        self.note = note

    @property
    def ok(self):
        return all(np.isfinite(self.p[n]) for n in self.names)

    def error(self, name):
        """The quoted error: the jackknife over seeds where it exists, else the
        fit's own; where the form misses the points (chi2/dof > 1) at least
        the fit's own error times sqrt(chi2/dof) (the Birge ratio), since
        seeds that all share the misfit agree with each other. A jackknife
        over fewer than MIN_JK_SEEDS seeds (one or two dof: its size is itself
        uncertain by a factor of two or more) is not taken alone: the larger of
        it and the fit's own error."""
        return self._quoted(self.jk.get(name, math.nan), self.err[name])

    def _quoted(self, jk, own):
        e = jk if np.isfinite(jk) else own
        if (self.jk_seeds < MIN_JK_SEEDS or self.jk_partial) and np.isfinite(own):
            e = max(e, own)
        r = self.chi2_dof()
        if np.isfinite(r) and r > 1 and np.isfinite(own):
            e = max(e, own * math.sqrt(r)) if np.isfinite(e) else own * math.sqrt(r)
        return e

    def derived(self, fn):
        """(fn(p), its quoted error) for a quantity made of the parameters (a
        ratio of two exponents, say), by the rule of error(): the jackknife
        over the same seeds' replicas of fn, and the fit's own error
        propagated through its covariance (correlations kept: two exponents
        sharing one xc are), where the fit keeps it."""
        v = float(fn(self.p))
        jk = math.nan
        reps = np.array([fn(q) for q in self.jk_p], float)
        if len(reps) >= 2 and np.all(np.isfinite(reps)):
            n = len(reps)
            jk = float(math.sqrt((n - 1) / n * ((reps - reps.mean()) ** 2).sum()))
        def slope(nm):
            h = 1e-6 * max(abs(self.p[nm]), 1.0)
            up, dn = dict(self.p), dict(self.p)
            up[nm] += h
            dn[nm] -= h
            return (fn(up) - fn(dn)) / (2 * h)
        own = math.nan
        # the covariance's parameters: those of p it names (lnA, kept as A in p, is not one of them); a
        # quantity that moves with a parameter outside it (an amplitude) has no propagated error
        inside = [nm for nm in self.cov_names if nm in self.p]
        outside = [nm for nm in self.p if nm not in inside and np.isfinite(self.p[nm])]
        if (self.cov is not None and np.all(np.isfinite(self.cov))
                and not any(slope(nm) != 0 for nm in outside)):
            g = np.array([slope(nm) if nm in self.p else 0.0 for nm in self.cov_names])
            var = float(g @ self.cov @ g)
            own = math.sqrt(var) if var >= 0 else math.nan
        return v, self._quoted(jk, own)

    @property
    def determined(self):
        """False where the fit ran to the end of its range (no divergence resolved)."""
        return self.ok and "scan's end" not in self.note

    def chi2_dof(self):
        return self.chi2 / self.dof if self.dof > 0 else math.nan

    def __repr__(self):
        ps = ", ".join(f"{n}={self.p[n]:.4g}+-{self.error(n):.2g}" for n in self.names)
        return f"Fit({self.form}: {ps}; chi2/dof={self.chi2_dof():.3g}; x in {self.x_range}; {self.note})"


def _clean(x, y, sy):
    x, y, sy = (np.asarray(v, float) for v in (x, y, sy))
    m = np.isfinite(x) & np.isfinite(y) & (y > 0) & np.isfinite(sy) & (sy > 0)
    return x[m], y[m], sy[m]


def _too_few(x, y, sy, points, distinct, what):
    """Why the points cannot carry a fit, or None: fewer than `points`
    points, fewer than `distinct` different x (a line through points at one
    x has no slope, and its normal equations are singular), or a weight
    (y / sy)^2 beyond the floats' range. `what` names the fit with its verb:
    "a power law needs"."""
    n, d = len(x), len(np.unique(x))
    if n < points:
        return f"{n} points with data in the range: {what} {points}"
    if d < distinct:
        return f"{n} points at {d} distinct x: {what} {distinct} distinct x"
    with np.errstate(all="ignore"):
        if not np.all(np.isfinite((np.asarray(y) / np.asarray(sy)) ** 2)):
            return "a relative error sy / y so small (below about 1e-154) that its weight (y / sy)^2 is beyond the floats' range"
    return None


def _wlin(u, v, w):
    """Weighted straight line v = c0 + c1 u (weights w = 1/sigma^2): (c, cov, chi2)."""
    A = np.vstack([np.ones_like(u), u]).T * np.sqrt(w)[:, None]
    b = v * np.sqrt(w)
    c, *_ = np.linalg.lstsq(A, b, rcond=None)
    try:
        cov = np.linalg.inv(A.T @ A)
    except np.linalg.LinAlgError:   # singular normal equations (met with y near 1e-300): no errors
        cov = np.full((2, 2), math.nan)
    r = A @ c - b
    return c, cov, float(r @ r)


def _chi2_lines(U, v, w):
    """The chi2 of _wlin(U[i], v, w) for every row i of U at once (closed
    form, centred sums, residuals summed explicitly), and for each the scale
    of its rounding (the sum of w times the square of the residual's terms'
    sizes): a scan's hundreds of lines in one pass instead of one lstsq each."""
    sw = w.sum()
    ub = (U * w).sum(axis=1) / sw
    vb = (v * w).sum() / sw
    du = U - ub[:, None]
    c1 = (w * du * (v - vb)).sum(axis=1) / (w * du * du).sum(axis=1)
    fit = c1[:, None] * du
    r = vb + fit - v
    return (w * r * r).sum(axis=1), (w * (abs(vb) + abs(fit) + abs(v)) ** 2).sum(axis=1)


def _scan_best(n_scan, chi2_of, chi2_all, scale):
    """(chi2, index, what chi2_of gave) of the first smallest chi2 over a
    scan, as the loop `for i: if best is None or chi2_of(i) < best: ...`
    picks it, where chi2_of(i) is the exact chi2 (each line by lstsq,
    _wlin) and chi2_all those of every i in one vectorised pass
    (_chi2_lines, with the scale of their rounding). The vectorised values
    only narrow the search: every i that could be the smallest within 1e-8
    of its scale (the rounding of either way is some 1e-16 of it) is
    computed exactly and judged as the loop judges it, so the pick, and so
    the fit, is the loop's to the bit. Where any vectorised value is not
    finite (a degenerate line), the loop over every i."""
    chi2_all, slack = np.asarray(chi2_all, float), 1e-8 * np.asarray(scale, float)
    if chi2_all.shape != (n_scan,) or not (np.all(np.isfinite(chi2_all)) and np.all(np.isfinite(slack))):
        idx = range(n_scan)
    else:
        idx = np.flatnonzero(chi2_all - slack <= (chi2_all + slack).min())
    best = None
    for i in idx:
        chi2, extra = chi2_of(int(i))
        if best is None or chi2 < best[0]:
            best = (chi2, int(i), extra)
    return best


def _inside(p0, lo, hi):
    """A least-squares start moved into its bounds (a scan's line may be
    steeper than they allow, and least_squares refuses a start outside
    them); a start inside them, bounds included, is kept as it is."""
    return np.clip(np.asarray(p0, float), lo, hi)


def _beyond_scan(top, s_max, name):
    """Why no singular point `name` can be scanned for above the largest x,
    top, or None."""
    if top + 1e-4 < s_max:
        return None
    return f"the largest x, {top:.4g}, is not at least 1e-4 below the scan's end ({s_max}): no {name} above it to find"


def _pinned(res, names, bounds):
    """Why a refinement cannot be kept, or None: the parameters (names, all
    but the first, the singular point, whose bound the scan's-end note
    covers) it left at a bound (least_squares' active_mask)."""
    pinned = [n for n, a in zip(names[1:], res.active_mask[1:]) if a != 0]
    if not pinned:
        return None
    return f"{' and '.join(pinned)} at the refinement's bound ({bounds}): the points are beyond this form's reach"


def _finish(fit, res, names, n):
    J = res.jac
    try:
        cov = np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        cov = np.full((len(names), len(names)), math.nan)
    fit.cov, fit.cov_names = cov, list(names)
    for i, nme in enumerate(names):
        fit.p[nme] = float(res.x[i])
        fit.err[nme] = float(math.sqrt(cov[i, i])) if cov[i, i] >= 0 else math.nan
    fit.chi2 = float(2 * res.cost)
    fit.n = n
    fit.dof = n - len(names)
    return fit


def power(x, y, sy, x_range=None, sx=None):
    """y = A x^s: a straight line in ln-ln, weighted by sy/y. Parameters A, s.
    With errors sx on x (x itself measured: tau_alpha, xi), orthogonal
    distance regression (scipy.odr) on the line in ln-ln with both errors
    (sx/x, sy/y): weighted least squares in y alone would let the points
    with the smallest y errors set the slope whatever their x errors."""
    fit = Fit("power", ["A", "s"])
    if sx is None:
        x, y, sy = _in_range(x, y, sy, x_range)
    else:
        x, y, sy, sx = _in_range(x, y, sy, x_range, sx)
    m = x > 0
    x, y, sy = x[m], y[m], sy[m]
    sx = sx[m] if sx is not None else None
    if (why := _too_few(x, y, sy, 3, 2, "a power law needs")):
        fit.note = why
        return fit
    fit.x_range = (float(x.min()), float(x.max()))
    c, cov, chi2 = _wlin(np.log(x), np.log(y), (y / sy) ** 2)
    if sx is not None and np.any(sx > 0):
        u_err = np.where(sx > 0, sx / x, np.min(sx[sx > 0] / x[sx > 0]) * 1e-3)
        out = odr.ODR(odr.RealData(np.log(x), np.log(y), sx=u_err, sy=sy / y),
                      odr.Model(lambda b, u: b[0] + b[1] * u), beta0=c).run()
        # sd_beta is scaled by the residual variance; cov_beta is not (the
        # points' errors taken as they are, as everywhere here).
        c, cov, chi2 = out.beta, out.cov_beta, float(out.sum_square)
        fit.note = "orthogonal distance regression (errors in x and y)"
    with np.errstate(over="ignore", invalid="ignore"):
        amp, e = float(np.exp(c[0])), np.sqrt(np.diag(cov))
    if not np.isfinite(amp):
        fit.note = f"ln A = {c[0]:.4g} (slope {c[1]:.4g}): the amplitude is beyond the floats' range"
        return fit
    fit.p.update(A=amp, s=float(c[1]))
    fit.err.update(A=float(amp * e[0]), s=float(e[1]))
    fit.chi2, fit.n, fit.dof = chi2, len(x), len(x) - 2
    return fit


def _in_range(x, y, sy, x_range, sx=None):
    """The finite points (y > 0, sy > 0) within x_range; with sx, also sx
    (NaN read as 0) of those points, as a fourth value."""
    if sx is not None:
        x, y, sy, sx = (np.asarray(v, float) for v in (x, y, sy, sx))
        m = np.isfinite(x) & np.isfinite(y) & (y > 0) & np.isfinite(sy) & (sy > 0)
        if x_range is not None:
            m &= (x >= x_range[0]) & (x <= x_range[1])
        return x[m], y[m], sy[m], np.nan_to_num(sx[m], nan=0.0)
    x, y, sy = _clean(x, y, sy)
    if x_range is not None:
        m = (x >= x_range[0]) & (x <= x_range[1])
        x, y, sy = x[m], y[m], sy[m]
    return x, y, sy


def _singular(form, names, x, y, sy, x_range, s_max, u, sign):
    """y = A exp(sign k u(s - x)) with a singular point s above every x:
    ln y is a straight line in u once s is fixed. Scans s for the best line,
    then refines s, k and ln A together (least squares on ln y, weighted by
    sy/y). names: (singular point, k, amplitude)."""
    fit = Fit(form, names)
    x, y, sy = _in_range(x, y, sy, x_range)
    if (why := _too_few(x, y, sy, 4, 3, "three parameters need")):
        fit.note = why
        return fit
    fit.x_range = (float(x.min()), float(x.max()))
    fit.xs = np.unique(x)
    top = x.max()
    if (why := _beyond_scan(top, s_max, names[0])):
        fit.note = why
        return fit
    scan = top + np.geomspace(1e-4, s_max - top, 400)
    v, w = np.log(y), (y / sy) ** 2

    def line(i):
        c, _, chi2 = _wlin(u(scan[i] - x), v, w)
        return chi2, c
    with np.errstate(all="ignore"):
        chi2_all, scale = _chi2_lines(u(scan[:, None] - x[None, :]), v, w)
    _, i0, c = _scan_best(len(scan), line, chi2_all, scale)
    s0 = scan[i0]
    sl = sy / y

    def res(p):
        return (p[2] + sign * p[1] * u(np.maximum(p[0] - x, 1e-12)) - v) / sl

    lo, hi = [top + 1e-6, -50, -200], [s_max + 1.0, 50, 200]
    r = least_squares(res, _inside([s0, sign * c[1], c[0]], lo, hi), bounds=(lo, hi))
    if (why := _pinned(r, [names[0], names[1], f"ln {names[2]}"], f"|{names[1]}| <= 50, |ln {names[2]}| <= 200")):
        fit.note = why
        return fit
    _finish(fit, r, [names[0], names[1], "lnA"], len(x))
    fit.p[names[2]], fit.err[names[2]] = math.exp(fit.p.pop("lnA")), math.exp(r.x[2]) * fit.err.pop("lnA")
    if s0 >= scan[-1] - 1e-12 or fit.p[names[0]] > s_max:
        fit.note = f"{names[0]} runs to the scan's end ({s_max}): no divergence is resolved"
    return fit


def critical(x, y, sy, x_range=None, xc_max=1.0):
    """y = A (xc - x)^-g, xc above every x. Parameters xc, g, A."""
    return _singular("critical", ["xc", "g", "A"], x, y, sy, x_range, xc_max, np.log, -1.0)


def critical_fixed(x, y, sy, xc, x_range=None):
    """y = A (xc - x)^-g with xc given (another fit's, e.g. the joint fit's
    phi_c): a weighted straight line in ln(xc - x). Parameters xc (as given,
    no error), g, A."""
    fit = Fit("critical", ["xc", "g", "A"])
    x, y, sy = _in_range(x, y, sy, x_range)
    if not np.isfinite(xc):
        fit.note = "no phi_c to hold fixed"
        return fit
    m = x < xc
    x, y, sy = x[m], y[m], sy[m]
    if (why := _too_few(x, y, sy, 3, 2, "two parameters need")):
        fit.note = f"below xc = {xc:.4g}, {why}"
        return fit
    fit.x_range = (float(x.min()), float(x.max()))
    c, cov, chi2 = _wlin(np.log(xc - x), np.log(y), (y / sy) ** 2)
    fit.p.update(xc=float(xc), g=float(-c[1]), A=float(math.exp(c[0])))
    fit.err.update(xc=0.0, g=float(math.sqrt(cov[1, 1])), A=float(math.exp(c[0]) * math.sqrt(cov[0, 0])))
    fit.chi2, fit.n, fit.dof = chi2, len(x), len(x) - 2
    fit.note = f"xc held at {xc:.4f}"
    return fit


def cannot_judge(fit, singular=None, p_min=1e-3):
    """Why a fit cannot carry a verdict in sigma, or None where it can.
    - its chi2 is improbable for its degrees of freedom (p < p_min): the form
      does not describe the points, and its errors mean nothing;
    - its singular point (singular: the parameter's name, e.g. "xc") lies
      closer to the last point than two of its own errors, or than half the
      spacing of the last two points: the fit sits on the edge of the data,
      where the last point alone places the divergence and a quantity
      plotted against (xc - x) gets all its leverage from that point."""
    r = fit.chi2_dof()
    if fit.dof > 0 and np.isfinite(fit.chi2):
        from scipy.stats import chi2 as chi2_dist
        pv = float(chi2_dist.sf(fit.chi2, fit.dof))
        if pv < p_min:
            return f"χ²/dof {r:.2g} over {fit.n} points (p = {pv:.1g}): the form does not describe the points"
    if singular is not None and singular in fit.p and np.isfinite(fit.p[singular]) and np.isfinite(fit.x_range[1]):
        gap, e = fit.p[singular] - fit.x_range[1], fit.error(singular)
        step = float(fit.xs[-1] - fit.xs[-2]) if len(fit.xs) >= 2 else math.nan
        if (np.isfinite(e) and gap < 2 * e) or (np.isfinite(step) and gap < step / 2):
            return (f"{singular} = {fit.p[singular]:.4g} lies {gap:.2g} above the last point (its error {e:.2g}, "
                    f"the last spacing {step:.2g}): the fit sits on the edge of the data")
    return None


def vft(x, y, sy, x_range=None, x0_max=1.0):
    """y = A exp(B/(x0 - x)), x0 above every x. Parameters x0, B, A."""
    return _singular("vft", ["x0", "B", "A"], x, y, sy, x_range, x0_max, lambda d: 1.0 / d, 1.0)


def critical_joint(series, x_range=None, xc_max=1.0):
    """Several quantities y_k = A_k (xc - x)^-g_k with one xc (the paper's
    "simultaneous fit of tau_alpha, chi4 and xi"). series: {name: (x, y, sy)}.
    Parameters xc, g_<name>, A_<name>."""
    keys = list(series)
    names = ["xc"] + [f"g_{k}" for k in keys] + [f"A_{k}" for k in keys]
    fit = Fit("critical_joint", names)
    data = {}
    for k in keys:
        x, y, sy = _in_range(*series[k], x_range)
        if (why := _too_few(x, y, sy, 3, 2, "each series needs")):
            fit.note = f"{k}: {why}"
            return fit
        data[k] = (x, y, sy)
    if max(len(np.unique(d[0])) for d in data.values()) < 3:
        fit.note = "no series has 3 distinct x: a line per series through 2 x fits any xc"
        return fit
    allx = np.concatenate([d[0] for d in data.values()])
    fit.x_range = (float(allx.min()), float(allx.max()))
    fit.xs = np.unique(allx)
    top = allx.max()
    if (why := _beyond_scan(top, xc_max, "xc")):
        fit.note = why
        return fit
    scan = top + np.geomspace(1e-4, xc_max - top, 300)

    def lines(i):
        tot, cs = 0.0, []
        for k in keys:
            x, y, sy = data[k]
            c, _, chi2 = _wlin(np.log(scan[i] - x), np.log(y), (y / sy) ** 2)
            tot += chi2
            cs.append(c)
        return tot, cs
    with np.errstate(all="ignore"):
        per = [_chi2_lines(np.log(scan[:, None] - x[None, :]), np.log(y), (y / sy) ** 2) for x, y, sy in data.values()]
    _, i0, cs = _scan_best(len(scan), lines, sum(p[0] for p in per), sum(p[1] for p in per))
    xc0 = scan[i0]
    p0 = [xc0] + [-c[1] for c in cs] + [c[0] for c in cs]
    K = len(keys)

    def res(p):
        out = []
        for i, k in enumerate(keys):
            x, y, sy = data[k]
            d = np.maximum(p[0] - x, 1e-12)
            out.append((p[1 + K + i] - p[1 + i] * np.log(d) - np.log(y)) / (sy / y))
        return np.concatenate(out)

    lo = [top + 1e-6] + [-50] * K + [-200] * K
    hi = [xc_max + 1.0] + [50] * K + [200] * K
    r = least_squares(res, _inside(p0, lo, hi), bounds=(lo, hi))
    lnames = ["xc"] + [f"g_{k}" for k in keys] + [f"lnA_{k}" for k in keys]
    if (why := _pinned(r, lnames, "|g| <= 50, |ln A| <= 200")):
        fit.note = why
        return fit
    tmp = Fit("tmp", lnames)
    _finish(tmp, r, lnames, len(allx))
    fit.p["xc"], fit.err["xc"] = tmp.p["xc"], tmp.err["xc"]
    for i, k in enumerate(keys):
        fit.p[f"g_{k}"], fit.err[f"g_{k}"] = tmp.p[f"g_{k}"], tmp.err[f"g_{k}"]
        fit.p[f"A_{k}"] = math.exp(tmp.p[f"lnA_{k}"])
        fit.err[f"A_{k}"] = fit.p[f"A_{k}"] * tmp.err[f"lnA_{k}"]
    fit.chi2, fit.n, fit.dof = tmp.chi2, tmp.n, tmp.dof
    k = 1 + len(keys)   # xc and the exponents: the same names here as in tmp
    fit.cov, fit.cov_names = tmp.cov[:k, :k], lnames[:k]
    if xc0 >= top + (xc_max - top) * 0.999:
        fit.note = f"xc runs to the scan's end ({xc_max}): no divergence is resolved"
    return fit


def seed_mean(values):
    """Mean over seeds and its standard error from their spread (NaN for one seed)."""
    v = np.asarray([a for a in values if np.isfinite(a)], float)
    if len(v) == 0:
        return math.nan, math.nan, 0
    if len(v) == 1:
        return float(v[0]), math.nan, 1
    return float(v.mean()), float(v.std(ddof=1) / math.sqrt(len(v))), len(v)


def quoted_mean_error(errs):
    """The error of a mean over seeds from each run's own quoted error."""
    e = np.asarray([a for a in errs if np.isfinite(a)], float)
    return float(math.sqrt((e ** 2).sum()) / len(e)) if len(e) else math.nan


def jackknife_over_seeds(fit_fn, seeds, fit=None):
    """Jackknife over independent runs. fit_fn(drop) makes the fit with
    seed `drop` left out of every point (drop=None: all seeds) and returns
    a Fit. Sets fit.jk (sqrt((n-1)/n sum (theta_s - theta_bar)^2) over the
    n seeds) and returns the fit."""
    if fit is None:
        fit = fit_fn(None)
    seeds = sorted(set(seeds))
    if not fit.ok or len(seeds) < 2:
        if len(seeds) < 2:
            fit.note = (fit.note + "; " if fit.note else "") + "one seed: no error over runs"
        return fit
    reps = [fit_fn(s) for s in seeds]
    n = len(reps)
    fit.jk_seeds = n
    fit.jk_p = [dict(r.p) for r in reps]
    failed = set()
    for name in fit.names:
        th = np.array([r.p.get(name, math.nan) if r.ok else math.nan for r in reps], float)
        if np.all(np.isfinite(th)):
            fit.jk[name] = float(math.sqrt((n - 1) / n * ((th - th.mean()) ** 2).sum()))
        else:
            failed |= {s for s, t in zip(seeds, th) if not np.isfinite(t)}
    if failed:   # no jackknife where a replicate has no value: the fit's own error, and it says so
        fit.note = ((fit.note + "; " if fit.note else "") + f"the fit without seed {', '.join(map(str, sorted(failed)))} "
                    "failed: the fit's own error, no jackknife over seeds")
    return fit


def interp_ln_t(t, y, at):
    """y(t) at t = at, linear in ln t between the two lags around it. Returns
    (value, interpolation error): the error is the difference from the
    parabola in ln t through the three lags nearest `at` (NaN outside the
    lags or where y is not finite there)."""
    t, y = np.asarray(t, float), np.asarray(y, float)
    if not np.isfinite(at) or at <= 0 or len(t) < 2 or at < t[0] or at > t[-1]:
        return math.nan, math.nan
    lt, la = np.log(t), math.log(at)
    j = int(np.searchsorted(lt, la))
    j = min(max(j, 1), len(t) - 1)
    a, b = j - 1, j
    if not (np.isfinite(y[a]) and np.isfinite(y[b])):
        return math.nan, math.nan
    f = (la - lt[a]) / (lt[b] - lt[a]) if lt[b] > lt[a] else 0.0
    lin = float(y[a] + f * (y[b] - y[a]))
    idx = np.argsort(np.abs(lt - la))[:3]
    idx = np.sort(idx)
    if len(idx) < 3 or not np.all(np.isfinite(y[idx])):
        return lin, math.nan
    c = np.polyfit(lt[idx], y[idx], 2)
    return lin, float(abs(np.polyval(c, la) - lin))


def slope_with_error(x, y):
    """(slope, its standard error from the residuals, points) of a straight
    line through (x, y), x = t0 / tau_alpha; NaN error with fewer than 4
    points (2 dof) or where neighbouring origins lie less than one tau_alpha
    apart (their tau_alpha(t0) are correlated: the residuals would understate it)."""
    n = len(x)
    b, a = np.polyfit(x, y, 1)
    if n < 4 or np.min(np.diff(np.sort(x))) < 1.0:
        return float(b), math.nan, n
    sxx = float(((x - x.mean()) ** 2).sum())
    ssr = float(((y - (a + b * x)) ** 2).sum())
    return float(b), math.sqrt(ssr / (n - 2) / sxx) if sxx > 0 else math.nan, n
