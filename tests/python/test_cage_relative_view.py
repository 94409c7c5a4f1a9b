"""The study analysis' cage-relative view (Analysis.cage_relative_view):
every run's per-cutoff results replaced by its cage-relative ones, runs
without them left out, rows marked and kept out of the agree/differ count,
fits and figures prefixed; the study itself untouched."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from dynhet.analysis.points import Point  # noqa: E402
from dynhet.analysis.study import Analysis  # noqa: E402


def analysis(tmp_path):
    A = Analysis.__new__(Analysis)  # no study directory: points made here
    A.dir, A.figdir = str(tmp_path), str(tmp_path / "figures")
    A.points, A.extra, A.cpu, A.fits, A.rows = {}, {}, {}, {}, []
    for phi, with_cr in ((0.70, True), (0.75, False)):
        p = Point(("neighbours", 0.9, phi, 4096))
        for seed in (1, 2):
            r = {"seed": seed, "cut": {0.6: {"tau_alpha": 10.0 * phi}}}
            if with_cr:
                r["cut_cr"] = {0.6: {"tau_alpha": 30.0 * phi}}
            p.runs.append(r)
        A.points[p.pairs, p.eps, p.phi, p.N] = p
    return A


def test_the_view_swaps_the_results_and_marks_its_rows(tmp_path):
    A = analysis(tmp_path)
    assert A.has_cage_relative()
    C = A.cage_relative_view()
    assert [p.phi for p in C.series()] == [0.70]                      # the point without _cr is left out
    assert [r["cut"][0.6]["tau_alpha"] for r in C.series()[0].runs] == [21.0, 21.0]
    assert [r["cut"][0.6]["tau_alpha"] for r in A.series()[0].runs] == [7.0, 7.0]  # the study untouched
    C.row("τ_α at φ = 0.7", "3.1", "7", "21", "differs", "", C.series())
    C.fit("tau_power", "a fit")
    row = A.rows[-1]
    assert row["item"] == "τ_α at φ = 0.7 (cage-relative)" and row["verdict"] == "—"
    assert "against the paper's standard measure: differs" in row["note"]
    assert A.fits == {"cr_tau_power": "a fit"}
    fig = plt.figure()
    fig.add_subplot().plot([1, 2], [1, 2])
    assert C.save(fig, "tau.png") == "figures/cr_tau.png"


def test_a_panel_with_nothing_a_log_axis_can_show_is_saved_as_such(tmp_path):
    A = analysis(tmp_path)
    fig, ax = plt.subplots(1, 2)
    ax[0].errorbar([float("nan")], [1.0], [0.1], fmt="o")  # xi of no run determined
    ax[1].errorbar([1.0, 2.0], [0.0, -1.0], [0.1, 0.1], fmt="o")               # nothing positive
    for a in ax:
        a.set_xscale("log")
        a.set_yscale("log")
    assert A.save(fig, "empty.png") == "figures/empty.png"
    assert (tmp_path / "figures" / "empty.png").stat().st_size > 1000


def test_the_cage_relative_and_bond_breaking_fits_are_of_their_own_times(tmp_path):
    """tau_alpha^CR(phi) and tau_B(phi) are fitted to their own values (the
    rows once held the standard tau_alpha's fit under their names)."""
    import math

    from dynhet.analysis.local_measures import local_phi_results
    A = Analysis.__new__(Analysis)
    A.dir, A.figdir = str(tmp_path), str(tmp_path / "figures")
    A.points, A.extra, A.cpu, A.fits, A.rows = {}, {}, {}, {}, []
    laws = {"tau": (0.80, 1.5), "tau_cr": (0.83, 2.0), "tau_b": (0.86, 2.5)}  # phi_c, gamma of each
    for phi in (0.70, 0.72, 0.74, 0.76, 0.78):
        p = Point(("neighbours", 0.9, phi, 4096))
        for seed in (1, 2, 3):
            v = {k: 0.1 * (xc - phi) ** -g * (1 + 0.002 * (seed - 2)) for k, (xc, g) in laws.items()}
            p.runs.append({"seed": seed, "tau_b": v["tau_b"], "tau_b_err": 0.01 * v["tau_b"],
                           "cut": {0.6: {"tau_alpha": v["tau"], "tau_alpha_err": 0.01 * v["tau"],
                                         "tau_cr": v["tau_cr"], "tau_cr_err": 0.01 * v["tau_cr"]}}})
        A.points[p.pairs, p.eps, p.phi, p.N] = p
    local_phi_results(A)
    for tag, key in (("tau_power_eps0.9_cr", "tau_cr"), ("tau_power_eps0.9_B", "tau_b")):
        f = A.fits[tag]
        assert f.ok and math.isclose(f.p["xc"], laws[key][0], abs_tol=2e-3), (tag, f.p)
        assert math.isclose(f.p["g"], laws[key][1], rel_tol=0.02), (tag, f.p)


def test_values_without_any_error_are_still_drawn(tmp_path):
    """A series whose points have no error at all (single seeds quoting none:
    tau_alpha where the origins cannot span it) is drawn without bars;
    matplotlib's own errorbar raises StopIteration on all-NaN errors, which
    failed whole sections of a study's analysis."""
    import math

    from dynhet.analysis.plotting import errorbar
    fig, ax = plt.subplots()
    lines = errorbar(ax, [1.0, 2.0], [3.0, 4.0], [math.nan, math.nan], fmt="o")
    assert list(lines[0].get_ydata()) == [3.0, 4.0]
    plt.close(fig)


def test_a_real_verdict_reaches_the_note_and_both_measures_stand_side_by_side(tmp_path):
    # Verdicts read "differs (3.2 σ)" or "agrees (0.4 σ); ...": the note of
    # the cage-relative row had only ever matched a bare "differs".
    from dynhet.analysis.output import side_by_side
    A = analysis(tmp_path)
    C = A.cage_relative_view()
    A.row("τ4 ∝ τ_α^z", "3.4", "1.19", "1.06 ± 0.1", "agrees (1.3 σ)", "", A.series())
    C.row("τ4 ∝ τ_α^z", "3.4", "1.19", "1 ± 0.02", "differs (9.5 σ)", "", C.series())
    C.row("κ", "3.3", "≈ 1.8", "1.72 ± 0.01", "not judged: χ² improbable", "", C.series())
    cr = A.rows[1]
    assert cr["verdict"] == "—" and cr["note"] == "against the paper's standard measure: differs (9.5 σ)"
    assert A.rows[2]["note"] == "not judged: χ² improbable"           # no verdict, but its reason stays in view
    lines = side_by_side(A.rows)
    assert "| τ4 ∝ τ_α^z | 1.19 | 1.06 ± 0.1; agrees (1.3 σ) | 1 ± 0.02; differs (9.5 σ) |" in lines
    assert "| κ (cage-relative) | ≈ 1.8 | — | 1.72 ± 0.01; not judged |" in lines     # no standard row: it stands alone
    assert side_by_side(A.rows[:1]) == []                                 # no cage-relative row: no section


def test_the_view_takes_the_cage_relative_d_and_never_the_standard_one(tmp_path):
    import math
    A = analysis(tmp_path)
    runs = A.series()[0].runs
    runs[0].update(D=0.01, D_err=0.001, D_cr=0.004, D_cr_err=0.0002)
    runs[1].update(D=0.012, D_err=0.001)                  # a run without the cage-relative MSD
    C = A.cage_relative_view()
    got = [(r["D"], r["D_err"]) for r in C.series()[0].runs]
    assert got[0] == (0.004, 0.0002) and all(math.isnan(x) for x in got[1])
    assert [r["D"] for r in A.series()[0].runs] == [0.01, 0.012]   # the study untouched


def test_pairs_are_found_across_numbers_in_the_names_and_a_lone_row_is_kept():
    from dynhet.analysis.output import side_by_side

    def row(item, ours, verdict="—", note="", section="3.4"):
        return dict(item=item, section=section, paper="2.5", ours=ours, verdict=verdict, note=note)
    rows = [row("γχ (φ_c held at the joint fit's 0.8006)", "1.2", "differs (4.0 σ)"),
            row("d_f at φ = 0.6", "1.6", "agrees (0.5 σ)"), row("d_f at φ = 0.8", "1.9", "agrees (1.0 σ)"),
            row("γχ (φ_c held at the joint fit's 0.8042) (cage-relative)", "0.9",
                note="against the paper's standard measure: differs (8.0 σ)"),
            row("d_f at φ = 0.6 (cage-relative)", "1.64"), row("d_f at φ = 0.78 (cage-relative)", "1.93"),
            row("θ (cage-relative)", "0.99", section="3.2")]
    lines = side_by_side(rows)
    assert ("| γχ (φ_c held at the joint fit's 0.8006) | 2.5 | 1.2; differs (4.0 σ) | "
            "[γχ (φ_c held at the joint fit's 0.8042)] 0.9; differs (8.0 σ) |") in lines
    assert "| d_f at φ = 0.6 | 2.5 | 1.6; agrees (0.5 σ) | 1.64 |" in lines          # in order: 0.6 with 0.6
    assert "| d_f at φ = 0.8 | 2.5 | 1.9; agrees (1.0 σ) | [d_f at φ = 0.78] 1.93 |" in lines
    assert "| θ (cage-relative) | 2.5 | — | 0.99 |" in lines                        # no standard row: alone
