"""dynhet.figures.run_figures (launch_scripts/plot_run.py): every figure of
a run in one process. A figure that fails is named and the status says so;
the figures after it are still tried; bad arguments are refused by name.
(The figures of a real run, all six, are checked by e2e_tiny.)"""
import h5py
import matplotlib
import pytest

matplotlib.use("Agg")

from dynhet.figures.run_figures import draw_all  # noqa: E402


def test_a_failing_figure_is_named_and_the_rest_are_still_tried(tmp_path, capsys):
    path = tmp_path / "run.h5"
    with h5py.File(path, "w") as f:        # chi4 results without their datasets
        f.attrs["complete"] = 1
        f.create_group("observables/chi4/a0.6")
    assert draw_all(str(path), str(tmp_path)) == 1
    err = capsys.readouterr().err
    assert "plot_chi4: failed: KeyError" in err
    assert "has no overlap results" in err   # overlap, drawn after chi4, was still tried
    assert not list(tmp_path.glob("*.png"))


def test_bad_arguments_are_refused_by_name(tmp_path):
    with pytest.raises(OSError, match="no such directory"):
        draw_all(str(tmp_path / "run.h5"), str(tmp_path / "nowhere"))
    (tmp_path / "run.h5").write_text("not a run")
    with pytest.raises(OSError, match="is not an HDF5 file"):
        draw_all(str(tmp_path / "run.h5"), str(tmp_path))
