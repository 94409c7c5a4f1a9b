"""dynhet.analysis.quantities: per-run values at tau_alpha carry the error
the run quotes at that lag (interpolated like the value), not the
interpolation's own error."""
import math

import numpy as np

from dynhet.analysis.quantities import chi4_at_tau


def run_with_chi4(err):
    lags = np.geomspace(0.1, 100.0, 25)
    chi4 = 3.0 + np.log(lags)                     # a line in ln t: no interpolation error
    grid_n = np.array([64.0, 256.0, 1024.0])      # sub-box particles; the proper sub-box is 256 (not the whole box)
    c = {"tau_alpha": 7.3, "tau_alpha_err": 0.1, "chi4_lag": lags, "chi4_N": grid_n,
         "chi4": np.tile(chi4, (3, 1)), "chi4_err": np.tile(err(lags), (3, 1))}
    return {"N": 1024, "cut": {0.6: c}}


def test_chi4_at_tau_alpha_takes_the_error_at_that_lag():
    v, e = chi4_at_tau(run_with_chi4(lambda t: np.full_like(t, 0.5)))
    assert math.isclose(v, 3.0 + math.log(7.3)) and math.isclose(e, 0.5)
    # an error growing as a line in ln t: its value at tau_alpha
    v, e = chi4_at_tau(run_with_chi4(lambda t: 0.1 + 0.05 * np.log(t)))
    assert math.isclose(e, 0.1 + 0.05 * math.log(7.3), rel_tol=1e-9)


def test_the_median_of_ratios_carries_the_error_its_values_give_it():
    from dynhet.analysis.appendix import median_error, ratios
    r, e = ratios([(2.0, 0.2), (3.0, 0.3), (math.nan, 0.1)], [(2.0, 0.0), (2.0, 0.0), (1.0, 0.1)])
    assert np.allclose(r, [1.0, 1.5]) and np.allclose(e, [0.1, 0.15])
    # one value: its median is itself, its error its own
    m, s = median_error([1.3], [0.1], draws=20000)
    assert m == 1.3 and abs(s - 0.1) < 0.003
    # 41 equal values of equal error: the median of 41 normal draws, whose
    # standard deviation is sqrt(pi/2) sigma / sqrt(n) to within a few per cent at this n
    m, s = median_error(np.ones(41), np.full(41, 0.2), draws=20000)
    assert m == 1.0 and abs(s / (math.sqrt(math.pi / 2) * 0.2 / math.sqrt(41)) - 1) < 0.06
    assert math.isnan(median_error([1.0, 2.0], [0.1, math.nan])[1])   # one without an error: no error claimed


def test_near_one_claims_a_difference_only_beyond_the_tolerance_and_the_errors():
    from dynhet.analysis.appendix import near_one
    assert near_one(1.10, 0.01) == "agrees"                 # within the paper's "≈"
    assert near_one(1.32, 0.24) == "agrees"                 # 0.32 off, but 1.3 errors: not told apart
    assert near_one(1.32, 0.10) == "differs (3.2 σ)"
    assert near_one(1.32, math.nan) == "differs"


def test_one_seeds_ageing_slope_error_matches_the_spread_of_independent_runs():
    """tau_alpha(t0) of one run: its slope's error from the scatter about the
    line is what 2000 independent realisations of the same line scatter by;
    none where origins lie closer than tau_alpha (correlated) or too few."""
    from dynhet.fits import slope_with_error
    rng = np.random.default_rng(7)
    x = 68.0 + 6.8 * np.arange(8)                 # 8 origins 6.8 tau_alpha apart (the scale study at phi 0.78)
    fits = [slope_with_error(x, 1.0 - 0.001 * x + rng.normal(0, 0.01, 8)) for _ in range(2000)]
    b, e = np.array([f[0] for f in fits]), np.array([f[1] for f in fits])
    assert all(f[2] == 8 for f in fits)
    assert abs(b.mean() + 0.001) < 3 * b.std() / math.sqrt(len(b))
    assert abs(np.sqrt((e ** 2).mean()) / b.std() - 1) < 0.06     # 2000 draws: the ratio to within ~3%
    assert math.isnan(slope_with_error(x[:3], x[:3])[1])
    assert math.isnan(slope_with_error(np.arange(8) * 0.5, np.ones(8))[1])


def test_the_cutoff_studys_d_f_prime_fits_over_the_same_xi_range_as_every_other():
    """Row 14 of the earlier table (d_f' at a = 0.6 from the cutoff study,
    0.64 'differs') was a fit over every xi; the main series fits over xi >= 3.
    Points with chi4 = xi^1.6 above xi = 3 and a flatter branch below it: the
    fit over xi >= 3 finds 1.6, one over every xi would not."""
    from dynhet.analysis.cutoff import df_fit
    from dynhet.analysis.points import Point
    pts = []
    for k, xi in enumerate((1.0, 1.5, 2.0, 3.5, 5.0, 7.0, 10.0)):
        p = Point(("neighbours", 0.9, 0.70 + 0.01 * k, 4096))
        chi4 = xi ** 1.6 if xi >= 3 else 3.0 ** 1.6 * (xi / 3.0) ** 0.3
        p.runs = [{"seed": s, "xi": xi * (1 + 0.001 * (s - 2)), "chi4": chi4 * (1 + 0.002 * (s - 2))} for s in (1, 2, 3)]
        pts.append(p)
    f = df_fit(pts, lambda r: (r["chi4"], 0.02 * r["chi4"]), lambda r: (r["xi"], 0.01 * r["xi"]))
    assert f.ok and f.n == 4 and abs(f.p["s"] - 1.6) < 0.02


def test_chi4_at_tau_alpha_takes_one_sub_box_size_at_every_n():
    # With --largest-n a series mixes N = 4096 with 65536 and 262144: the
    # largest grid below the whole box would be 455 particles at one density
    # and 29127 at another. chi4(tau_alpha) takes the grid of about 4096 / 9.
    from dynhet.analysis.quantities import proper_subbox
    sizes = {4096: [28.4, 113.8, 455.1, 4096.0],
             65536: [28.4, 113.8, 455.1, 1820.4, 7281.8, 65536.0],
             262144: [28.4, 113.8, 455.1, 1820.4, 7281.8, 29127.1, 262144.0]}
    for n, ns in sizes.items():
        assert math.isclose(ns[proper_subbox({"chi4_N": np.array(ns)}, n)], 455.1)
    # a box too small for it: its largest proper grid; one grid only: that one
    assert proper_subbox({"chi4_N": np.array([28.4, 113.8, 1024.0])}, 1024) == 1
    assert proper_subbox({"chi4_N": np.array([1024.0])}, 1024) == 0
    # sub-boxes far from 455 (a study that asked for others): the largest below the box
    assert proper_subbox({"chi4_N": np.array([64.0, 1600.0, 65536.0])}, 65536) == 1


def test_kappa_of_a_run_carries_the_scatter_of_its_bins():
    # bins that scatter 3 times their errors about the power law: kappa's
    # error is the fit's times sqrt(chi2/dof), not the covariance's alone
    from dynhet import fits as sf
    from dynhet.analysis.quantities import kappa_of
    rng = np.random.default_rng(4)
    n = np.geomspace(1, 3000, 25)
    p = n ** -1.8 * np.exp(-n / 1000.0)
    pe = 0.02 * p
    noisy = p * (1 + 3 * 0.02 * rng.standard_normal(len(n)))
    r = {"cut": {0.6: {"cl_size": n, "cl_width": np.gradient(n), "cl_p_slow": noisy, "cl_p_slow_err": pe}}}
    k, e = kappa_of(r)
    from dynhet.analysis.quantities import n_star
    m = (n >= 3) & (n <= n_star(r)[0])
    f = sf.power(n[m], noisy[m], pe[m])
    assert f.chi2_dof() > 3 and math.isclose(e, f.err["s"] * math.sqrt(f.chi2_dof()))
