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


def _with_errors(tmp_path):
    """A committed run of the quick study (recorded before the nodes
    published these errors) with xi_lag_err and tau_alpha_t0_err added as
    the recorder writes them: the final record of each series."""
    import os
    import shutil
    import numpy as np
    from dynhet.archive import Archive
    quick = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "results", "quick")
    name = "phi0.8000_eps0.900_n4096_seed1_any"
    if name not in Archive(quick).runs():
        pytest.skip(f"no {name} in {quick}")
    path = tmp_path / "run.h5"
    shutil.copy(Archive(quick).path(name), path)
    with h5py.File(path, "r+") as f:
        for group, like, name_ in (("observables/s4/a0.6", "xi_lag", "xi_lag_err"),
                                   ("observables/overlap/a0.6", "tau_alpha_t0", "tau_alpha_t0_err")):
            src = f[group][like]
            dst = f[group].create_group(name_)
            value = np.full(src["value"].shape, 0.25)
            value.reshape(-1)[0] = np.nan  # one without an error
            dst.create_dataset("value", data=value)
            for k in src:
                if k != "value":
                    f.copy(src[k], dst, k)
            for k, v in src.attrs.items():
                dst.attrs[k] = v
    return str(path)


def _bars(container):
    """The half-lengths of an errorbar container's vertical bars."""
    import numpy as np
    segs = container.lines[2][0].get_segments()
    return np.array([abs(s[1][1] - s[0][1]) / 2 if len(s) == 2 else np.nan for s in segs])  # none at a NaN value


def test_xi_of_t_and_tau_alpha_of_t0_are_drawn_with_their_errors(tmp_path, monkeypatch):
    import numpy as np
    import matplotlib.pyplot as plt
    from matplotlib.container import ErrorbarContainer
    from dynhet.run import open_run
    from dynhet.figures import overlap, s4
    path = _with_errors(tmp_path)
    with open_run(path) as run:
        g = run.s4(0.6)
        fig, ax = plt.subplots()
        s4.plot_xi(ax, g)
        bars = [c for c in ax.containers if isinstance(c, ErrorbarContainer)]
        assert len(bars) == len(g["subbox_per_side"])  # one curve with bars per grid
        gi = int(np.argmax(np.isfinite(g["xi_lag"]).sum(axis=0)))  # the grid with most lags with a xi
        drawn_bars = _bars(bars[gi])
        shown = np.isfinite(drawn_bars)
        assert shown.sum() == np.isfinite(g["xi_lag"][:, gi]).sum() > 0
        assert np.allclose(drawn_bars[shown], np.nan_to_num(g["xi_lag_err"][:, gi])[shown], atol=1e-12)
        plt.close(fig)
    drawn = {}
    monkeypatch.setattr(overlap, "save", lambda fig, run, png, dpi: drawn.setdefault("fig", fig))
    assert overlap.main(path, str(tmp_path / "overlap.png")) == 0
    ax2 = drawn["fig"].axes[1]
    bars = [c for c in ax2.containers if isinstance(c, ErrorbarContainer)]
    with open_run(path) as run:  # the first cutoff's, 0.6: its errors as given
        expected = np.nan_to_num(run.overlap(0.6)["tau_alpha_t0_err"])
    drawn_bars = _bars(bars[0])
    shown = np.isfinite(drawn_bars)
    assert shown.sum() > 1 and np.allclose(drawn_bars[shown], expected[shown], atol=1e-12)
    plt.close(drawn["fig"])
