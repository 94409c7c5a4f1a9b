"""dynhet.fits on exact data (each form recovers its parameters to
rounding) and on the cases where a fit must refuse or decline to judge.
The statistical checks (errors that match the spread of synthetic studies)
are tests/test_study_fits.py (ctest study_fits_synthetic)."""
import math

import numpy as np

from dynhet import fits as sf

PHI = np.array([0.60, 0.65, 0.70, 0.72, 0.74, 0.76, 0.77, 0.78])


def test_exact_forms_are_recovered():
    x = np.geomspace(1, 50, 8)
    f = sf.power(x, 0.3 * x ** -1.47, 0.01 * x ** -1.47)
    assert abs(f.p["s"] + 1.47) < 1e-10 and abs(f.p["A"] - 0.3) < 1e-10 and f.chi2 < 1e-16
    y = 0.05 * (0.82 - PHI) ** -2.4
    f = sf.critical(PHI, y, 0.01 * y)
    assert abs(f.p["xc"] - 0.82) < 1e-5 and abs(f.p["g"] - 2.4) < 1e-3
    f = sf.critical_fixed(PHI, y, 0.01 * y, 0.82)
    assert abs(f.p["g"] - 2.4) < 1e-10 and f.err["xc"] == 0.0 and f.dof == len(PHI) - 2


def test_odr_with_exact_data_and_x_errors_is_the_line():
    x = np.geomspace(2, 20, 7)
    y = 0.5 * x ** 1.6
    f = sf.power(x, y, 0.03 * y, sx=0.2 * x)
    assert "orthogonal distance" in f.note and abs(f.p["s"] - 1.6) < 1e-8


def test_refusals_say_why():
    f = sf.power([1, 2], [1, 2], [0.1, 0.1])
    assert not f.ok and "needs 3" in f.note
    f = sf.critical_fixed(PHI, np.ones_like(PHI), 0.1 * np.ones_like(PHI), math.nan)
    assert not f.ok and "no phi_c" in f.note
    f = sf.critical_fixed(PHI, np.ones_like(PHI), 0.1 * np.ones_like(PHI), 0.69)
    assert not f.ok and "below xc" in f.note                      # 2 points below 0.69 only


def test_points_at_too_few_distinct_x_are_refused_not_a_crash():
    """Seeds of one size, or one density, stacked: a line through one x has
    no slope (its normal equations are singular), three parameters need
    three distinct x."""
    y, sy = [1.0, 1.1, 0.9, 2.0], [0.1] * 4
    f = sf.power([2, 2, 2], y[:3], sy[:3])
    assert not f.ok and "1 distinct x" in f.note
    f = sf.critical_fixed([0.7] * 3, y[:3], sy[:3], 0.8)
    assert not f.ok and "1 distinct x" in f.note
    f = sf.critical([0.7, 0.7, 0.7, 0.71], y, sy)
    assert not f.ok and "2 distinct x" in f.note
    f = sf.vft([0.7, 0.7, 0.7, 0.71], y, sy)
    assert not f.ok and "2 distinct x" in f.note
    f = sf.critical_joint({"tau": ([0.7] * 3, y[:3], sy[:3]), "chi4": (PHI, PHI, 0.1 * PHI)})
    assert not f.ok and f.note.startswith("tau: ")
    f = sf.power([2, 2, 3], y[:3], sy[:3])                          # two distinct x: a line
    assert f.ok and f.dof == 1


def test_data_beyond_the_forms_reach_is_refused_not_a_crash():
    # three sizes close together with a steep fall: ln A beyond a float's range
    f = sf.power([570000, 590000, 610000], [100, 8, 0.1], [10, 0.8, 0.01])
    assert not f.ok and "beyond the floats' range" in f.note
    # every x at or above the end of the scan for the singular point (x = N, not phi)
    f = sf.critical([5e5, 6e5, 6e5, 7e5], [1.4, 1.0, 0.6, 0.01], [0.1, 0.1, 0.1, 0.001])
    assert not f.ok and "below the scan's end" in f.note
    f = sf.critical_joint({"tau": ([7e5, 5.8e5, 7.6e5], [0.09, 5.9, 3.9], [0.01, 0.6, 0.4])})
    assert not f.ok and "below the scan's end" in f.note
    # a divergence steeper than the refinement's bounds (g = 60 > 50): the scan's line starts
    # outside them; the refinement starts inside and, ending at the bound, says so
    y = 0.05 * (0.82 - PHI) ** -60.0
    for f in (sf.critical(PHI, y, 0.01 * y), sf.critical_joint({"tau": (PHI, y, 0.01 * y)})):
        assert not f.ok and "at the refinement's bound" in f.note
    # each series at 2 distinct x: a line through each fits any xc
    f = sf.critical_joint({"a": ([0.7, 0.7, 0.75], [1.0, 1.1, 2.0], [0.1] * 3),
                           "b": ([0.7, 0.76, 0.76], [1.0, 2.0, 2.1], [0.1] * 3)})
    assert not f.ok and "no series has 3 distinct x" in f.note
    # weights (y / sy)^2 beyond the floats' range (errors in the subnormals)
    y, x = np.array([3.5e-152, 5.3e-150, 3.2e-151, 9.6e-152, 3.6e-150]), [0.62, 0.72, 0.63, 0.67, 0.51]
    for f in (sf.power(x, y, np.full(5, 1e-310)), sf.critical(x, y, np.full(5, 1e-310)),
              sf.critical_fixed(x, y, np.full(5, 1e-310), 0.8)):
        assert not f.ok and "beyond the floats' range" in f.note


def test_cannot_judge_an_edge_or_an_improbable_chi2():
    y = 0.05 * (0.7804 - PHI) ** -1.0
    edge = sf.critical(PHI, y, 0.01 * y)
    assert "edge of the data" in (sf.cannot_judge(edge, "xc") or "")
    y = 0.05 * (0.82 - PHI) ** -2.4
    good = sf.critical(PHI, y * (1 + 0.005 * np.sin(7 * np.arange(len(PHI)))), 0.01 * y)
    assert sf.cannot_judge(good, "xc") is None
    bad = sf.critical(PHI, y * np.exp(0.3 * np.sin(40 * PHI)), 0.01 * y)
    assert "does not describe the points" in (sf.cannot_judge(bad, "xc") or "")


def test_jackknife_over_identical_seeds_has_no_spread():
    x = np.geomspace(1, 50, 8)
    f = sf.jackknife_over_seeds(lambda drop: sf.power(x, 2 * x, 0.1 * x), [1, 2, 3])
    assert f.jk["s"] < 1e-12 and f.jk["A"] < 1e-12  # zero but for rounding


def test_a_jackknife_over_two_seeds_is_not_taken_alone():
    # Two seeds whose fits agree by chance: one dof says nothing about the
    # error, so the fit's own error stands (three seeds too: two dof); with
    # four the jackknife does.
    x = np.geomspace(1, 50, 8)
    rng = np.random.default_rng(7)
    y = 2 * x * np.exp(rng.normal(0, 0.1, len(x)))
    two = sf.jackknife_over_seeds(lambda drop: sf.power(x, y, 0.1 * y), [1, 2])
    assert two.jk["s"] < 1e-12 and two.jk_seeds == 2
    assert two.error("s") >= two.err["s"] > 0.01
    three = sf.jackknife_over_seeds(lambda drop: sf.power(x, y, 0.1 * y), [1, 2, 3])
    assert three.jk_seeds == 3 and three.error("s") >= three.err["s"]
    four = sf.jackknife_over_seeds(lambda drop: sf.power(x, y, 0.1 * y), [1, 2, 3, 4])
    assert four.jk_seeds == 4 and four.error("s") < 1e-12  # chi2/dof below 1 here: no Birge inflation
    assert four.chi2_dof() < 1


def test_a_seed_jackknife_keeps_the_points_of_one_seed_in_every_replicate():
    # The largest-N table mixes points of 4 seeds with points of one (scale's
    # N = 262144): leaving "seed 1" out of a one-seed point dropped the point,
    # and the replicates were fits over other densities. It stays; the
    # jackknife then misses its noise, so the fit's own error is a floor.
    from dynhet.analysis.points import Point, fit_series
    rng = np.random.default_rng(11)
    pts = []
    for k, x in enumerate(np.geomspace(1, 50, 6)):
        p = Point(("neighbours", 0.9, 0.70 + 0.01 * k, 4096))
        for seed in ((1,) if k >= 4 else (1, 2, 3, 4)):
            v = 2 * x ** 1.5 * np.exp(rng.normal(0, 0.05))
            p.runs.append({"seed": seed, "x": x, "y": v, "y_err": 0.05 * v})
        pts.append(p)
    assert pts[5].mean(lambda r: (r["y"], r["y_err"]), drop=1)[3] == 1   # one seed: kept
    assert pts[0].mean(lambda r: (r["y"], r["y_err"]), drop=1)[3] == 3   # four: seed 1 left out
    sizes = []
    f = fit_series(pts, lambda r: (r["y"], r["y_err"]), lambda x, y, e: (sizes.append(len(x)), sf.power(x, y, e))[1],
                   xpoint=lambda p: p.runs[0]["x"])
    assert sizes == [6] * 5                # the fit and each of the 4 replicates: every point
    assert f.jk_seeds == 4 and f.jk_partial
    assert f.error("s") >= f.err["s"] and abs(f.p["s"] - 1.5) < 4 * f.error("s")


def test_a_jackknife_replicate_that_fails_is_said():
    x = np.geomspace(1, 50, 8)
    y = 2 * x

    def one(drop):
        return sf.power(x, y if drop != 3 else np.full_like(y, np.nan), 0.1 * y)
    f = sf.jackknife_over_seeds(one, [1, 2, 3, 4])
    assert math.isnan(f.jk["s"]) and "the fit without seed 3 failed" in f.note
    assert f.error("s") == f.err["s"]


def test_no_verdict_from_a_fit_whose_error_exceeds_its_value():
    from dynhet.analysis.verdicts import fit_verdict
    rng = np.random.default_rng(3)
    x = np.geomspace(2, 2.1, 6)                                # a narrow range: the slope undetermined
    y = 0.5 * x ** 1.6 * (1 + 0.1 * rng.standard_normal(6))
    f = sf.power(x, y, 0.1 * 0.5 * x ** 1.6)
    assert f.error("s") > abs(f.p["s"])
    assert fit_verdict(f, "s", 1.6) == "not judged: its error exceeds its value (the points do not determine it)"
    x = np.geomspace(2, 20, 6)
    y = 0.5 * x ** 1.6 * (1 + 0.01 * rng.standard_normal(6))
    f = sf.power(x, y, 0.01 * y)
    assert fit_verdict(f, "s", 1.6).startswith("agrees")
    # determined (error below its value) but with an error above the paper's number: within 2 errors
    # of the paper is then also within 2 of 0, and "agrees" would say nothing
    rng = np.random.default_rng(3)
    x = np.geomspace(2, 3.0, 6)
    y = 0.5 * x ** -2.0 * (1 + 0.2 * rng.standard_normal(6))
    f = sf.power(x, y, 0.2 * y)
    v, e = f.p["s"], f.error("s")
    near = v + 1.5 * e                                  # 1.5 errors away, and within one error of 0
    assert abs(v) > e > abs(near) > 0, (v, e)
    assert fit_verdict(f, "s", near) == ("not judged: its error exceeds the paper's value (the comparison could "
                                         "not tell it from 0)")
    assert fit_verdict(f, "s", 0.0).startswith(("agrees", "differs"))   # a paper's 0: judged as before
    far = v + 2.5 * e                                   # beyond 2 such errors it still differs
    assert abs(far) < e and fit_verdict(f, "s", far) == "differs (2.5 σ)"


def test_a_value_falls_with_eps_only_where_the_fall_exceeds_its_errors():
    from dynhet.analysis.restitution import falls_verdict
    assert falls_verdict([(0.7, 0.810, 0.002), (0.9, 0.800, 0.002), (1.0, 0.782, 0.003)]).startswith("agrees")
    # the same order, errors as large as the fall: no agreement claimed
    assert falls_verdict([(0.7, 0.810, 0.02), (0.9, 0.800, 0.02), (1.0, 0.782, 0.02)]).startswith("not resolved")
    assert falls_verdict([(0.7, 0.780, 0.002), (0.9, 0.800, 0.002)]).startswith("differs (ε 0.7 → 0.9 rises")
    assert falls_verdict([(0.7, 0.80, math.nan), (1.0, 0.78, math.nan)]).startswith("not resolved")


def test_a_derived_quantity_of_a_parameter_outside_the_covariance_claims_no_propagated_error():
    f = sf.Fit("critical_joint", ["xc", "g_a", "g_b", "A_a"])
    f.p = {"xc": 0.8, "g_a": 2.0, "g_b": 1.0, "A_a": 3.0}
    f.err = {"xc": 0.01, "g_a": 0.1, "g_b": 0.05, "A_a": 0.3}
    f.cov, f.cov_names = np.array([[1e-4, 0, 0], [0, 0.01, 0.004], [0, 0.004, 0.0025]]), ["xc", "g_a", "g_b"]
    f.chi2, f.dof = 1.0, 5
    v, e = f.derived(lambda q: q["g_a"] / q["g_b"])
    # r = a/b: var = r^2 (var_a/a^2 + var_b/b^2 - 2 cov_ab/(a b)) = 4 (0.0025 + 0.0025 - 0.004) = 0.004
    assert v == 2.0 and math.isclose(e, math.sqrt(0.004), rel_tol=1e-5)
    assert math.isnan(f.derived(lambda q: q["A_a"] * q["g_a"])[1])
