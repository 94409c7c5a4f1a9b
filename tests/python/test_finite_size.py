"""dynhet.analysis.finite_size: the verdicts computed from the numbers
(converged from which N on, or the drift per doubling of N), xi only with
enough q shells, and the report on synthetic points at three N."""
import math

import pytest

import matplotlib
import numpy as np

matplotlib.use("Agg")

from dynhet.analysis.finite_size import size_verdict, spread_ratio, write_finite_size  # noqa: E402
from dynhet.analysis.size_rows import MIN_SHELLS, chi4p_grid, xi_shells  # noqa: E402
from dynhet.analysis.points import Point  # noqa: E402
from dynhet.analysis.study import Analysis  # noqa: E402


def test_converged_from_the_first_n_that_agrees_with_every_larger_one():
    text, n0, _, _ = size_verdict([1024, 4096, 16384, 65536], [10.0, 12.0, 12.1, 12.05], [0.2, 0.2, 0.2, 0.2])
    assert n0 == 4096 and text.startswith("converged from N = 4096")
    # 1024 is 2.05 / 0.283 = 7 sigma off: not converged there
    text, n0, _, _ = size_verdict([1024, 4096], [12.0, 12.5], [0.2, 0.2])
    assert n0 == 1024   # 0.5 / 0.28 = 1.8 sigma: within 2


def test_a_gap_below_the_largest_n_breaks_convergence():
    # 4096 agrees with 65536, 16384 does not: converged only from ... nowhere
    text, n0, drift, err = size_verdict([4096, 16384, 65536], [12.0, 13.0, 12.0], [0.1, 0.1, 0.1])
    assert n0 is None and text.startswith("drifting")
    assert math.isclose(drift, -1.0 / 2) and math.isclose(err, math.hypot(0.1, 0.1) / 2)


def test_drift_per_doubling_between_the_two_largest_sizes():
    text, n0, drift, err = size_verdict([1024, 4096, 16384], [48.0, 42.0, 27.0], [4.0, 3.0, 1.0])
    assert n0 is None
    assert math.isclose(drift, (27.0 - 42.0) / 2) and math.isclose(err, math.hypot(3.0, 1.0) / 2)
    assert "per doubling of N" in text and "(-18%)" in text


def test_a_steady_drift_in_steps_within_the_errors_is_a_drift():
    # each of 27, 24 agrees with 21 ± 3 within 2 sigma, but the three fall by
    # 1.5 ± 0.58 per doubling (weighted line in log2 N), 2.6 sigma from flat;
    # nor do the last two alone converge while the three largest fall
    text, n0, _, _ = size_verdict([1024, 4096, 16384, 65536], [30.0, 27.0, 24.0, 21.0], [1.0, 1.0, 1.0, 3.0])
    assert n0 is None and text.startswith("drifting") and "over N = 4096 to 65536" in text
    from dynhet.analysis.size import flat_slope
    b, e = flat_slope([(4096, 27.0, 1.0), (16384, 24.0, 1.0), (65536, 21.0, 3.0)])
    assert math.isclose(b, -1.5, rel_tol=1e-9) and abs(e - 0.582) < 0.001
    # a clean -0.75 per doubling whose every step is within the errors
    text, n0, _, _ = size_verdict([4096, 16384, 65536, 262144], [24.0, 22.5, 21.0, 19.5], [0.5, 0.5, 0.5, 0.8])
    assert n0 is None and "-0.75 ± 0.22 per doubling, 3.3σ from flat" in text
    # flat within the errors: the line does not hold it back
    text, n0, _, _ = size_verdict([1024, 4096, 16384, 65536], [12.3, 11.9, 12.2, 12.0], [0.2] * 4)
    assert n0 == 1024
    # three sizes whose last step levels off: converged from the middle one
    from dynhet.analysis.size import levels_off
    assert levels_off([(1024, 200.0, 0.71), (4096, 250.0, 0.71), (16384, 251.0, 0.71)])
    assert not levels_off([(4096, 27.0, 1.0), (16384, 24.0, 1.0), (65536, 21.0, 3.0)])
    assert size_verdict([1024, 4096, 16384], [200.0, 250.0, 251.0], [0.71] * 3)[1] == 4096
    # the three largest flat, the smallest off: converged from the next one
    text, n0, _, _ = size_verdict([1024, 4096, 16384, 65536], [10.0, 12.1, 11.9, 12.0], [0.2] * 4)
    assert n0 == 4096 and "from flat" not in text


def test_one_or_no_size():
    assert size_verdict([1024], [1.0], [0.1])[0] == "one N only"
    assert size_verdict([1024, 4096], [math.nan, math.nan], [0.1, 0.1])[0] == "no data"


def s4_cut(xi, L):
    """A whole-box S4 group of a box of side L: shells at q = 2 pi k / L."""
    q = 2 * math.pi / L * np.arange(0, 40)
    return {"tau_alpha": 10.0, "s4_nshells": np.array([len(q)]), "s4_q": q, "s4_N": np.array([4096.0]),
            "s4_lag": np.array([1.0, 10.0, 100.0]), "xi_t": np.full((3, 1), xi),
            "s4_oz_xi": np.array([xi]), "s4_oz_xi_err": np.array([0.1 * xi])}


def test_xi_needs_five_shells_below_q_xi_1():
    L = 100.0
    # shells below q xi = 1: k <= L / (2 pi xi); xi = 2: 7 shells, xi = 4: 3 shells
    v, e, n = xi_shells({"cut": {0.6: s4_cut(2.0, L)}})
    assert n == 7 >= MIN_SHELLS and math.isclose(v, 2.0) and math.isclose(e, 0.2)
    v, e, n = xi_shells({"cut": {0.6: s4_cut(4.0, L)}})
    assert n == 3 and math.isnan(v)


def test_the_finite_size_xi_is_the_reproductions_xi():
    # One function (quantities.xi_of_cut) for both documents: beyond the
    # lags no xi (np.interp once took the last lag's), and the error is the
    # OZ fit's and the interpolation's in quadrature.
    from dynhet.analysis.quantities import xi_at_tau
    L = 100.0
    c = s4_cut(2.0, L)
    c["xi_t"] = np.array([[1.6], [2.0], [3.0]])
    run = {"N": 4096, "cut": {0.6: dict(c, tau_alpha=10.0, tau_alpha_err=0.1)}}
    v, e, n = xi_shells(run)
    assert (v, e) == xi_at_tau(run) and math.isclose(v, 2.0) and n == 7
    run["cut"][0.6]["tau_alpha"] = 31.6   # between 10 and 100: the parabola through 3 lags is the interpolation error
    v, e, n = xi_shells(run)
    assert (v, e) == xi_at_tau(run) and 2.0 < v < 3.0 and e > 0.1 * 2.0
    run["cut"][0.6]["tau_alpha"] = 150.0  # beyond the longest lag
    v, e, n = xi_shells(run)
    assert math.isnan(v) and n == 0 and math.isnan(xi_at_tau(run)[0])


def test_the_report_on_three_sizes(tmp_path):
    A = Analysis.__new__(Analysis)
    A.dir, A.figdir, A.also = str(tmp_path / "study"), str(tmp_path / "study" / "figures"), []
    A.points, A.extra, A.cpu, A.fits, A.rows = {}, {}, {}, {}, []
    for n, t, tcr in ((1024, 48.0, 200.0), (4096, 42.0, 250.0), (16384, 27.0, 251.0)):
        p = Point(("neighbours", 0.9, 0.79, n))
        for seed, d in ((1, -1.0), (2, 1.0)):
            p.runs.append({"seed": seed, "N": n,
                           "cut": {0.6: {"tau_alpha": t + d, "tau_alpha_err": 1.0}},
                           "cut_cr": {0.6: {"tau_alpha": tcr + d, "tau_alpha_err": 1.0}}})
        A.points[p.pairs, p.eps, p.phi, p.N] = p
    out = tmp_path / "docs" / "finite_size.md"
    out.parent.mkdir()
    assert write_finite_size(A, str(out), "analyse_study.sh study") == 1
    text = out.read_text()
    assert "## φ = 0.79" in text
    row = next(l for l in text.splitlines() if l.startswith("| τ_α |"))
    assert "48 ± 0.71" in row and "drifting: -7.5 ± 0.5 per doubling of N" in row
    row = next(l for l in text.splitlines() if l.startswith("| τ_α — cage-relative |"))
    assert "converged from N = 4096 on" in row
    assert (tmp_path / "docs" / "finite_size" / "fs_tau_alpha.png").stat().st_size > 1000
    # seeds 1 apart, errors 1: the spread is sqrt(2) / 1 at every N
    row = next(l for l in text.splitlines() if l.startswith("| τ_α |") and "(1)" in l)
    assert row.count("1.41 ± 1.00 (1)") == 3


def test_spread_ratio_pools_the_seeds_against_the_quoted_errors():
    # Two points: seeds 10, 12 (error 1) and 20, 20, 23 (error 1.5): the
    # squared deviations over e^2 sum to 2 + 6 / 2.25, over 1 + 2 dof.
    pts = []
    for vals, err in (((10.0, 12.0), 1.0), ((20.0, 20.0, 23.0), 1.5)):
        p = Point(("neighbours", 0.9, 0.79, 4096))
        for seed, v in enumerate(vals, 1):
            p.runs.append({"seed": seed, "cut": {0.6: {"tau_alpha": v, "tau_alpha_err": err}}})
        pts.append(p)
    tau = lambda r, cr=False: (r["cut"][0.6]["tau_alpha"], r["cut"][0.6]["tau_alpha_err"])
    r, u, dof, unquoted = spread_ratio(pts, tau)
    assert dof == 3 and unquoted == 0
    assert math.isclose(r, math.sqrt((2.0 + 6.0 / 2.25) / 3)) and math.isclose(u, r / math.sqrt(6))
    # Seeds drawn with exactly their quoted spread give about 1.
    rng = np.random.default_rng(5)
    pts = []
    for k in range(200):
        p = Point(("neighbours", 0.9, 0.79, 4096))
        for seed in (1, 2, 3):
            p.runs.append({"seed": seed, "cut": {0.6: {"tau_alpha": 50 + rng.normal(0, 2.0), "tau_alpha_err": 2.0}}})
        pts.append(p)
    r, u, dof, _ = spread_ratio(pts, tau)
    assert dof == 400 and abs(r - 1.0) < 3 * u
    # Runs without an error are counted, not pooled.
    p = Point(("neighbours", 0.9, 0.79, 4096))
    p.runs += [{"seed": 1, "cut": {0.6: {"tau_alpha": 1.0, "tau_alpha_err": math.nan}}},
               {"seed": 2, "cut": {0.6: {"tau_alpha": 2.0, "tau_alpha_err": math.nan}}}]
    r, _, dof, unquoted = spread_ratio([p], tau)
    assert math.isnan(r) and dof == 0 and unquoted == 2


def test_a_point_without_a_measured_error_says_so_and_stays_out_of_the_verdict():
    from dynhet.analysis.finite_size import cell, measured_error
    one_unquoted = (1930.0, math.nan, math.nan, 1)   # one seed, no quoted error (tau_B)
    assert math.isnan(measured_error(one_unquoted)) and cell(one_unquoted) == "1930 (no error) ¹"
    assert "± 12" in cell((1930.0, 12.0, math.nan, 2))
    # two seeds and no quoted error: the spread of two, marked (one dof); three: not marked; quoted: not
    assert cell((1930.0, 40.0, 40.0, 2)).endswith("²") and not cell((1930.0, 40.0, 40.0, 3)).endswith("²")
    assert not cell((1930.0, 12.0, 40.0, 2)).endswith("²")
    text, n0, _, _ = size_verdict([1024, 4096, 16384], [1900.0, 1930.0, 2500.0], [20.0, 20.0, math.nan])
    assert n0 == 1024 and "N = 4096" in text  # the largest N, without an error, is left out


def test_errors_are_scaled_to_the_seeds_spread_when_it_is_larger(tmp_path):
    """Seeds 2 apart around each mean, quoted errors 1: the spread is twice the
    quoted error (12 dof over 6 points), so the tables' errors are doubled."""
    A = Analysis.__new__(Analysis)
    A.dir, A.figdir, A.also = str(tmp_path / "study"), str(tmp_path / "study" / "figures"), []
    A.points, A.extra, A.cpu, A.fits, A.rows = {}, {}, {}, {}, []
    for phi in (0.76, 0.79):
        for n, t in ((1024, 40.0), (4096, 42.0), (16384, 41.0)):
            p = Point(("neighbours", 0.9, phi, n))
            for seed, dv in ((1, -2.0), (2, 0.0), (3, 2.0)):
                p.runs.append({"seed": seed, "N": n, "cut": {0.6: {"tau_alpha": t + dv, "tau_alpha_err": 1.0}}})
            A.points[p.pairs, p.eps, p.phi, p.N] = p
    out = tmp_path / "finite_size.md"
    write_finite_size(A, str(out), "analyse_study.sh study")
    text = out.read_text()
    assert "τ_α × 2.00 (ratio 2.00 ± 0.41, 12 dof)" in text
    row = next(l for l in text.splitlines() if l.startswith("| τ_α |") and "verdict" not in l and "(" not in l.split("|")[2])
    assert "42 ± 1.2" in row  # sqrt(3) / 3 quoted, times 2


def test_xi_cells_say_how_many_q_shells_their_fits_had():
    from dynhet.analysis.size_rows import shells_note
    p = Point(("neighbours", 0.9, 0.79, 4096))
    p.runs = [{"seed": 1, "cut": {0.6: s4_cut(2.0, 100.0)}}, {"seed": 2, "cut": {0.6: s4_cut(4.0, 100.0)}}]
    assert shells_note(p, False) == " [3-7 q]"  # xi = 2: 7 shells below q xi = 1; xi = 4: 3
    p.runs = p.runs[:1]
    assert shells_note(p, False) == " [7 q]"
    assert shells_note(None, False) == ""


def test_a_whole_box_xi_or_chi0_without_a_value_says_why():
    from dynhet.analysis.size_rows import s4_reason
    L = 100.0
    resolved, few = {"cut": {0.6: s4_cut(2.0, L)}}, {"cut": {0.6: s4_cut(4.0, L)}}
    refused, tiny = {"cut": {0.6: s4_cut(math.nan, L)}}, {"cut": {0.6: s4_cut(0.2, L)}}
    assert s4_reason(resolved, False, "xi") is None
    assert s4_reason(few, False, "xi") == "not resolved"        # 3 shells below q xi = 1
    assert s4_reason(refused, False, "xi") == "no OZ fit" == s4_reason(refused, False, "chi0")
    assert s4_reason(tiny, False, "xi") == "ξ < 0.3"
    unreached = {"cut": {0.6: dict(s4_cut(2.0, L), tau_alpha=math.nan)}}
    assert s4_reason(unreached, False, "xi") == "τ_α not reached"
    assert s4_reason({"cut": {0.6: {"tau_alpha": 1.0}}}, False, "xi") is None   # no S4 measured
    # tau_alpha beyond the S4 lags (1 to 100): said as such, not "not resolved" (np.interp took the
    # last lag's xi there); a xi beyond the box (side 100, largest wavelength 100)
    beyond = {"cut": {0.6: dict(s4_cut(2.0, L), tau_alpha=150.0)}}
    assert s4_reason(beyond, False, "xi") == "τ_α beyond the S4 lags"
    huge = {"cut": {0.6: s4_cut(120.0, L)}}
    assert s4_reason(huge, False, "xi") == "ξ beyond the box"
    # one lag around tau_alpha below 0.3: the interpolated xi the cell would show is none
    half = {"cut": {0.6: dict(s4_cut(2.0, L), tau_alpha=31.6)}}
    half["cut"][0.6]["xi_t"] = np.array([[2.0], [2.0], [0.2]])
    assert s4_reason(half, False, "xi") is not None and math.isnan(xi_shells(half)[0])


def test_s4_of_every_n_is_drawn_standard_and_cage_relative(tmp_path):
    from dynhet.analysis.finite_size import plot_s4_q
    A = Analysis.__new__(Analysis)
    A.dir, A.figdir = str(tmp_path), str(tmp_path / "figures")
    multi, multi_cr = {0.79: {}}, {0.79: {}}
    for n, L in ((1024, 50.0), (4096, 100.0)):
        p = Point(("neighbours", 0.9, 0.79, n))
        for seed in (1, 2):
            c = dict(s4_cut(3.0, L), tau_alpha_err=0.5)
            q = c["s4_q"]
            c["s4_t"] = np.tile(4.0 / (1 + (3.0 * q) ** 2), (3, 1))   # OZ at every lag
            p.runs.append({"seed": seed, "N": n, "cut": {0.6: c}, "cut_cr": {0.6: dict(c)}})
        multi[0.79][n] = multi_cr[0.79][n] = p
    f = plot_s4_q(A, multi, multi_cr)
    assert f.endswith("fs_s4_q.png") and (tmp_path / "figures" / "fs_s4_q.png").stat().st_size > 5000
    # no S4 in any run: no figure
    for p in multi[0.79].values():
        for r in p.runs:
            r["cut"] = r["cut_cr"] = {0.6: {"tau_alpha": 10.0}}
    assert plot_s4_q(A, multi, multi_cr) == ""


def test_chi4p_against_the_sub_box_is_drawn_per_n_from_interior_peaks_only(tmp_path):
    from dynhet.analysis.finite_size import plot_chi4p_subbox
    A = Analysis.__new__(Analysis)
    A.dir, A.figdir = str(tmp_path), str(tmp_path / "figures")
    multi, multi_cr = {0.79: {}}, {0.79: {}}
    for n in (1024, 4096):
        p = Point(("neighbours", 0.9, 0.79, n))
        for seed in (1, 2):
            c = {"chi4_N": np.array([32.0, 128.0, float(n)]), "chi4_peak": np.array([1.0, 2.0 + seed, 5.0]),
                 "chi4_peak_err": np.array([0.1, 0.3, 0.5]), "tau4_interior": np.array([True, True, seed == 1])}
            p.runs.append({"seed": seed, "N": n, "cut": {0.6: c}})
        multi[0.79][n] = p
    # the points and their error bars: the mean over seeds with the table's error (Point.mean)
    p = multi[0.79][4096]
    v, e, sem, k = p.mean(chi4p_grid(128))
    assert (v, k) == (3.5, 2) and math.isclose(e, math.hypot(0.3, 0.3) / 2)
    assert p.mean(chi4p_grid(4096))[:2] == (5.0, 0.5)          # the whole box: seed 2's peak is no peak
    assert p.mean(chi4p_grid(512))[3] == 0                     # no grid of that size
    f = plot_chi4p_subbox(A, multi, multi_cr)
    assert f.endswith("fs_chi4p_subbox.png") and (tmp_path / "figures" / "fs_chi4p_subbox.png").stat().st_size > 5000
    for p in multi[0.79].values():
        for r in p.runs:
            r["cut"][0.6]["tau4_interior"][:] = False          # no interior peak anywhere: nothing to draw
    assert plot_chi4p_subbox(A, multi, multi_cr) == ""


def test_a_size_verdict_takes_no_zero_error_and_no_size_twice():
    # an error of 0 (a fit's, passed straight in) made the flatness test NaN, so the line was never
    # judged: such a size is no measurement, like one without an error, and takes no part
    text, n0, _, _ = size_verdict([1024, 4096, 16384, 65536], [10.0, 10.4, 10.8, 11.2], [0.3, 0.3, 0.3, 0.0])
    assert "within 2σ of N = 16384" in text
    text, n0, _, _ = size_verdict([1024, 4096, 16384, 65536], [10.0, 10.4, 10.8, 11.2], [0.3, 0.3, 0.3, 1e-9])
    assert n0 is None and "3.0σ from flat" in text
    with pytest.raises(ValueError, match="a size given twice"):
        size_verdict([1024, 1024, 4096], [1.0, 1.1, 1.2], [0.1] * 3)


def test_the_reproduction_takes_xi_and_chi0_only_where_five_shells_resolve_them():
    """The 5-shell rule holds for every xi and chi0 the reproduction uses (its rows and
    fits), not only for the finite-size table: xi = 2 in a box of side 100 has
    7 shells below q xi = 1 and is taken; xi = 4 has 3, and neither it nor the
    chi0 of the same fit is."""
    from dynhet.analysis.appendix import whole_box
    from dynhet.analysis.quantities import chi0_at_tau, xi_at_tau

    def run(xi):
        c = s4_cut(xi, 100.0)
        c.update(tau_alpha_err=0.5, chi0_t=np.full((3, 1), 5.0), s4_oz_chi0=np.array([5.0]),
                 s4_oz_chi0_err=np.array([0.5]), s4_chi4=np.array([4.0]), s4_chi4_err=np.array([0.4]))
        return {"cut": {0.6: c}, "N": 4096}
    v, e = xi_at_tau(run(2.0))
    assert math.isclose(v, 2.0) and e > 0
    assert math.isclose(chi0_at_tau(run(2.0))[0], 5.0) and math.isclose(whole_box(run(2.0), "s4_oz_chi0")[0], 5.0)
    assert math.isnan(xi_at_tau(run(4.0))[0]) and math.isnan(chi0_at_tau(run(4.0))[0])
    assert math.isnan(whole_box(run(4.0), "s4_oz_chi0")[0]) and whole_box(run(4.0), "s4_chi4")[0] == 4.0


def test_a_size_where_only_some_seeds_have_a_value_says_so_and_stays_out_of_the_verdict():
    from dynhet.analysis.finite_size import cell, quantity_rows

    def pt(n, vals):
        p = Point(("neighbours", 0.9, 0.78, n))
        p.runs = [{"seed": s, "N": n, "v": v} for s, v in enumerate(vals, 1)]
        return p
    fn = lambda r, cr: (r["v"], 0.1)
    d = {1024: pt(1024, [5.0, 5.1, 4.9]), 4096: pt(4096, [3.0, math.nan, math.nan]), 16384: pt(16384, [5.0, 5.05])}
    ns, ms, (text, n0, _, _) = quantity_rows(d, fn, False)
    assert cell(ms[1], 3).endswith("¹ (1 of 3 seeds)") and "seeds" not in cell(ms[0], 3)
    assert n0 == 1024, text            # 4096's lone seed (3.0, far off) does not break convergence: it is not judged


def test_a_verdict_that_cannot_take_the_sizes_shown_says_why():
    from dynhet.analysis.finite_size import quantity_rows

    def pt(n, vals):
        p = Point(("neighbours", 0.9, 0.78, n))
        p.runs = [{"seed": s, "N": n, "v": v} for s, v in enumerate(vals, 1)]
        return p
    d = {1024: pt(1024, [5.0, math.nan]), 4096: pt(4096, [3.0, math.nan]), 16384: pt(16384, [5.0, 5.05])}
    _, _, (text, n0, _, _) = quantity_rows(d, lambda r, cr: (r["v"], 0.1), False)
    assert n0 is None and text == "no verdict: 1 of the 3 sizes shown has every seed's value with an error and a steady state"
    d = {4096: pt(4096, [3.0, math.nan]), 16384: pt(16384, [math.nan, math.nan])}
    _, _, (text, _, _, _) = quantity_rows(d, lambda r, cr: (r["v"], 0.1), False)
    assert text == "no verdict: 0 of the 1 size shown have every seed's value with an error and a steady state"


def test_a_size_whose_runs_did_not_all_finish_is_held_back_and_named():
    from dynhet.analysis.size import held_back, points_by_phi_n

    def point(study, n, seeds):
        p = Point(("neighbours", 0.9, 0.8, n))
        p.runs = [{"seed": s, "N": n, "study": study} for s in range(1, seeds + 1)]
        p.study = study
        return p
    A = Analysis.__new__(Analysis)
    A.points = {}
    A.extra = {("scale", "neighbours", 0.9, 0.8, n): point("scale", n, k) for n, k in ((1024, 3), (4096, 3), (16384, 2))}
    A.unfinished = {("scale", "neighbours", 0.9, 0.8, 16384): 1}
    assert sorted(points_by_phi_n(A)[0.8]) == [1024, 4096]
    assert held_back(A, 0.8) == [(16384, "scale", 1)] and held_back(A, 0.79) == []


def test_the_sub_box_caption_names_a_box_its_sub_boxes_stop_short_of():
    """fig. chi4P(a): a curve's last point is the whole box only where the
    study's sub-box sizes reach it (studies/scale.toml's end at 32768, below
    N = 262144): the caption names that size and its largest sub-box."""
    from dynhet.analysis.finite_size import short_of_box
    def pt(n, sizes):
        p = Point(("neighbours", 0.9, 0.78, n))
        p.runs.append({"seed": 1, "N": n, "cut": {0.6: {"chi4_N": np.array(sizes)}}})
        return p
    reach = {0.78: {16384: pt(16384, [28.4, 113.8, 455.1, 1820.4, 16384.0])}}
    assert short_of_box(reach) == ""
    reach[0.78][262144] = pt(262144, [28.4, 113.8, 455.1, 1820.4, 7281.8, 29127.1])
    assert short_of_box(reach) == "; at N = 262144 it is the largest sub-box its study asks for, 29127 particles, short of the box"


def test_the_spread_table_says_a_size_of_one_seed_cannot_check_its_errors():
    """The seed-spread check at the largest N: one seed has no spread, so the check cannot be
    made there; the table says so instead of a bare dash."""
    from dynhet.analysis.finite_size import spread_section
    multi = {}
    for phi in (0.76, 0.78):
        multi[phi] = {}
        for n, seeds in ((4096, (1, 2, 3)), (262144, (1,))):
            p = Point(("neighbours", 0.9, phi, n))
            for s in seeds:
                p.runs.append({"seed": s, "N": n, "cut": {0.6: {"tau_alpha": 10.0 + s, "tau_alpha_err": 1.0}}})
            multi[phi][n] = p
    row = next(l for l in spread_section(multi, {}) if l.startswith("| τ_α |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[1] == "1.00 ± 0.35 (4)"          # seeds 1 apart (std 1), errors 1: 2 points of 2 dof, ± 1/sqrt(8)
    assert cells[2] == "one seed: not checkable"
    # a one-seed size that lacks the quantity (another study's run, which did not measure it): a dash
    for phi in (0.76, 0.78):
        multi[phi][262144].runs[0]["cut"][0.6]["tau_alpha"] = float("nan")
    row = next(l for l in spread_section(multi, {}) if l.startswith("| τ_α |"))
    assert [c.strip() for c in row.strip("|").split("|")][2] == "—"


def test_d_has_its_row_against_n(tmp_path):
    """D grows with the box in two dimensions (phi 0.78: 0.0085 at N 1024,
    0.0129 at 262144): finite_size.md judges it like every other quantity,
    standard and cage-relative."""
    A = Analysis.__new__(Analysis)
    A.dir, A.figdir, A.also = str(tmp_path / "study"), str(tmp_path / "study" / "figures"), []
    A.points, A.extra, A.cpu, A.fits, A.rows = {}, {}, {}, {}, []
    for n, dd in ((1024, 0.0085), (4096, 0.0095), (16384, 0.0107)):
        p = Point(("neighbours", 0.9, 0.78, n))
        for seed, e in ((1, -1e-5), (2, 1e-5)):
            p.runs.append({"seed": seed, "N": n, "cut": {0.6: {"tau_alpha": 14.0 + e, "tau_alpha_err": 0.5}},
                           "cut_cr": {0.6: {"tau_alpha": 85.0, "tau_alpha_err": 1.0}},
                           "D": dd + e, "D_err": 1e-4, "D_cr": 0.002 + e, "D_cr_err": 1e-4})
        A.points[p.pairs, p.eps, p.phi, p.N] = p
    out = tmp_path / "finite_size.md"
    write_finite_size(A, str(out), "analyse_study.sh study")
    lines = out.read_text().splitlines()
    row = next(l for l in lines if l.startswith("| D (the MSD's long-time slope / 4) |"))
    assert "drifting: 0.0006 ± 5e-05 per doubling of N" in row
    row = next(l for l in lines if l.startswith("| D (the MSD's long-time slope / 4) — cage-relative |"))
    assert "converged from N = 1024 on" in row


def test_tau_against_n_rows_give_a_spread_only_where_seeds_can_have_one(tmp_path):
    """local_measures.local_n_results: each N's cell gives the seeds' spread
    where it has several seeds, and none (no "± nan") where one seed."""
    from dynhet.analysis.local_measures import local_n_results
    A = Analysis.__new__(Analysis)
    A.dir, A.figdir, A.also = str(tmp_path / "study"), str(tmp_path / "study" / "figures"), []
    A.points, A.extra, A.cpu, A.fits, A.rows = {}, {}, {}, {}, []
    for n, seeds in ((4096, (1, 2, 3)), (65536, (1,))):
        p = Point(("neighbours", 0.9, 0.79, n))
        for seed in seeds:
            p.runs.append({"seed": seed, "N": n, "cut": {0.6: {"tau_alpha": 27.0 + seed, "tau_alpha_err": 1.0,
                                                               "tau_cr": 240.0 + seed, "tau_cr_err": 5.0}}})
        A.points[p.pairs, p.eps, p.phi, p.N] = p
    local_n_results(A)
    rows = {r["item"]: r["ours"] for r in A.rows}
    cell = rows["τ_α against N at φ = 0.79"]
    assert "N 4096: 29 ± 0.58 (seeds 3, spread ± 0.58)" in cell and "N 65536: 28 ± 1 (seeds 1)" in cell
    assert "nan" not in " ".join(rows.values())
