"""collapse.py: the exponent of a data collapse (the paper's kappa, fig. dist-collapse)."""
import math

import numpy as np

from dynhet import collapse


def curves(kappa, n_stars, rel, rng):
    """P(N_c) = N_c^-kappa exp(-N_c/N*) on log-spaced sizes, each bin drawn
    with a relative error rel (1 + N_c/N*) (the tail is noisier, as in runs)."""
    n = np.unique(np.round(np.geomspace(1, 2e4, 25)))
    out = []
    for ns in n_stars:
        p = n ** -kappa * np.exp(-n / ns)
        sp = rel * p * (1 + n / ns)
        keep = n < 8 * ns
        out.append((n[keep] / ns, n[keep], (p + rng.normal(0, 1, len(p)) * sp)[keep], sp[keep]))
    return out


def test_recovers_the_exponent_and_its_error_matches_the_spread_of_realisations():
    rng = np.random.default_rng(11)
    stars = [30, 80, 200, 500, 1200]
    f = collapse.exponent(curves(1.8, stars, 0.05, rng), resamples=40)
    assert f.ok and np.isfinite(f.err["kappa"])
    # the curves collapse within their errors at the true exponent: quality about 1
    assert 0.5 < f.chi2_dof() < 1.5
    assert abs(f.p["kappa"] - 1.8) < 3 * f.err["kappa"]
    # the bootstrap error is a claim: the spread of independent realisations
    vals = [collapse.exponent(curves(1.8, stars, 0.05, rng)).p["kappa"] for _ in range(30)]
    spread = float(np.std(vals, ddof=1))
    assert 0.6 < f.err["kappa"] / spread < 1.6, (f.err["kappa"], spread)
    assert abs(np.mean(vals) - 1.8) < 3 * spread / math.sqrt(len(vals))


def test_another_exponent_and_no_collapse_said():
    rng = np.random.default_rng(3)
    f = collapse.exponent(curves(2.2, [50, 300, 2000], 0.03, rng))
    assert abs(f.p["kappa"] - 2.2) < 0.05
    # curves whose x ranges never overlap cannot be collapsed
    one = collapse.exponent(curves(1.8, [100], 0.05, rng))
    assert not one.ok and "no collapse" in one.note
    apart = [(np.array([1.0, 2.0]), np.array([1.0, 2.0]), np.array([1.0, 0.5]), np.array([0.1, 0.1])),
             (np.array([10.0, 20.0]), np.array([5.0, 10.0]), np.array([0.1, 0.05]), np.array([0.01, 0.01]))]
    assert not collapse.exponent(apart).ok


def test_scaling_violated_shows_in_the_quality():
    # one curve with another exponent: the collapse is poor (quality well above 1)
    rng = np.random.default_rng(5)
    good = curves(1.8, [30, 200, 1200], 0.03, rng)
    bad = curves(1.4, [80], 0.03, rng)
    assert collapse.exponent(good + bad).chi2_dof() > 3
