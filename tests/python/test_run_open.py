"""dynhet.open_run opens a run (its directory or its run.h5) and refuses
anything else at open with what it found: another HDF5 file (a checkpoint,
a study.h5), a truncated file, a file that is not HDF5; an incomplete run
warns unless asked for; a cutoff is matched within rounding. A study query
for a series the study lacks says so."""
import types
import warnings

import h5py
import numpy as np
import pytest

import dynhet
from dynhet.analysis.study import Analysis
from dynhet.run import IncompleteRunWarning, RunFileError


def write_run(path, complete=1, missing=""):
    with h5py.File(path, "w") as f:
        f.attrs.update(complete=complete, missing=missing, run_id=7)
        f.create_group("parameters/system").attrs.update(n_particles=300, packing_fraction=0.7)
        for a in ("a0.6", "a1"):
            g = f.create_group(f"observables/overlap/{a}")
            g.create_dataset("lag_time", data=np.geomspace(0.1, 10, 5))
            g.create_dataset("big", data=np.arange(200000, dtype=float))  # a file worth truncating
    return path


def test_a_run_directory_or_its_file(tmp_path):
    write_run(tmp_path / "run.h5")
    with dynhet.open_run(tmp_path) as run:
        assert run.path == str(tmp_path / "run.h5") and run.complete
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty" / "scene.toml").write_text("")
    with pytest.raises(RunFileError, match=r"holds no run.h5 \(it holds scene.toml\)"):
        dynhet.open_run(tmp_path / "empty")


def test_other_hdf5_files_are_refused_with_what_they_hold(tmp_path):
    with h5py.File(tmp_path / "checkpoint.h5", "w") as f:
        f.attrs["format"] = "dynhet checkpoint 1"
        f.attrs["run_id"] = 7
        f.create_group("particles")
    with pytest.raises(RunFileError, match=r"is not a run file .*groups \[particles\].*'dynhet checkpoint 1'.*checkpoint"):
        dynhet.open_run(tmp_path / "checkpoint.h5")
    with h5py.File(tmp_path / "study.h5", "w") as f:
        f.attrs["study_dir"] = "runs/x"
        f.create_group("points")
        f.create_group("fits")
    with pytest.raises(RunFileError, match=r"is not a run file .*study.h5: dynhet.open_study"):
        dynhet.open_run(tmp_path / "study.h5")


def test_a_truncated_file_and_a_file_not_hdf5_are_said_in_words(tmp_path):
    full = write_run(tmp_path / "run.h5").read_bytes()
    cut = tmp_path / "cut.h5"
    cut.write_bytes(full[:len(full) // 2])
    with pytest.raises(RunFileError, match=rf"is truncated: {len(full) // 2} bytes on disk of the {len(full)}"):
        dynhet.open_run(cut)
    text = tmp_path / "notes.h5"
    text.write_text("not a run")
    with pytest.raises(RunFileError, match=r"is not an HDF5 file \(9 bytes, beginning b'not a ru'\)"):
        dynhet.open_run(text)


def test_an_incomplete_run_warns_unless_allowed(tmp_path):
    write_run(tmp_path / "run.h5", complete=0, missing="the s4 node's results")
    with pytest.warns(IncompleteRunWarning, match="an incomplete run \\(the s4 node's results\\)"):
        dynhet.open_run(tmp_path).close()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with dynhet.open_run(tmp_path, allow_incomplete=True) as run:
            assert not run.complete and "incomplete" in repr(run)


def test_cutoffs_match_within_rounding_and_a_miss_is_said_in_full(tmp_path):
    write_run(tmp_path / "run.h5")
    with dynhet.open_run(tmp_path) as run:
        assert run.overlap(a=0.60000001).name == "overlap/a0.6"
        assert run.overlap(a=1 + 1e-9).name == "overlap/a1"
        with pytest.raises(KeyError, match=r"no cutoff a = 0.61 .*it has \[0.6, 1.0\]"):
            run.overlap(a=0.61)


def test_a_series_the_study_lacks_is_said(tmp_path):
    A = Analysis.__new__(Analysis)  # its points alone: what a query reads
    A.points = {("neighbours", 0.9, 0.7, 300): types.SimpleNamespace(phi=0.7, N=300, mean=lambda f: (2.0, 0.1, 0.1, 2))}
    phi, v, e, seeds = A.against_phi("tau_alpha")
    assert list(phi) == [0.7] and list(v) == [2.0] and list(seeds) == [2]
    with pytest.raises(KeyError, match=r"no complete run of the series pairs = 'neighbours', eps = 0.8 .*"
                                       r"it has pairs = 'neighbours', eps = 0.9, N = 300"):
        A.against_phi("tau_alpha", eps=0.8)
