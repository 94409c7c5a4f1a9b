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
    assert "| d_f' | 0.95 ± 0.09; differs (7.4 σ) | 1.5 ± 0.2; agrees (0.5 σ) | now agrees |" in text
    assert "| φ_c (own) | 0.8004 ± 0.0005; differs (40.0 σ); χ²/dof 22 | 0.8004 ± 0.0005; not judged: on the edge" in text
    assert "now not judged |" in text
    assert "| gone row | 1.66 ± 0.005; differs (26.6 σ) | — | no such row now |" in text
    assert "3 rows differed; 0 still differ, 2 have another verdict now, 1 have no row now." in text
