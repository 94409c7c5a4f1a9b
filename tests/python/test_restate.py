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
