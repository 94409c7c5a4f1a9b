"""results/README.md (archive.results_readme): the studies' archives, and the
single-run checks beside them, each named with its README's title."""
from dynhet.archive import results_readme


def test_a_check_beside_the_studies_is_listed_with_its_title_and_size(tmp_path):
    d = tmp_path / "checks" / "cr_big"
    d.mkdir(parents=True)
    (d / "README.md").write_text("# Cage-relative relaxation at N = 262144\n\nmore\n")
    (d / "run.h5.gz").write_bytes(b"x" * (3 << 20))
    (tmp_path / "checks" / "notes.txt").write_text("a folder without a README is not a check\n")
    text = results_readme(str(tmp_path))
    assert "- `checks/cr_big`: Cage-relative relaxation at N = 262144 (3.0 MiB;" in text
    assert "In all 3.0 MiB of entries" in text
    assert text.count("\n- `") == 1
