"""dynhet.analysis.points: a per-point error is the runs' quoted errors
combined, times the study's pooled seed-spread ratio for that quantity where
that ratio is resolved above 1 (at least MIN_CAL_DOF dof, more than two of its
uncertainties above 1); never smaller than quoted; one factor per study and
per quantity."""
import math

import numpy as np

from dynhet.analysis.points import MIN_CAL_DOF, Point, ensure_calibrated, fn_key


def tau(r):
    return r["tau"], r["tau_err"]


def other(r):
    return r["tau"] * 2, r["tau_err"] * 2


def study(n_points, spread, quoted, name=None, seeds=(1, 2, 3), rng=None):
    """n_points points whose seeds scatter by `spread` (exactly 0, -spread,
    +spread around each mean; or Gaussian with rng) and quote `quoted`."""
    pts = []
    for k in range(n_points):
        p = Point(("neighbours", 0.9, 0.70 + 0.01 * k, 4096))
        if name:
            p.study = name
        for s, seed in enumerate(seeds):
            d = rng.normal(0, spread) if rng is not None else (0.0, -spread, spread)[s]
            p.runs.append({"seed": seed, "tau": 50.0 + k + d, "tau_err": quoted})
        pts.append(p)
    return pts


def test_errors_twice_too_small_are_doubled():
    # Seeds 0, -sqrt(3), +sqrt(3) around the mean: sample sd sqrt(3), quoted 1.
    pts = study(6, math.sqrt(3.0), 1.0)           # 6 points x 2 dof = 12 dof
    ensure_calibrated(pts)
    k, r, u, dof = pts[0].population.calibration(tau)
    assert dof == 12 and math.isclose(r, math.sqrt(3.0)) and math.isclose(k, r)
    m, e, sem, n = pts[0].mean(tau)
    assert n == 3 and math.isclose(e, math.sqrt(3.0) * math.sqrt(3.0) / 3)  # quoted sqrt(3)/3, times sqrt(3)
    assert math.isclose(e, sem)  # here the seeds' spread is the same at every point


def test_honest_errors_are_left_as_quoted():
    rng = np.random.default_rng(11)
    pts = study(100, 2.0, 2.0, rng=rng)
    ensure_calibrated(pts)
    k, r, u, dof = pts[0].population.calibration(tau)
    assert dof == 200 and abs(r - 1.0) < 3 * u
    assert k == 1.0  # seed 11: r = 0.94 +- 0.05: honest, no factor
    m, e, _, _ = pts[5].mean(tau)
    assert math.isclose(e, 2.0 * math.sqrt(3) / 3)


def test_too_few_dof_or_too_large_errors_leave_them_alone():
    few = study((MIN_CAL_DOF - 1) // 2, 3.0, 1.0)   # fewer than MIN_CAL_DOF dof: no scaling
    ensure_calibrated(few)
    assert few[0].population.calibration(tau)[0] == 1.0
    assert math.isclose(few[0].mean(tau)[1], math.sqrt(3) / 3)
    big = study(10, 0.5, 2.0)                       # quoted errors larger than the spread: not shrunk
    ensure_calibrated(big)
    assert big[0].population.calibration(tau)[0] == 1.0


def test_one_factor_per_study_and_per_quantity():
    a = study(6, math.sqrt(3.0), 1.0, name="a")
    b = study(6, math.sqrt(3.0) * 3, 1.0, name="b")
    ensure_calibrated(a + b)
    assert a[0].population is a[5].population and a[0].population is not b[0].population
    assert math.isclose(a[0].factor(tau), math.sqrt(3.0)) and math.isclose(b[0].factor(tau), 3 * math.sqrt(3.0))
    assert math.isclose(a[0].factor(other), math.sqrt(3.0))  # its own ratio, the same here by construction
    # Functions that differ only by what their closure holds are different quantities.
    fns = [(lambda s: (lambda r: (r["tau"] * s, r["tau_err"])))(s) for s in (1.0, 0.0)]
    assert fn_key(fns[0]) != fn_key(fns[1])
    assert a[0].factor(fns[1]) == 1.0 and math.isclose(a[0].factor(fns[0]), math.sqrt(3.0))


def test_a_point_without_quoted_errors_takes_the_seeds_spread():
    pts = study(6, 1.5, math.nan)
    ensure_calibrated(pts)
    m, e, sem, n = pts[0].mean(tau)
    assert math.isclose(e, sem) and math.isclose(sem, 1.5 / math.sqrt(3))


def test_a_study_with_too_few_seeds_borrows_the_pooled_ratio():
    a = study(6, math.sqrt(3.0), 1.0, name="a")                       # 12 dof of its own
    one = study(4, 0.0, 1.0, name="one", seeds=(1,))                  # one seed: no dof
    ensure_calibrated(a + one)
    assert one[0].population.own(tau)[3] == 0
    k, r, u, dof = one[0].population.calibration(tau)
    assert dof == 12 and math.isclose(k, math.sqrt(3.0))            # all studies together: a's 12 dof
    assert math.isclose(one[0].mean(tau)[1], math.sqrt(3.0))         # its quoted 1, times the pooled ratio
    assert math.isclose(a[0].factor(tau), math.sqrt(3.0))             # a keeps its own


def test_a_mean_over_seeds_of_which_some_quote_no_error_takes_the_seeds_spread():
    # 1000 +- 5 and 2000 without an error: not "1500 +- 5" but the standard
    # error of the two seeds, 500.
    p = Point(("neighbours", 0.9, 0.79, 4096))
    p.runs = [{"seed": 1, "tau": 1000.0, "tau_err": 5.0}, {"seed": 2, "tau": 2000.0, "tau_err": math.nan}]
    m, e, sem, n = p.mean(tau)
    assert (m, n) == (1500.0, 2) and math.isclose(sem, 500.0) and math.isclose(e, 500.0)
    p.runs[1]["tau_err"] = 5.0          # both quote one: the quoted errors combined
    assert math.isclose(p.mean(tau)[1], math.sqrt(50.0) / 2)
