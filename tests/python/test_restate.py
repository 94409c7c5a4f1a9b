"""dynhet.analysis.restate: every row an earlier table judged "differs" is
found in the new rows (by its name, a name that grew, or not at all) and
its verdict then and now set side by side."""
from dynhet.analysis.restate import read_rows, restate

OLD = """# The paper from our own runs

| result | paper (section, figure) | paper | ours | verdict | figure | CPU |
|---|---|---|---|---|---|---|
| d_f' | 3.4 | 1.6 | 0.95 ± 0.09 | differs (7.4 σ) | `x.png` | 0:01:00 |
| φ_c (own) | 3.1 | 0.82 | 0.8004 ± 0.0005 | differs (40.0 σ); χ²/dof 22 | `y.png` | 0:01:00 |
| β | 3.1 | figure only | 1.4 | figure | — | 0:01:00 |
| gone row | 3.3 | 1.8 | 1.66 ± 0.005 | differs (26.6 σ) | — | 0:01:00 |

## Per point

| pairs | ε |
|---|---|
| x | differs |
"""


def test_each_differing_row_is_restated(tmp_path):
    old = tmp_path / "old.md"
    old.write_text(OLD, encoding="utf-8")
    assert list(read_rows(old)) == ["d_f'", "φ_c (own)", "β", "gone row"]   # the first table only
    rows = [dict(item="d_f' (ξ ≥ 3)", ours="1.5 ± 0.2", verdict="agrees (0.5 σ)"),
            dict(item="φ_c", ours="0.8004 ± 0.0005", verdict="not judged: on the edge of the data"),
            dict(item="β", ours="1.4", verdict="figure")]
    text = "\n".join(restate(str(old), rows))
    assert "| d_f' | 0.95 ± 0.09; differs (7.4 σ) | 1.5 ± 0.2; agrees (0.5 σ) | now agrees; error 2.2× the earlier one's |" in text
    assert "| φ_c (own) | 0.8004 ± 0.0005; differs (40.0 σ); χ²/dof 22 | 0.8004 ± 0.0005; not judged: on the edge" in text
    assert "now not judged; error 1× the earlier one's |" in text   # the same error: the verdict moved, not the error
    assert "| gone row | 1.66 ± 0.005; differs (26.6 σ) | — | no such row now |" in text
    assert "3 rows differed; 0 still differ, 2 have another verdict now, 1 have no row now." in text


def test_tables_between_say_at_which_step_a_verdict_moved(tmp_path):
    old = tmp_path / "old.md"
    old.write_text(OLD, encoding="utf-8")
    fixed = tmp_path / "fixed.md"   # the errors fixed: d_f' agrees, φ_c not judged
    fixed.write_text(OLD.replace("| 0.95 ± 0.09 | differs (7.4 σ) |", "| 0.84 ± 0.52 | agrees (1.5 σ) |")
                        .replace("| differs (40.0 σ); χ²/dof 22 |", "| not judged: χ²/dof 10 |"), encoding="utf-8")
    seeds = tmp_path / "seeds.md"   # other seeds: d_f' differs again; the gone row has no row there
    seeds.write_text(OLD.replace("| 0.95 ± 0.09 | differs (7.4 σ) |", "| 0.7 ± 0.2 | differs (4.5 σ) |")
                        .replace("| gone row |", "| another row |"), encoding="utf-8")
    rows = [dict(item="d_f'", ours="1.3 ± 0.2", verdict="agrees (1.2 σ)"),
            dict(item="φ_c (own)", ours="0.801", verdict="not judged: χ²/dof 9"),
            dict(item="gone row", ours="1.72 ± 0.006", verdict="differs (13.0 σ)")]
    text = "\n".join(restate(str(old), rows, [("errors fixed", str(fixed)), ("other seeds", str(seeds))]))
    assert "| result (earlier) | earlier: ours, verdict | errors fixed | other seeds | now: ours, verdict | change |" in text
    assert ("| d_f' | 0.95 ± 0.09; differs (7.4 σ) | 0.84 ± 0.52; agrees (1.5 σ) | 0.7 ± 0.2; differs (4.5 σ) | "
            "1.3 ± 0.2; agrees (1.2 σ) | now agrees (agrees at errors fixed, differs at other seeds, agrees at now); error 2.2× the earlier one's |"
            in text)
    # the row is not in "other seeds": its column says so, and the verdict compared across the gap
    assert "| gone row | 1.66 ± 0.005; differs (26.6 σ) | 1.66 ± 0.005; differs (26.6 σ) | — | 1.72 ± 0.006; " \
           "differs (13.0 σ) | same verdict |" in text
    assert "now not judged (not judged at errors fixed, differs at other seeds, not judged at now) |" in text


def test_restate_via_takes_label_equals_table_and_names_what_is_wrong(tmp_path, capsys):
    import pytest
    from dynhet.analysis.cli import main
    old = tmp_path / "old.md"
    old.write_text(OLD, encoding="utf-8")
    study = str(tmp_path / "no-study")
    for args, says in ((["--restate-via", "errors fixed (N = 4096)=" + str(old)], "needs --restate"),
                       (["--restate", str(old), "--restate-via", str(old)], "give LABEL=TABLE"),
                       (["--restate", str(old), "--restate-via", "x (N = 4096)=missing.md"], "no such file missing.md")):
        with pytest.raises(SystemExit) as e:
            main([study] + args)
        assert e.value.code == 2 and says in capsys.readouterr().err  # a bad argument
    # a label holding "=" is split at the last one: the file is found, and the study is next to be read
    with pytest.raises(SystemExit) as e:
        main([study, "--restate", str(old), "--restate-via", "errors fixed (N = 4096)=" + str(old)])
    err = capsys.readouterr().err
    assert e.value.code == 2 and "not a study directory nor a results archive: no index.toml" in err and "no-study" in err


def test_how_far_each_step_moved_the_value_in_errors(tmp_path):
    from dynhet.analysis.restate import shifts, value_of
    assert value_of("1.3 ± 0.2 (orthogonal distance regression)") == (1.3, 0.2)
    assert value_of("median 1.37") is None and value_of("-2.27 ± 1.6") == (-2.27, 1.6)
    assert value_of("0.0268 ± 0.0029") == (0.0268, 0.0029) and value_of("1.48e+03 ± 1.3e+02") == (1480.0, 130.0)
    # d_f': 0.95 ± 0.09 -> 0.84 ± 0.52 -> 0.7 ± 0.2 -> 1.3 ± 0.2
    assert shifts(["0.95 ± 0.09", "0.84 ± 0.52", "0.7 ± 0.2", "1.3 ± 0.2"]) == "0.2 / 0.3 / 2.1"
    assert shifts(["1.66 ± 0.005", "median 1.2", "1.72 ± 0.006"]) == "— / —"
    old = tmp_path / "old.md"
    old.write_text(OLD, encoding="utf-8")
    rows = [dict(item="d_f'", ours="1.3 ± 0.2", verdict="agrees (1.2 σ)")]
    text = "\n".join(restate(str(old), rows))
    assert "| d_f' | 0.95 ± 0.09; differs (7.4 σ) | 1.3 ± 0.2; agrees (1.2 σ) | now agrees; error 2.2× the earlier one's | 1.6 |" in text


def test_the_comparison_with_the_n_4096_table_lists_what_changed(tmp_path):
    """analyse_study --compare: every row with a verdict against the same
    result in another table: changed verdicts, moves of 2 sigma or more under
    the same verdict, new rows; the rest counted. A joint fit's phi_c in a
    row's name (it moves with the data) does not make the row new."""
    from dynhet.analysis.restate import compare
    ref = tmp_path / "old.md"
    ref.write_text("| result | paper (section, figure) | paper | ours | verdict | figure | CPU |\n|---|---|---|---|---|---|---|\n"
                   "| θ | 3.2 | 1.47 | 1.52 ± 0.07 | agrees (0.7 σ) | f | 1 |\n"
                   "| γχ | 3.4 | 2.5 | 1.13 ± 0.15 | differs (9.1 σ) | f | 1 |\n"
                   "| ρ with the joint fit's φ_c = 0.8013 | 3.3 | 1.63 | 1.68 ± 0.18 | not judged: χ² | f | 1 |\n"
                   "| κ | 3.3 | 1.8 | 1.71 ± 0.01 | differs (8 σ) | f | 1 |\n"
                   "| Q(t) | 3.1 | figure only | 12 | figure | f | 1 |\n"
                   "| better form | 3.1 | VFT | VFT (χ²/dof 12) | not judged: both | f | 1 |\n"
                   "| φ_c(ε) falls | 3.4 | yes | 0.80, 0.79 | agrees (falls 2.1 σ) | f | 1 |\n"
                   "| τ_B against N | — | — | N 4096: 274 ± 2 | drifting: 2.54 ± 1.1 per doubling of N | f | 1 |\n")
    rows = [{"item": "θ", "ours": "1.53 ± 0.03", "verdict": "agrees (1.9 σ)"},
            {"item": "γχ", "ours": "1.37 ± 0.23", "verdict": "not judged: χ²/dof 9.5"},
            {"item": "ρ with the joint fit's φ_c = 0.8018", "ours": "1.54 ± 0.2", "verdict": "not judged: χ²"},
            {"item": "κ", "ours": "1.75 ± 0.01", "verdict": "differs (5 σ)"},
            {"item": "Q(t)", "ours": "12", "verdict": "figure"},
            {"item": "better form", "ours": "power law (χ²/dof 9.7)", "verdict": "not judged: both"},
            {"item": "φ_c(ε) falls", "ours": "0.80, 0.795", "verdict": "not resolved (falls 1.2 σ)"},
            {"item": "τ_B against N", "ours": "N 4096: 274 ± 2", "verdict": "drifting: 0.67 ± 0.51 per doubling of N"},
            {"item": "d_f'", "ours": "1.1 ± 0.1", "verdict": "differs (4.5 σ)"}]
    out = compare("N = 4096", str(ref), rows)
    body = [l for l in out if l.startswith("| ") and not l.startswith("| result")]
    assert [l.split(" | ")[0][2:] for l in body] == ["γχ", "φ_c(ε) falls", "κ", "better form", "d_f'"]
    assert body[0].endswith("| differs → not judged | 0.9 |")
    assert body[1].endswith("| agrees → not resolved | — |")     # "not resolved" is a verdict too
    body = body[:1] + body[2:]
    assert body[1].endswith("| same verdict, moved | 2.8 |")
    assert body[2].endswith("| same verdict, another value | — |")
    assert "new row" in body[3]
    assert out[-1] == "2 rows changed verdict, 2 rows moved by 2σ or more (or changed, quoting no error) under the same verdict, " \
                      "3 rows stayed within 2σ under the same verdict, 1 row new."   # a drift's rate is not its verdict
