"""steady_runs: every run's tau_alpha(t0) (and tau_alpha^CR(t0)) change
over its production, judged run by run, and its equilibration in units of
tau_alpha^CR (its own, else the largest N's at that density)."""
import numpy as np

from dynhet.analysis.points import Point
from dynhet.analysis.study import Analysis
from dynhet.analysis.steady_runs import run_change, steady_section


def run(seed, slope, noise, tau=10.0, origins=8, spacing=12.0, cr_tau=None, t_equil=300.0):
    t0 = np.arange(origins) * spacing
    wiggle = noise * np.where(np.arange(origins) % 2, 1.0, -1.0)
    c = {"t0": t0, "tau_t0": tau * (1 + slope * t0 / tau + wiggle), "tau_alpha": tau}
    r = {"seed": seed, "name": f"s{seed}", "cut": {0.6: c}, "cut_cr": {}, "schedule": (origins, spacing),
         "t_equil": t_equil}
    if cr_tau:
        r["cut_cr"] = {0.6: {"t0": t0, "tau_t0": np.full(origins, cr_tau) * (1 + wiggle), "tau_alpha": cr_tau}}
        r["cut"][0.6].update(tau_cr=cr_tau, tau_cr_err=1.0)
    return r


def test_a_trend_is_not_steady_and_a_wiggle_is():
    # a line: the change is its slope times the span in tau_alpha, exactly
    v, e, k, why = run_change(run(1, 0.05, 0.001), False)
    span = 7 * 12.0 / 10.0
    assert abs(v - 100 * 0.05 * span) < 0.5 and why == "not steady" and k == 6
    v, e, k, why = run_change(run(2, 0.0, 0.02), False)
    assert abs(v) < 3 * e and why == "steady"
    # origins closer than the errors allow (fewer than 3 with a value): not judged, said
    r = run(3, 0.0, 0.02)
    r["cut"][0.6]["tau_t0"][2:] = np.nan
    assert run_change(r, False)[3].startswith("not judged")
    assert run_change(run(4, 0.0, 0.02), True)[3] == "not measured"


def test_the_section_counts_every_run_and_takes_tau_cr_where_the_run_has_none():
    A = Analysis.__new__(Analysis)
    A.points, A.extra, A.cpu = {}, {}, {}
    p = Point(("neighbours", 0.9, 0.78, 4096))
    p.runs = [run(1, 0.0, 0.02, cr_tau=60.0), run(2, 0.05, 0.001, cr_tau=60.0)]
    A.points[p.pairs, p.eps, p.phi, p.N] = p
    q = Point(("neighbours", 0.9, 0.78, 65536))
    q.study = "big"
    q.runs = [run(1, 0.0, 0.02, t_equil=600.0)]
    A.extra[("big",) + (q.pairs, q.eps, q.phi, q.N)] = q
    L = "\n".join(steady_section(A))
    assert "**big**, 1 runs: τ_α(t0): 1 steady, 0 not steady, 0 not judged. Equilibration 10 to 10 τ_α^CR" in L
    assert "**this study**, 2 runs: τ_α(t0): 1 steady, 1 not steady (φ 0.78 N 4096 seed 2)" in L
    # origins 12 apart against a tau_alpha^CR of 60: no error can be had, so not judged, not "steady"
    assert "τ_α^CR(t0): 0 steady, 0 not steady, 2 not judged" in L and "Equilibration 5 to 5 τ_α^CR" in L
    rows = [l for l in L.splitlines() if l.startswith("| big")]
    assert len(rows) == 1 and "| 10 † |" in rows[0]   # 600 over the 4096 runs' tau_alpha^CR of 60


def test_the_same_system_after_two_equilibration_times_is_set_side_by_side():
    A = Analysis.__new__(Analysis)
    A.points, A.extra, A.cpu = {}, {}, {}
    p = Point(("neighbours", 0.9, 0.8, 4096))
    p.runs = [run(s, 0.0, 0.02, tau=t, t_equil=3000.0) for s, t in ((1, 200.0), (2, 300.0))]
    A.points[p.pairs, p.eps, p.phi, p.N] = p
    q = Point(("neighbours", 0.9, 0.8, 4096))
    q.study = "long"
    q.runs = [run(s, 0.0, 0.02, tau=t, t_equil=9000.0) for s, t in ((1, 300.0), (2, 400.0))]
    for r in q.runs:
        r["study"] = "long"
    A.extra[("long",) + (q.pairs, q.eps, q.phi, q.N)] = q
    L = "\n".join(steady_section(A))
    # means 250 and 350, each with a standard error of 50: +40%, 100 / (50 sqrt 2) = 1.4 errors
    assert ("- φ = 0.8, N = 4096: τ_α 250 ± 50 after 3000 (this study, 2 runs); 350 ± 50 after 9000 (long, 2 runs): "
            "+40% from the shortest to the longest, 1.4 of their combined errors (2 dof).") in L
