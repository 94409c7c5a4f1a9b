"""Whether a size was steady over its production (analysis.steady): the
change of tau_alpha(t0) against 0 with the dof of its error, and a size
that is not steady left out of every verdict."""
import math

import matplotlib
import numpy as np

matplotlib.use("Agg")

from dynhet.analysis.points import Point  # noqa: E402
from dynhet.analysis.study import Analysis  # noqa: E402

from dynhet.analysis.finite_size import write_finite_size  # noqa: E402


def test_an_unsteady_size_is_judged_nowhere():
    # the tau_alpha table and local_measures' tau_alpha against N leave it out alike
    from dynhet.analysis.finite_size import quantity_rows
    from dynhet.analysis.size_rows import tau_of
    t0 = 923.5 + 92.35 * np.arange(8)
    d = {}
    for n, fall in ((4096, 0.0), (262144, 0.05)):
        p = Point(("neighbours", 0.9, 0.78, n))
        for seed in (1, 2):
            alt = np.array([1, -1, 1, -1, -1, 1, -1, 1]) * 0.004 * seed
            line = 1.0 - fall * (t0 - t0[0]) / (t0[-1] - t0[0])
            p.runs.append({"seed": seed, "N": n, "cut": {0.6: {"t0": t0, "tau_t0": 13.6 * (line + alt),
                                                                "tau_alpha": 13.6 + (0.3 if n > 4096 else 0),
                                                                "tau_alpha_err": 0.1}}})
        d[n] = p
    _, _, (text, n0, _, _) = quantity_rows(d, tau_of, False)
    assert text.startswith("no verdict: 1 of the 2 sizes shown has every seed's value with an error and a steady")


def test_the_change_of_tau_alpha_over_the_production_is_measured_per_run():
    """A steady state has tau_alpha(t0) flat: at phi 0.78, N 262144, it fell
    from 14.0 to 13.3 over 8 origins while the cage-relative one held. A line
    falling 5% from the first origin to the last reads -5%; a flat one 0 within
    its error; its error is the slope's (the origins' scatter about the line)."""
    from dynhet.analysis.size_rows import production_change
    t0 = 923.5 + 92.35 * np.arange(8)
    tm = 13.6
    fall = 1.0 - 0.05 * (t0 - t0[0]) / (t0[-1] - t0[0])
    noise = np.array([1, -1, 1, -1, -1, 1, -1, 1]) * 0.002
    r = {"cut": {0.6: {"t0": t0, "tau_t0": tm * (fall + noise), "tau_alpha": tm}},
         "cut_cr": {0.6: {"t0": t0, "tau_t0": 85.0 * (1.0 + noise), "tau_alpha": 85.0}}}
    v, e = production_change(r)
    assert abs(v + 5.0) < 3 * e and 0 < e < 1.0
    v, e = production_change(r, cr=True)
    assert abs(v) < 3 * e
    # origins closer than tau_alpha^CR apart in units of the cage-relative tau_alpha: no error claimed
    r["cut_cr"][0.6]["tau_alpha"] = 200.0
    assert math.isnan(production_change(r, cr=True)[1])


def test_a_size_whose_tau_alpha_moves_over_its_production_is_not_steady(tmp_path):
    """The change of tau_alpha(t0) is judged against 0 at each N (not for
    convergence in N), and the reproduction's header names a largest N that
    is not steady."""
    from dynhet.analysis.output import still_drifting
    t0 = 923.5 + 92.35 * np.arange(8)
    alt = np.array([1, -1, 1, -1, -1, 1, -1, 1]) * 0.004
    d = {}
    for n, fall in ((4096, 0.0), (16384, 0.0), (262144, 0.05)):
        p = Point(("neighbours", 0.9, 0.78, n))
        for seed in (1, 2):
            line = 1.0 - fall * (t0 - t0[0]) / (t0[-1] - t0[0])
            p.runs.append({"seed": seed, "N": n,
                           "cut": {0.6: {"t0": t0, "tau_t0": 13.6 * (line + seed * alt), "tau_alpha": 13.6,
                                         "tau_alpha_err": 0.1}}})
        d[n] = p
    A = Analysis.__new__(Analysis)
    A.dir, A.figdir, A.also = str(tmp_path / "study"), str(tmp_path / "study" / "figures"), []
    A.points, A.extra, A.cpu, A.fits, A.rows = {}, {}, {}, {}, []
    for p in d.values():
        A.points[p.pairs, p.eps, p.phi, p.N] = p
    out = tmp_path / "finite_size.md"
    write_finite_size(A, str(out), "analyse_study.sh study")
    row = next(l for l in out.read_text().splitlines() if l.startswith("| τ_α(t0): change over the production"))
    assert "| not steady at N = 262144 (-5" in row and "0 within 3σ's probability at N = 4096, 16384 |" in row
    # its values are no steady state's: marked, and out of the verdict (which ends at 16384)
    row = next(l for l in out.read_text().splitlines() if l.startswith("| τ_α |"))
    cells = row.split(" | ")
    assert cells[3].endswith("‡") and not cells[1].endswith("‡") and not cells[2].endswith("‡")
    assert "converged from N = 4096 on (within 2σ of N = 16384" in row
    notes = still_drifting({0.78: d}, d, {}, 262144)
    assert len(notes) == 1 and notes[0].startswith("τ_α(t0) not steady over the production at N = 262144 (-5")
    assert still_drifting({0.78: d}, d, {}, 16384) == []
    # a size whose error cannot be given (origins closer than tau_alpha) is named, not counted as steady
    from dynhet.analysis.steady import steady_verdict
    nan = float("nan")
    text = steady_verdict([4096, 262144], [(0.5, 1.0, 1.0, 2), (1.0, nan, nan, 1)], [True, True])
    assert text == "steady: 0 within 3σ's probability at N = 4096; not judged (no error) at N = 262144"


def test_local_measures_leave_an_unsteady_size_out_of_their_verdict(tmp_path):
    # tau_alpha against N at 0.79: 262144's tau_alpha(t0) falls by 5 % over its production
    from dynhet.analysis.local_measures import local_n_results
    A = Analysis.__new__(Analysis)
    A.dir, A.figdir, A.also = str(tmp_path / "study"), str(tmp_path / "study" / "figures"), []
    A.points, A.extra, A.cpu, A.fits, A.rows = {}, {}, {}, {}, []
    t0 = 2700.0 + 270.0 * np.arange(8)
    for n, fall, tau in ((4096, 0.0, 27.0), (16384, 0.0, 27.1), (262144, 0.05, 31.0)):
        p = Point(("neighbours", 0.9, 0.79, n))
        for seed in (1, 2):
            alt = np.array([1, -1, 1, -1, -1, 1, -1, 1]) * 0.004 * seed
            line = 1.0 - fall * (t0 - t0[0]) / (t0[-1] - t0[0])
            p.runs.append({"seed": seed, "N": n, "cut": {0.6: {
                "tau_alpha": tau, "tau_alpha_err": 0.1, "tau_cr": 240.0, "tau_cr_err": 5.0,
                "t0": t0, "tau_t0": tau * (line + alt)}}})
        A.points[p.pairs, p.eps, p.phi, p.N] = p
    local_n_results(A)
    row = next(r for r in A.rows if r["item"] == "τ_α against N at φ = 0.79")
    assert "N 262144 not steady (out of the verdict)" in row["ours"]
    assert row["verdict"].startswith("converged from N = 4096 on (within 2σ of N = 16384")


def test_not_steady_takes_the_student_t_of_the_origins_scatter():
    # an error from 4 origins about a line has 2 dof: 3 of them are no 3 sigma (t = 19.2 is);
    # one run of 8 origins, 6 dof: 4.9; a known error: 3
    from dynhet.analysis.steady import change_dof, steady_limit, steady_off
    assert steady_limit(None) == 3.0
    assert abs(steady_limit(6) - 4.90) < 0.01 and abs(steady_limit(2) - 19.2) < 0.1 and abs(steady_limit(18) - 3.475) < 0.01
    m = (-5.0, 1.0, math.nan, 1)               # 5 errors from 0
    assert steady_off(m, True) and steady_off(m, True, 6) and not steady_off(m, True, 2)
    # the dof of the error the verdict uses: three runs of 7 origins a tau_alpha apart, equal
    # errors: 3 x 5; origins half a tau_alpha apart quote none, and the seeds' spread has 2
    def runs(spacing, scatter):
        out = []
        for s, amp in zip((1, 2, 3), scatter):
            t0 = 100.0 + spacing * 10.0 * np.arange(7)
            tt = 10.0 * (1 + amp * np.array([1, -1, 1, -1, -1, 1, -1]))
            out.append({"seed": s, "cut": {0.6: {"t0": t0, "tau_t0": tt, "tau_alpha": 10.0}}})
        return out
    p = Point(("neighbours", 0.9, 0.78, 4096))
    p.runs = runs(1.0, (0.01, 0.01, 0.01))
    assert math.isclose(change_dof(p, False), 15.0)
    p.runs = runs(1.0, (0.01, 0.01, 0.04))     # unequal errors: fewer than 15 (Welch-Satterthwaite)
    assert 5.0 < change_dof(p, False) < 15.0
    p.runs = runs(0.5, (0.01, 0.01, 0.01))
    assert change_dof(p, False) == 2
    assert change_dof(Point(("neighbours", 0.9, 0.78, 4096)), False) is None


def test_the_spread_of_two_seeds_is_no_check_of_steadiness():
    # where some run quotes no error, a size's error is its seeds' spread:
    # with two seeds one dof, and 3 sigma's probability would allow 236
    # errors, so -10.4 +- 2 (5 errors from 0) would pass as steady: not judged, said why
    from dynhet.analysis.steady import steady_limit, steady_off, steady_verdict
    assert abs(steady_limit(1) - 235.8) < 0.1
    m = (-10.4, 2.0, math.nan, 2)
    assert steady_off(m, True, 1) is None and steady_off(m, True, 2) is False
    text = steady_verdict([4096, 65536], [(-5.0, 4.0, math.nan, 2), m], [True, True], [6, 1])
    assert text == ("steady: 0 within 3σ's probability at N = 4096; "
                    "not judged (1 dof: 3σ's probability would allow 236 errors) at N = 65536")
    assert steady_verdict([65536], [m], [True], [1]) == (
        "no verdict: not judged (1 dof: 3σ's probability would allow 236 errors) at N = 65536")
