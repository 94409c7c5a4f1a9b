"""results/README.md (archive.results_readme): the studies' archives, and the
single-run checks beside them, each named with its README's title."""
import numpy as np

from dynhet.archive import results_readme


def test_a_check_beside_the_studies_is_listed_with_its_title_and_size(tmp_path):
    d = tmp_path / "checks" / "cr_big"
    d.mkdir(parents=True)
    (d / "README.md").write_text("# Cage-relative relaxation at N = 262144\n\nmore\n")
    import gzip
    import h5py
    with h5py.File(tmp_path / "run.h5", "w") as f:
        f.create_group("provenance").attrs.update({"command": "launch_scripts/run_scene.sh scene.toml", "cpu_s": 7200.0})
        f.create_dataset("pad", data=np.random.default_rng(1).random(3 << 17))   # 3 MiB that do not compress
    (d / "run.h5.gz").write_bytes(gzip.compress((tmp_path / "run.h5").read_bytes()))
    (tmp_path / "checks" / "notes.txt").write_text("a folder without a README is not a check\n")
    text = results_readme(str(tmp_path))
    kib = sum(f.stat().st_size for f in d.iterdir()) / 1024
    import hashlib
    sha = hashlib.sha256((d / "run.h5.gz").read_bytes()).hexdigest()[:16]
    assert (f"- `checks/cr_big`: Cage-relative relaxation at N = 262144 ({kib:.0f} KiB; run.h5.gz sha256 {sha}…; command "
            "`launch_scripts/run_scene.sh scene.toml`; 2.00 CPU-hours; its README.md says how it was made)") in text
    assert f"In all {kib / 1024:.1f} MiB of entries" in text and kib > 2800
    assert text.count("\n- `") == 1
    (d / "run.h5.gz").write_bytes(b"x" * 100)                   # a broken file is said, not a crash
    assert "run.h5.gz not readable" in results_readme(str(tmp_path))
