#!/usr/bin/env python3
"""Each cross-run fit of the study analysis (python/dynhet/fits.py)
against synthetic studies with known parameters: K seeds per point, each
seed's value the true one times (1 + s * gaussian noise), its quoted error
s * true value, as a run reports it. The fit with its jackknife error over
seeds must recover every parameter within 3 errors in every one of R
synthetic studies, and the errors must be honest: the fraction of studies
whose parameter lies within one jackknife error of the truth must be that
of a t distribution with K-1 degrees of freedom (0.64 for K = 6) within
its binomial spread. Through the study analysis' own fit_series: chi4
against xi with errors on both axes (orthogonal distance regression) and
the sub-box bias of eq. (14), which the pooled estimator does not have;
critical fits on the edge of the data not judged, and with phi_c held
fixed. Also: the ln t interpolation is exact for a line in
ln t and its error estimate is zero there; fits with too few points say so.
Usage: test_study_fits.py (the package is the repository's python/dynhet, beside it as tests/dynhet)"""
import math
import sys

import numpy as np

from dynhet import fits as sf

K, R, S = 6, 60, 0.03
fails = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        fails.append(what)


def synthetic(fit_fn, x, truth_fn, params, rng):
    """R synthetic studies; returns per parameter the normalised deviations (est - true)/jk_err."""
    y_true = truth_fn(x)
    devs = {p: [] for p in params}
    for _ in range(R):
        runs = y_true[None, :] * (1 + S * rng.standard_normal((K, len(x))))

        def one(drop):
            keep = [k for k in range(K) if k != drop]
            y = runs[keep].mean(axis=0)
            sy = S * y_true / math.sqrt(len(keep))
            return fit_fn(x, y, sy)
        f = sf.jackknife_over_seeds(one, list(range(K)))
        for p, true in params.items():
            devs[p].append((f.p[p] - true) / f.error(p) if f.ok else math.inf)
    return {p: np.array(v) for p, v in devs.items()}


def judge(name, devs):
    # P(|t_5| < 1) = 0.637; binomial sd over R = 60 studies is 0.062: accept 0.45 .. 0.85
    for p, d in devs.items():
        inside = float(np.mean(np.abs(d) < 1))
        check(np.all(np.abs(d) < 3 * 2.0) and np.mean(np.abs(d) < 3) > 0.9,
              f"{name}: {p} recovered within 3 jackknife errors in {np.mean(np.abs(d) < 3):.0%} of {R} studies (worst {np.max(np.abs(d)):.2f})")
        check(0.45 <= inside <= 0.85, f"{name}: {p} within one error in {inside:.0%} of studies (t with {K - 1} dof: 64%)")


rng = np.random.default_rng(20261123)
phi = np.array([0.60, 0.65, 0.70, 0.72, 0.74, 0.76, 0.77, 0.78, 0.785, 0.79, 0.795, 0.80])

# tau_alpha = 0.05 (0.82 - phi)^-2.4
judge("critical (power law in phi_c - phi)",
      synthetic(sf.critical, phi, lambda x: 0.05 * (0.82 - x) ** -2.4, {"xc": 0.82, "g": 2.4}, rng))
# tau_alpha = 0.2 exp(0.5/(0.83 - phi))
judge("vft", synthetic(sf.vft, phi, lambda x: 0.2 * np.exp(0.5 / (0.83 - x)), {"x0": 0.83, "B": 0.5}, rng))
# D = 0.3 tau^-1.47 over tau from 1.5 to 50
tau = np.geomspace(1.5, 50, 9)
judge("power", synthetic(sf.power, tau, lambda x: 0.3 * x ** -1.47, {"s": -1.47}, rng))


# joint: tau, chi4, xi with one phi_c
def joint_truth():
    return {"tau": lambda x: 0.05 * (0.82 - x) ** -2.4, "chi4": lambda x: 0.02 * (0.82 - x) ** -2.5,
            "xi": lambda x: 0.1 * (0.82 - x) ** -1.6}


devs = {"xc": [], "g_chi4": [], "g_xi": [], "g_chi4/g_xi": []}
own_ratio = []   # the ratio's error from the covariance alone, against the truth
for _ in range(R // 2):
    data = {k: f(phi)[None, :] * (1 + S * rng.standard_normal((K, len(phi)))) for k, f in joint_truth().items()}

    def one(drop):
        keep = [k for k in range(K) if k != drop]
        return sf.critical_joint({k: (phi, v[keep].mean(axis=0), S * joint_truth()[k](phi) / math.sqrt(len(keep)))
                                  for k, v in data.items()})
    f = sf.jackknife_over_seeds(one, list(range(K)))
    for p, true in (("xc", 0.82), ("g_chi4", 2.5), ("g_xi", 1.6)):
        devs[p].append((f.p[p] - true) / f.error(p))
    # a quantity of two parameters (the exponent ratio of the finite-size collapse): Fit.derived
    ratio = lambda q: q["g_chi4"] / q["g_xi"]
    v, e = f.derived(ratio)
    devs["g_chi4/g_xi"].append((v - 2.5 / 1.6) / e)
    f.jk_p = []
    own_ratio.append((v - 2.5 / 1.6) / f.derived(ratio)[1])
own_ratio = np.array(own_ratio)
check(0.45 <= np.mean(np.abs(own_ratio) < 1) <= 0.9,
      f"Fit.derived from the covariance alone (correlations kept): the ratio within one error in {np.mean(np.abs(own_ratio) < 1):.0%} of studies")
for p, d in devs.items():
    d = np.array(d)
    check(np.mean(np.abs(d) < 3) > 0.9, f"critical_joint: {p} recovered within 3 jackknife errors in {np.mean(np.abs(d) < 3):.0%} of {R // 2} studies")
    check(0.40 <= np.mean(np.abs(d) < 1) <= 0.90, f"critical_joint: {p} within one error in {np.mean(np.abs(d) < 1):.0%} of studies")

# too few points: a note, no numbers
f = sf.critical(phi[:3], phi[:3] * 0 + 1, phi[:3] * 0 + 0.1)
check(not f.ok and "need 4" in f.note, f"critical with 3 points says why it is not made: {f.note!r}")
f = sf.power([1, 2], [1, 2], [0.1, 0.1])
check(not f.ok and "needs 3" in f.note, f"power with 2 points says why it is not made: {f.note!r}")
f = sf.jackknife_over_seeds(lambda d: sf.power(tau, tau, tau * 0.1), [1])
check("one seed" in f.note and not np.isfinite(f.jk["s"]), "one seed: no jackknife error, and the note says so")

# interpolation in ln t
t = np.geomspace(0.1, 100, 13)
v, e = sf.interp_ln_t(t, 2 + 3 * np.log(t), 7.3)
check(abs(v - (2 + 3 * math.log(7.3))) < 1e-12 and e < 1e-12, f"interp_ln_t exact on a line in ln t ({v:.15g}, error {e:.2g})")
v, e = sf.interp_ln_t(t, np.log(t) ** 2, 7.3)
true = math.log(7.3) ** 2
check(abs(v - true) <= 1.5 * e + 1e-12 and e > 0, f"interp_ln_t on a parabola: error estimate {e:.3g} covers the miss {abs(v - true):.3g}")
check(all(math.isnan(x) for x in sf.interp_ln_t(t, t, 1000.0)), "interp_ln_t outside the lags: NaN")

# --- The analysis path itself (analyse_study.fit_series on Points of runs):
# chi4 ~ xi^d_f with errors on both axes and a known sub-box bias.
from dynhet.analysis import config, points

DF, XI_S, CHI_S = 1.6, 0.25, 0.03   # true d_f'; relative error of one run's xi and chi4
xi_true = np.geomspace(1.2, 12.0, 10)
M, ELL = 9, 7.0                     # a 3 x 3 grid of sub-boxes of side ELL


def eq14_factor(xi):
    """eq. (14) removes each origin's mean over the M boxes: low by the part
    of the variance the boxes share, here (xi/ELL)^2/(1 + (xi/ELL)^2) of it
    (more as xi approaches the box), times (M - 1)/M of the rest."""
    shared = (xi / ELL) ** 2 / (1 + (xi / ELL) ** 2)
    return (1 - shared) * (M - 1) / M


def synthetic_points(rng):
    pts = []
    for i, x in enumerate(xi_true):
        pt = points.Point(("neighbours", 0.9, 0.7 + 0.01 * i, 4096))
        for k in range(K):
            xv = x * (1 + XI_S * rng.standard_normal())
            c = 0.5 * x ** DF * (1 + CHI_S * rng.standard_normal())
            pt.runs.append({"seed": k, "xi": (xv, XI_S * x), "chi4": (c, CHI_S * c),
                            "chi4_eq14": (c * eq14_factor(x), CHI_S * c * eq14_factor(x))})
        pts.append(pt)
    return pts


dev_odr, dev_wls, dev_eq14, chi_odr, chi_wls = [], [], [], [], []
for _ in range(R // 2):
    pts = synthetic_points(rng)
    f = points.fit_series(pts, lambda r: r["chi4"], sf.power, xrun=lambda r: r["xi"], x_range=(config.XI_MIN_DF, math.inf))
    dev_odr.append((f.p["s"] - DF) / f.error("s"))
    chi_odr.append(f.chi2_dof())
    w = points.fit_series(pts, lambda r: r["chi4"], sf.power, xpoint=lambda p: p.mean(lambda r: r["xi"])[0],
                      x_range=(config.XI_MIN_DF, math.inf))  # x errors ignored: weighted least squares in y
    dev_wls.append((w.p["s"] - DF) / w.error("s"))
    chi_wls.append(w.chi2_dof())
    b = points.fit_series(pts, lambda r: r["chi4_eq14"], sf.power, xrun=lambda r: r["xi"], x_range=(config.XI_MIN_DF, math.inf))
    dev_eq14.append((b.p["s"] - DF) / b.error("s"))
dev_odr, dev_wls, dev_eq14 = map(np.array, (dev_odr, dev_wls, dev_eq14))
check("orthogonal distance" in f.note, f"fit_series with x errors uses ODR ({f.note!r})")
check(np.mean(np.abs(dev_odr) < 3) > 0.9 and 0.40 <= np.mean(np.abs(dev_odr) < 1) <= 0.90,
      f"d_f' with errors on both axes, through fit_series: recovered within 1 error in {np.mean(np.abs(dev_odr) < 1):.0%}, "
      f"within 3 in {np.mean(np.abs(dev_odr) < 3):.0%} of {R // 2} studies (mean deviation {dev_odr.mean():+.2f})")
check(np.median(chi_odr) < 2.0 and np.median(chi_wls) > 10.0,
      f"chi2/dof: {np.median(chi_odr):.2g} with both errors, {np.median(chi_wls):.2g} with x errors ignored (median over "
      "studies): weighted least squares in y alone misjudges the points")
check(dev_eq14.mean() < -2.0,
      f"eq. (14)'s sub-box bias, growing with xi, lowers d_f' by {-dev_eq14.mean():.1f} errors on average: the "
      "pooled estimator is the one to fit")

# critical fits: phi_c on the edge of the data is not judged; a fit with
# phi_c held fixed recovers the exponent.
x = phi
y_edge = 0.05 * (0.8004 - x) ** -1.0
f = sf.critical(x, y_edge * (1 + 0.01 * rng.standard_normal(len(x))), 0.01 * y_edge)
why = sf.cannot_judge(f, "xc")
check(why is not None and "edge" in why, f"phi_c {f.p['xc']:.5f}, 0.0004 above the last point: not judged ({why})")
y_ok = 0.05 * (0.82 - x) ** -2.4
f = sf.critical(x, y_ok * (1 + 0.01 * rng.standard_normal(len(x))), 0.01 * y_ok)
check(sf.cannot_judge(f, "xc") is None, f"phi_c 0.02 above the data with a fitting form: judged ({f.p['xc']:.4f})")
f = sf.critical(x, y_ok * np.exp(0.3 * np.sin(40 * x)), 0.01 * y_ok)
why = sf.cannot_judge(f, "xc")
check(why is not None and "does not describe" in why, f"a form that misses the points by 30x their errors: not judged ({why})")
devs = {"g": []}
for _ in range(R):
    yy = y_ok * (1 + S * rng.standard_normal((K, len(x))))

    def one(drop):
        keep = [k for k in range(K) if k != drop]
        return sf.critical_fixed(x, yy[keep].mean(axis=0), S * y_ok / math.sqrt(len(keep)), 0.82)
    f = sf.jackknife_over_seeds(one, list(range(K)))
    devs["g"].append((f.p["g"] - 2.4) / f.error("g"))
judge("critical with phi_c held at its true value", {k: np.array(v) for k, v in devs.items()})

print(f"{len(fails)} failed" if fails else "all passed")
sys.exit(1 if fails else 0)
