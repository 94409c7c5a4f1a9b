"""The kappa collapse rows on Points (clusters.collapse_fit, size.kappa_n_results):
runs without clusters or with other bins are left out, not fatal; exact
scaling histograms give back their exponent at every N."""
import math

import numpy as np

from dynhet.analysis.clusters import collapse_curves, collapse_fit
from dynhet.analysis.points import Point
from dynhet.analysis.size import kappa_n_results
from dynhet.analysis.study import Analysis

SIZES = np.unique(np.round(np.geomspace(1, 3e4, 30)))
WIDTHS = np.gradient(SIZES)
CUTOFF = {0.76: 60.0, 0.78: 200.0, 0.79: 700.0, 0.80: 2500.0}


def run(phi, seed, rng, sizes=SIZES):
    c = CUTOFF[phi]
    p = sizes ** -1.8 * np.exp(-sizes / c)
    sp = 0.04 * p * (1 + sizes / c)
    return {"seed": seed, "cut": {0.6: {"cl_size": sizes, "cl_width": np.gradient(sizes), "cl_p_slow_err": sp,
                                         "cl_p_slow": p + rng.normal(0, 1, len(p)) * sp, "tau_alpha": 1.0}}}


def analysis(tmp_path, ns=(4096, 16384)):
    rng = np.random.default_rng(7)
    A = Analysis.__new__(Analysis)
    A.points, A.extra, A.cpu, A.fits, A.rows = {}, {}, {}, {}, []
    A.dir, A.figdir = str(tmp_path), str(tmp_path / "figures")
    for n in ns:
        for phi in CUTOFF:
            p = Point(("neighbours", 0.9, phi, n))
            p.runs = [run(phi, s, rng) for s in (1, 2, 3)]
            (A.points if n == ns[0] else A.extra)[(p.pairs, p.eps, p.phi, p.N) if n == ns[0] else
                                                  ("big", p.pairs, p.eps, p.phi, p.N)] = p
            if n != ns[0]:
                p.study = "big"
    return A


def test_runs_without_clusters_or_with_other_bins_are_left_out(tmp_path):
    A = analysis(tmp_path, ns=(4096,))
    pts = sorted(A.points.values(), key=lambda p: p.phi)
    del pts[0].runs[0]["cut"][0.6]["cl_size"]                           # no clusters at this cutoff
    pts[1].runs[2] = run(0.78, 3, np.random.default_rng(1), SIZES[:-3])  # other bins than its point's first run
    cv = collapse_curves(pts)
    assert len(cv) == 4 and all(len(c[0]) == len(SIZES) for c in cv)
    f, err, _ = collapse_fit(A, pts, "k")
    assert f.ok and abs(f.p["kappa"] - 1.8) < 3 * err, (f.p["kappa"], err)
    assert "k" in A.fits and A.fits["k"].quoted["kappa"] == err


def test_kappa_against_n_finds_no_change_where_there_is_none(tmp_path):
    A = analysis(tmp_path)
    kappa_n_results(A)
    row = A.rows[-1]
    assert row["item"].startswith("κ by the collapse against N")
    assert "N 4096" in row["ours"] and "N 16384" in row["ours"]
    assert row["verdict"].startswith("converged from N = 4096 on"), row


def test_kappa_against_n_sees_a_change(tmp_path):
    A = analysis(tmp_path)
    rng = np.random.default_rng(9)
    for p in A.extra.values():           # the larger box with another exponent
        for r in p.runs:
            c = r["cut"][0.6]
            p_ = SIZES ** -2.1 * np.exp(-SIZES / CUTOFF[p.phi])
            c["cl_p_slow"] = p_ + rng.normal(0, 1, len(p_)) * 0.04 * p_ * (1 + SIZES / CUTOFF[p.phi])
            c["cl_p_slow_err"] = 0.04 * p_ * (1 + SIZES / CUTOFF[p.phi])
    kappa_n_results(A)
    assert A.rows[-1]["verdict"].startswith("drifting: "), A.rows[-1]


def test_a_one_seed_point_stays_in_every_jackknife_replicate_of_the_collapse(tmp_path):
    # scale's N = 262144 points have one seed: leaving "seed 1" out dropped
    # the point, and the replicate was a collapse over the other densities
    A = analysis(tmp_path, ns=(4096,))
    pts = sorted(A.points.values(), key=lambda p: p.phi)
    pts[3].runs = pts[3].runs[:1]                                 # one seed
    assert len(collapse_curves(pts, drop=1)) == 4 == len(collapse_curves(pts))
    assert len(collapse_curves(pts, drop=2)) == 4


def test_a_jackknife_replicate_of_the_collapse_leaves_a_seed_out_never_swaps_one_in(tmp_path):
    # a point whose two runs have other bins takes its first run's (the bins must match); leaving
    # that seed out once swapped the other run in, where the point has one usable seed
    A = analysis(tmp_path, ns=(4096,))
    pts = sorted(A.points.values(), key=lambda p: p.phi)
    pts[0].runs = [pts[0].runs[0], run(0.76, 2, np.random.default_rng(3), SIZES[:-3])]
    full = collapse_curves(pts)[0]
    left = collapse_curves(pts, drop=1)[0]
    assert len(full[0]) == len(SIZES) and np.array_equal(full[2], left[2])


def test_kappa_against_n_fits_one_window_of_cluster_sizes_at_every_n(tmp_path):
    # each run's own N* grows with the box where the box cuts clusters off; the finite-size
    # row fits 3 <= N_c <= the density's smallest N* at every N (size_rows.kappa_windows)
    from dynhet.analysis.quantities import kappa_of, n_star
    from dynhet.analysis.size_rows import kappa_common, kappa_windows
    A = analysis(tmp_path)
    multi = {}
    for p in list(A.points.values()) + list(A.extra.values()):
        for r in p.runs:
            r["packing_fraction"] = p.phi
        multi.setdefault(p.phi, {})[p.N] = p
    small = multi[0.78][4096].runs[0]
    for r in multi[0.78][16384].runs:           # the larger box: clusters cut off later
        c = r["cut"][0.6]
        c["cl_p_slow"] = SIZES ** -1.8 * np.exp(-SIZES / 2000.0)
    kw = kappa_windows(multi)
    lo = min(n_star(r)[0] for p in multi[0.78].values() for r in p.runs)
    assert math.isclose(kw[(0.78, False)], lo) and lo < n_star(multi[0.78][16384].runs[0])[0] / 3
    big = multi[0.78][16384].runs[0]
    assert kappa_common(kw)(big) == kappa_of(big, hi=lo) != kappa_of(big)
    assert kappa_common(kw)(small) == kappa_of(small, hi=lo)


def test_the_cage_relative_kappa_window_comes_from_the_cage_relative_points_and_ignores_a_run_that_fits_nothing(
        tmp_path):
    from dynhet.analysis.quantities import n_star
    from dynhet.analysis.size_rows import kappa_common, kappa_windows
    A = analysis(tmp_path)
    multi, multi_cr = {}, {}
    for p in list(A.points.values()) + list(A.extra.values()):
        for r in p.runs:
            r["packing_fraction"] = p.phi
        multi.setdefault(p.phi, {})[p.N] = p
    # the cage-relative rows' points (another study's) carry cut_cr; the table's do not
    import copy
    for phi, d in multi.items():
        for n, p in d.items():
            q = copy.deepcopy(p)
            for r in q.runs:
                r["cut_cr"] = r["cut"]
            multi_cr.setdefault(phi, {})[n] = q
    kw = kappa_windows(multi, multi_cr)
    assert (0.78, True) in kw and (0.78, True) not in kappa_windows(multi)
    r = multi_cr[0.78][4096].runs[0]
    assert np.isfinite(kappa_common(kw)(r, cr=True)[0])
    # a run whose slow clusters stop at N_c = 4 (N* about 2) does not narrow the density's window
    tiny = multi[0.78][4096].runs[1]["cut"][0.6]
    tiny["cl_p_slow"] = np.where(SIZES <= 4, SIZES ** -1.8, np.nan)
    assert n_star(multi[0.78][4096].runs[1])[0] < 3
    assert kappa_windows(multi)[(0.78, False)] > 10
