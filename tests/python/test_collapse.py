"""collapse.py: the exponent of a data collapse (the paper's kappa, fig. dist-collapse)."""

import numpy as np

from dynhet import collapse

SIZES = np.unique(np.round(np.geomspace(1, 3e4, 30)))
WIDTHS = np.gradient(SIZES)


def curves(kappa, cutoffs, rel, rng):
    """Histograms P(N_c) = N_c^-kappa exp(-N_c/c) on log-spaced sizes, each
    bin drawn with a relative error rel (1 + N_c/c) (the tail is noisier,
    as in runs)."""
    out = []
    for c in cutoffs:
        p = SIZES ** -kappa * np.exp(-SIZES / c)
        sp = rel * p * (1 + SIZES / c)
        keep = SIZES < 8 * c
        out.append((SIZES[keep], WIDTHS[keep], (p + rng.normal(0, 1, len(p)) * sp)[keep], sp[keep]))
    return out


def test_quality_is_the_parabola_it_minimises():
    rng = np.random.default_rng(2)
    pc = collapse.prepare(curves(1.8, [40, 300, 2000], 0.05, rng), 1.0)
    k, q, cnt = collapse.best(pc)
    ks = np.linspace(1.0, 2.6, 161)
    qs = [collapse.quality(pc, x)[0] for x in ks]
    assert abs(ks[int(np.argmin(qs))] - k) <= 0.01 and abs(min(qs) - q) < 0.01 * q + 1e-3


def test_recovers_the_exponent_and_its_error_matches_the_spread_of_realisations():
    rng = np.random.default_rng(11)
    cut = [60, 200, 700, 2500]
    f = collapse.exponent(curves(1.8, cut, 0.05, rng), resamples=100)
    assert f.ok and np.isfinite(f.err["kappa"])
    assert 0.4 < f.quality < 1.5  # the curves collapse within their errors
    # the bootstrap error is a claim: the spread of independent realisations
    vals = [collapse.exponent(curves(1.8, cut, 0.05, rng)).p["kappa"] for _ in range(40)]
    spread = float(np.std(vals, ddof=1))
    assert 0.6 < f.err["kappa"] / spread < 1.6, (f.err["kappa"], spread)
    # N* = <N_c^2>/<N_c> is not exactly proportional to the cutoff (κ < 2):
    # the exponent is still found to within a few of its errors
    assert abs(np.mean(vals) - 1.8) < 3 * spread, (np.mean(vals), spread)
    # and with noisy tails (30% errors) the bootstrap keeps up: N* redrawn too
    g = collapse.exponent(curves(1.8, cut, 0.3, rng), resamples=100)
    vals = [collapse.exponent(curves(1.8, cut, 0.3, rng)).p["kappa"] for _ in range(40)]
    assert 0.6 < g.err["kappa"] / np.std(vals, ddof=1) < 1.6


def test_no_collapse_said():
    rng = np.random.default_rng(3)
    one = collapse.exponent(curves(1.8, [100], 0.05, rng))
    assert not one.ok and "no collapse" in one.note
    n = np.array([1.0, 2.0, 3.0])
    w = np.ones(3)
    apart = [(n, w, np.array([1.0, 0.5, 0.3]), np.full(3, 0.01)),
             (n * 1000, w, np.array([0.1, 0.05, 0.03]), np.full(3, 0.001))]
    assert not collapse.exponent(apart).ok


def test_scaling_violated_shows_in_the_quality():
    rng = np.random.default_rng(5)
    good = curves(1.8, [60, 400, 2500], 0.03, rng)
    bad = curves(1.3, [150], 0.03, rng)
    assert collapse.exponent(good).quality < 1.5
    assert collapse.exponent(good + bad).quality > 3
