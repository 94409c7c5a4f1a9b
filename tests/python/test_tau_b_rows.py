"""dynhet.analysis.finite_size and size_rows on bond breaking: tau_B from
the point that followed C_B furthest (a bound where C_B stayed above 1/e),
C_B compared across N at a common lag whose origin blocks give an error, and
no size whose runs did not all finish."""
import math

import matplotlib
import numpy as np

matplotlib.use("Agg")

from dynhet.analysis.finite_size import write_finite_size  # noqa: E402
from dynhet.analysis.points import Point  # noqa: E402
from dynhet.analysis.study import Analysis  # noqa: E402


def test_tau_b_beyond_the_lags_is_a_bound_and_c_b_is_compared_at_a_common_time(tmp_path):
    """C_B(t) = exp(-t / 100) in every run; one seed at N = 4096 stops at
    t = 60, before C_B reaches 1/e. Its point gives no mean tau_B (the other
    seed alone would say 100) but the bound > (100 + 60) / 2 = 80, and C_B
    is compared across N at t = 60, the longest lag every run reached."""
    A = Analysis.__new__(Analysis)
    A.dir, A.figdir, A.also = str(tmp_path / "study"), str(tmp_path / "study" / "figures"), []
    A.points, A.extra, A.cpu, A.fits, A.rows = {}, {}, {}, {}, []
    for n in (1024, 4096):
        p = Point(("neighbours", 0.9, 0.79, n))
        for seed in (1, 2):
            t_max = 60.0 if (n, seed) == (4096, 1) else 1000.0
            lag = np.geomspace(1.0, t_max, 40)
            p.runs.append({"seed": seed, "N": n, "packing_fraction": 0.79,
                           "cut": {0.6: {"tau_alpha": 10.0 + seed, "tau_alpha_err": 1.0,
                                         "lag": np.array([1.0, 50.0 * seed]), "tau_cr": 10.0}},
                           "c_b_lag": lag, "c_b": np.exp(-lag / 100.0), "c_b_err": np.full(40, 0.01),
                           "tau_b": 100.0 if t_max > 100 else math.nan, "tau_b_err": 2.0})
        A.points[p.pairs, p.eps, p.phi, p.N] = p
    out = tmp_path / "finite_size.md"
    write_finite_size(A, str(out), "analyse_study.sh study")
    text = out.read_text()
    row = next(l for l in text.splitlines() if l.startswith("| τ_B (bond breaking) |") and "verdict" not in l
               and "seeds: C_B" in l)
    cells = [c.strip() for c in row.split("|")[2:-1]]
    assert cells[0].startswith("100 ± ")                     # both seeds reached it
    assert cells[1] == "> 80 (1 of 2 seeds: C_B > 1/e at the last lag)"
    assert cells[2] == "one N only"                          # the bound takes no part in the verdict
    row = next(l for l in text.splitlines() if l.startswith("| C_B at t = 60 (bond breaking) |"))
    v = math.exp(-0.6)
    for c in row.split("|")[2:4]:
        assert abs(float(c.split("±")[0]) - v) < 2e-3     # interpolated in ln t between lags
    assert "converged from N = 1024" in row
    # the run lengths in units of each run's own tau_alpha^CR, per N (seed range)
    assert "own measured τ_α^CR (a study in units of τ_α^CR sets every N's lags from its pilot's; a run's own τ_α^CR scatters about that, and so does this ratio): N 1024: 5-10, N 4096: 5-10." in text


def test_a_tau_b_error_whose_blocks_cannot_span_it_is_dropped_on_reading(tmp_path):
    """The nodes' rule (origin_blocks_span), applied to runs recorded before
    the node did: 8 origins 263.7 apart allow blocks of 2 origins, which span
    a lag of up to 2 spacings; tau_B = 1950 spans 8."""
    import h5py
    from dynhet.analysis.runs import blocks_span, run_plan
    path = tmp_path / "run.h5"
    with h5py.File(path, "w") as f:
        g = f.create_group("parameters/schedule")
        g.attrs["origins"], g.attrs["origin_spacing"] = 8, 263.72614
    sch = run_plan(str(path))[0]
    assert sch == (8, 263.72614)
    assert not blocks_span(1950.0, sch)
    assert blocks_span(2 * 263.72614, sch) and not blocks_span(2.01 * 263.72614, sch)
    assert blocks_span(1950.0, (32, 263.72614))           # 8 blocks of 8 origins span it
    assert blocks_span(1950.0, None) and blocks_span(math.nan, sch)   # cannot be told: kept


def c_b_run(seed, n, t_max, tau_b=100.0, origins=8, spacing=1000.0):
    lag = np.geomspace(1.0, t_max, 40)
    return {"seed": seed, "N": n, "packing_fraction": 0.79,
            "cut": {0.6: {"tau_alpha": 10.0, "tau_alpha_err": 1.0}},
            "c_b_lag": lag, "c_b": np.exp(-lag / tau_b), "c_b_err": np.full(40, 0.01),
            "tau_b": tau_b if t_max > tau_b else math.nan, "tau_b_err": 2.0, "schedule": (origins, spacing)}


def test_tau_b_comes_from_the_point_that_followed_c_b_furthest_not_from_the_seeds_that_crossed():
    from dynhet.analysis.finite_size import bound_conflict
    from dynhet.analysis.size_rows import tau_b_bound, tau_b_points
    A = Analysis.__new__(Analysis)
    A.dir, A.also = "study", []
    A.points, A.extra = {}, {}
    main = Point(("neighbours", 0.9, 0.79, 4096))
    main.runs = [c_b_run(1, 4096, 200.0, 180.0), c_b_run(2, 4096, 200.0, 190.0), c_b_run(3, 4096, 200.0, 250.0)]
    early = Point(("neighbours", 0.9, 0.79, 4096))    # the same lags, two seeds that happened to cross early
    early.runs = [c_b_run(1, 4096, 200.0, 150.0), c_b_run(2, 4096, 200.0, 160.0)]
    early.study = "early"
    A.points[main.pairs, main.eps, main.phi, main.N] = main
    A.extra[("early",) + (early.pairs, early.eps, early.phi, early.N)] = early
    multi = {0.79: {4096: main}}
    assert tau_b_points(A, multi)[0.79][4096] is main         # equal reach: the more runs, bound and all
    assert math.isclose(tau_b_bound(main), (180.0 + 190.0 + 200.0) / 3)
    longer = Point(("neighbours", 0.9, 0.79, 4096))         # lags 10 times longer: its tau_B is measured
    longer.runs = [c_b_run(1, 4096, 2000.0, 200.0), c_b_run(2, 4096, 2000.0, 220.0)]
    longer.study = "longer"
    A.extra[("longer",) + (longer.pairs, longer.eps, longer.phi, longer.N)] = longer
    assert tau_b_points(A, multi)[0.79][4096] is longer
    assert tau_b_bound(longer) is None
    # a run whose C_B was below 1/e from its first lag gives no bound
    odd = Point(("neighbours", 0.9, 0.79, 1024))
    odd.runs = [c_b_run(1, 1024, 200.0, 300.0), c_b_run(2, 1024, 200.0, 0.5)]
    odd.runs[1]["tau_b"] = math.nan
    assert tau_b_bound(odd) is None
    # a bound above the largest measured N's value: the sizes do not agree
    ms = [(100.0, 2.0, 2.0, 2), (101.0, 2.0, 2.0, 2), (math.nan, math.nan, math.nan, 0)]
    text = bound_conflict([1024, 4096, 16384], ms, [None, None, 350.0])
    assert text.startswith("not converged: N = 16384's bound > 350 lies above N = 4096's 101 ± 2")
    assert bound_conflict([1024, 4096, 16384], ms, [None, None, 102.0]) == ""


def test_c_b_keeps_its_quoted_error_only_where_origin_blocks_span_the_lag():
    from dynhet.analysis.size_rows import c_b_at
    fn = c_b_at(((0.79, 60.0),))
    v, e = fn(c_b_run(1, 4096, 1000.0, spacing=1000.0))     # 60 within one spacing: blocks span it
    assert abs(v - math.exp(-0.6)) < 2e-3 and 0.01 <= e < 0.02
    v, e = fn(c_b_run(1, 4096, 1000.0, spacing=20.0))       # 3 spacings, blocks of 2 origins: no error
    assert abs(v - math.exp(-0.6)) < 2e-3 and math.isnan(e)


def test_the_seed_spread_of_tau_b_is_taken_over_the_points_its_cells_show():
    from dynhet.analysis.finite_size import spread_section

    def pt(n, tb):
        p = Point(("neighbours", 0.9, 0.79, n))
        p.runs = [{"seed": s, "N": n, "cut": {0.6: {"tau_alpha": 10.0 + s, "tau_alpha_err": 1.0}},
                   "tau_b": v, "tau_b_err": 10.0 if np.isfinite(v) else math.nan} for s, v in enumerate(tb, 1)]
        return p
    main = {0.79: {1024: pt(1024, [math.nan] * 3), 4096: pt(4096, [math.nan] * 3)}}     # lags short of tau_B
    longer = {0.79: {1024: pt(1024, [1900.0, 1920.0, 1910.0]), 4096: pt(4096, [1930.0, 1950.0, 1940.0])}}
    lines = spread_section(main, {}, longer)
    row = [x for x in lines if x.startswith("| τ_B")]
    assert row and "(2)" in row[0], lines       # 2 dof per N from the longer study's three seeds
    assert not [x for x in spread_section(main, {}) if x.startswith("| τ_B")]


def test_c_b_is_compared_at_the_longest_lag_whose_origin_blocks_give_every_size_an_error():
    """8 origins 100 apart: blocks of 2 origins span lags up to 200, so C_B is
    compared at the longest lag <= 200 (one seed at N = 262144 then has its
    own error), not at the last common lag 400, where no run quotes one."""
    from dynhet.analysis.size_rows import c_b_at, c_b_times
    lag = np.geomspace(1.0, 400.0, 30)
    d = {}
    for n, seeds in ((4096, (1, 2)), (262144, (1,))):
        p = Point(("neighbours", 0.9, 0.78, n))
        for s in seeds:
            p.runs.append({"seed": s, "N": n, "packing_fraction": 0.78, "schedule": (8, 100.0),
                           "c_b_lag": lag, "c_b": np.exp(-lag / 1000.0), "c_b_err": np.full(30, 0.002)})
        d[n] = p
    ((phi, t),) = c_b_times({0.78: d})
    assert phi == 0.78 and t == lag[lag <= 200.0][-1]
    v, e = c_b_at(((phi, t),))(d[262144].runs[0])
    assert abs(v - math.exp(-t / 1000.0)) < 1e-9 and abs(e - 0.002) < 1e-9
    # a lag beyond what the blocks span: no error (the seeds' spread stands in)
    assert math.isnan(c_b_at(((phi, 400.0),))(d[262144].runs[0])[1])


def test_the_tau_b_row_takes_no_size_whose_runs_did_not_all_finish():
    """tau_b_points chose its points over every study without the rule of
    the other rows: the scale study's N = 65536 at phi 0.79, one seed of two
    finished, appeared in the tau_B row while the size was held back."""
    from dynhet.analysis.size import points_by_phi_n
    from dynhet.analysis.size_rows import tau_b_points
    A = Analysis.__new__(Analysis)
    A.points, A.extra = {}, {}
    lag = np.geomspace(1.0, 400.0, 20)
    for n in (4096, 16384, 65536):
        p = Point(("neighbours", 0.9, 0.79, n))
        p.study = "scale"
        p.runs = [{"seed": 1, "N": n, "cut": {0.6: {"tau_alpha": 30.0, "tau_alpha_err": 1.0}},
                   "c_b_lag": lag, "c_b": np.exp(-lag / 100.0)}]
        A.extra[("scale",) + (p.pairs, p.eps, p.phi, p.N)] = p
    A.unfinished = {("scale", "neighbours", 0.9, 0.79, 65536): 1}
    multi = points_by_phi_n(A)
    assert sorted(multi[0.79]) == [4096, 16384]
    assert sorted(tau_b_points(A, multi)[0.79]) == [4096, 16384]
