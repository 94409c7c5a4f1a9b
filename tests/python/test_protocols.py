"""One protocol per density's table against N (size.points_by_phi_n): the
studies' run lengths (unit, equilibration, origins, spacing) decide which
study's sizes a table takes, which it names and which it holds back."""
import matplotlib

matplotlib.use("Agg")

from dynhet.analysis.points import Point  # noqa: E402
from dynhet.analysis.study import Analysis  # noqa: E402


def test_a_tie_at_one_n_goes_to_the_study_that_runs_the_density_at_every_n():
    """One protocol across N: where a single-N study (quick, other run lengths)
    and the scale study have as many seeds at N = 4096, the scale study's
    point is the one in the table; more seeds still win."""
    from dynhet.analysis.size import points_by_phi_n

    def point(study, n, seeds):
        p = Point(("neighbours", 0.9, 0.79, n))
        p.runs = [{"seed": s, "N": n, "study": study} for s in range(1, seeds + 1)]
        return p
    A = Analysis.__new__(Analysis)
    quick = point("quick", 4096, 3)
    A.points = {(quick.pairs, quick.eps, quick.phi, quick.N): quick}
    scale = {n: point("scale", n, 3) for n in (1024, 4096, 16384)}
    A.extra = {("scale", p.pairs, p.eps, p.phi, p.N): p for p in scale.values()}
    multi = points_by_phi_n(A)
    assert multi[0.79][4096] is scale[4096] and multi[0.79][1024] is scale[1024]
    quick.runs.append({"seed": 4, "N": 4096, "study": "quick"})     # four seeds against three
    assert points_by_phi_n(A)[0.79][4096] is quick
    # as many seeds and sizes: the study with the cage-relative measures (the tau_alpha^CR protocol)
    other = {n: point("d_size", n, 3) for n in (1024, 4096, 16384)}
    A.points = {}
    A.extra = {(st, p.pairs, p.eps, p.phi, p.N): p for st, d in (("d_size", other), ("scale", scale)) for p in d.values()}
    for p in scale.values():
        for r in p.runs:
            r["cut_cr"] = {0.6: {}}
    assert all(points_by_phi_n(A)[0.79][n] is scale[n] for n in scale)


def protocol_point(study, n, seeds=1, cr=False, phi=0.76):
    """A point of `study` at (phi, N) with `seeds` runs (cage-relative measures
    with cr); every study but d_size (the overlap and the MSD alone) measured chi4."""
    p = Point(("neighbours", 0.9, phi, n))
    p.study = study
    chi4 = {} if study == "d_size" else {"cut": {0.6: {"chi4": [1.0]}}}
    p.runs = [{"seed": s, "N": n, "study": study, **chi4, **({"cut_cr": {0.6: {}}} if cr else {})}
              for s in range(1, seeds + 1)]
    return p


def protocol_analysis(points, protocols):
    """An Analysis holding `points` as --also points, with the studies' protocols."""
    A = Analysis.__new__(Analysis)
    A.points, A.protocols = {}, protocols
    A.extra = {(p.study, p.pairs, p.eps, p.phi, p.N): p for p in points}
    return A


def test_each_densitys_table_is_one_protocol():
    """The referee's rule: the same run lengths in units of the relaxation
    time at every N. Protocols as the studies' run_length say (unit,
    equilibration, origins, spacing; not the lag range)."""
    from dynhet.analysis.size import others_note, points_by_phi_n
    scale = [protocol_point("scale", n, 3 if n <= 16384 else 1, cr=True) for n in (1024, 4096, 16384, 65536, 262144)]
    d_size = [protocol_point("d_size", n) for n in (4096, 16384, 65536, 262144, 1000000)]
    quick = [protocol_point("quick", 4096, 4)]
    fs = [protocol_point("finite_size", n) for n in (1024, 16384)]
    A = protocol_analysis(scale + d_size + quick + fs,
                          {"scale": ("tau_alpha_cr", 10.0, 8, 1.0), "d_size": ("tau_alpha", 5.0, 4, 1.0),
                           "quick": ("tau_alpha", 10.0, 8, 1.0), "finite_size": ("tau_alpha", 10.0, 8, 1.0)})
    t = points_by_phi_n(A)[0.76]
    # five sizes each: scale's (the cage-relative protocol); quick's four seeds at 4096 do not
    # displace it, and d_size's 10^6 is named, not a column
    assert t.protocol == A.protocols["scale"] and all(t[p.N] is p for p in scale) and 1000000 not in t
    assert t.others == [("d_size", 1000000, 1)]
    assert others_note(t) == "; not in this table, another study's protocol: N 1000000 of d_size (1 run)"
    # D against N: the protocol reaching the largest N (d_size's), scale's 1024 named
    t = points_by_phi_n(A, lead_by="n")[0.76]
    assert t.protocol == A.protocols["d_size"] and sorted(t) == [4096, 16384, 65536, 262144, 1000000]
    assert t.others == [("finite_size", 1024, 1), ("scale", 1024, 3)]
    # quick and finite_size differ only in their lags: one protocol, merged (quick's seeds at 4096)
    del A.extra["scale", "neighbours", 0.9, 0.76, 1024]
    for p in d_size:
        del A.extra["d_size", p.pairs, p.eps, p.phi, p.N]
    A.protocols["scale"] = ("tau_alpha_cr", 10.0, 8, 2.0)      # not the same spacing
    for n in (65536, 262144):
        del A.extra["scale", "neighbours", 0.9, 0.76, n]
    t = points_by_phi_n(A)[0.76]
    assert t.protocol == A.protocols["quick"] and t[4096] is quick[0] and sorted(t) == [1024, 4096, 16384]
    assert t.others == []   # scale's sizes (4096, 16384) are the table's already: none only it ran


def test_another_protocols_unfinished_size_holds_nothing_back():
    # d_size's N = 262144 unfinished: scale's finished 262144 stays in scale's
    # table (a hold per study made d_size lead with five sizes, and scale's
    # 262144 vanished); scale's own unfinished size is still held back, and
    # not filled from d_size's.
    from dynhet.analysis.size import points_by_phi_n
    scale = [protocol_point("scale", n, cr=True) for n in (1024, 4096, 16384, 65536, 262144)]
    d_size = [protocol_point("d_size", n) for n in (4096, 16384, 65536, 1000000)]
    A = protocol_analysis(scale + d_size, {"scale": ("tau_alpha_cr", 10.0, 8, 1.0), "d_size": ("tau_alpha", 5.0, 4, 1.0)})
    A.unfinished = {("d_size", "neighbours", 0.9, 0.76, 262144): 1}
    t = points_by_phi_n(A)[0.76]
    assert t.protocol == A.protocols["scale"] and sorted(t) == [1024, 4096, 16384, 65536, 262144]
    # the other way round: scale's 262144 unfinished, d_size's finished
    del A.extra["scale", "neighbours", 0.9, 0.76, 262144]
    A.extra["d_size", "neighbours", 0.9, 0.76, 262144] = protocol_point("d_size", 262144)
    A.unfinished = {("scale", "neighbours", 0.9, 0.76, 262144): 1}
    t = points_by_phi_n(A)[0.76]
    assert t.protocol == A.protocols["scale"] and sorted(t) == [1024, 4096, 16384, 65536]
    assert (("d_size", 262144, 1) not in t.others)   # held back, not named as another protocol's size


def test_the_d_table_holds_back_by_its_own_leading_protocol():
    # D against N leads with d_size (to 10^6): scale's unfinished 65536 must not hold back d_size's
    # finished one (the hold used the cage-relative tie rule, d_size fell to four sizes and the
    # table went to scale); and a size of the leading protocol finished by one of its studies is
    # not held back by another of its studies that has it unfinished
    from dynhet.analysis.size import points_by_phi_n
    scale = [protocol_point("scale", n, cr=True) for n in (1024, 4096, 16384, 262144)]
    d_size = [protocol_point("d_size", n) for n in (4096, 16384, 65536, 262144, 1000000)]
    A = protocol_analysis(scale + d_size, {"scale": ("tau_alpha_cr", 10.0, 8, 1.0), "d_size": ("tau_alpha", 5.0, 4, 1.0),
                                           "d_more": ("tau_alpha", 5.0, 4, 1.0)})
    A.unfinished = {("scale", "neighbours", 0.9, 0.76, 65536): 1}
    t = points_by_phi_n(A, lead_by="n")[0.76]
    assert t.protocol == A.protocols["d_size"] and sorted(t) == [4096, 16384, 65536, 262144, 1000000]
    t = points_by_phi_n(A)[0.76]            # the cage-relative rule: scale's, its 65536 held back
    assert t.protocol == A.protocols["scale"] and 65536 not in t
    A.unfinished = {("d_more", "neighbours", 0.9, 0.76, 65536): 1}   # d_size's protocol, another study
    assert 65536 in points_by_phi_n(A, lead_by="n")[0.76]


def test_a_studys_protocol_is_read_from_the_study_file_it_holds(tmp_path):
    from dynhet.analysis.study import study_protocol
    (tmp_path / "study.toml").write_text('[run_length]\nunit = "tau_alpha_cr"\nequilibration_tau = 10.0\n'
                                         'origins = 8\nlag_max_tau = 4.0\n')
    assert study_protocol(str(tmp_path)) == ("tau_alpha_cr", 10.0, 8, 1.0)   # the spacing's default
    (tmp_path / "study.toml").write_text('[run_length]\nequilibration_tau = 5.0\norigins = 4\nlag_max_tau = 10.0\n')
    assert study_protocol(str(tmp_path)) == ("tau_alpha", 5.0, 4, 1.0)
    assert study_protocol(str(tmp_path / "none")) is None
