"""dynhet.run on a run.h5 written here in the recorder's layout (H5MD time
series: step, time, value [record][...]; fixed datasets; attributes): the
reader gives each series' last record, the fixed arrays as they are, errors
beside values, the cutoffs, and names what exists when asked for what does
not."""
import math

import h5py
import numpy as np
import pytest

import dynhet


def series(g, name, records, times):
    s = g.create_group(name)
    s.create_dataset("step", data=np.arange(len(records)))
    s.create_dataset("time", data=np.asarray(times, float))
    s.create_dataset("value", data=np.asarray(records, float))


@pytest.fixture
def run_file(tmp_path):
    path = tmp_path / "run.h5"
    lag = np.geomspace(0.1, 10, 5)
    with h5py.File(path, "w") as f:
        f.attrs.update(complete=1, missing="", run_id=7)
        f.create_group("parameters/system").attrs.update(n_particles=300, packing_fraction=0.7, restitution=0.9, seed=3)
        for a, tau in (("a0.6", 1.5), ("a1", 3.0)):
            g = f.create_group(f"observables/overlap/{a}")
            g.attrs["cutoff_a"] = float(a[1:])
            g.create_dataset("lag_time", data=lag)
            q_last = np.exp(-lag / tau)
            series(g, "q", [q_last + 0.1, q_last], [5.0, 10.0])
            series(g, "q_err", [0.02 * np.ones(5), 0.01 * np.ones(5)], [5.0, 10.0])
            series(g, "tau_alpha", [tau + 1, tau], [5.0, 10.0])
            series(g, "tau_alpha_err", [0.3, 0.1], [5.0, 10.0])
        c = f.create_group("observables/chi4/a0.6")
        c.attrs["estimator"] = b"chi4: the pooled estimator"
        series(c, "chi4", [np.ones((2, 5)), 2 * np.ones((2, 5))], [5.0, 10.0])
        series(c, "tau4_interior", [[1, 0]], [10.0])
        m = f.create_group("observables/msd")
        series(m, "diffusion", [0.5, 0.25], [5.0, 10.0])
        series(m, "diffusion_err", [0.05, 0.02], [5.0, 10.0])
        series(m, "empty", np.zeros((0, 3)), [])
    return path, lag


def test_last_records_fixed_arrays_and_metadata(run_file):
    path, lag = run_file
    with dynhet.open_run(path) as run:
        assert run.complete and run.run_id == 7 and run.n_particles == 300 and run.seed == 3
        assert run.packing_fraction == 0.7 and run.restitution == 0.9
        assert run.observables() == ["chi4", "msd", "overlap"]
        assert run.cutoffs() == [0.6, 1.0]
        ov = run.overlap()
        np.testing.assert_array_equal(ov.lag_time, lag)
        np.testing.assert_allclose(ov.q, np.exp(-lag / 1.5))        # the last record, not the first
        assert run.tau_alpha() == (1.5, 0.1)
        assert run.tau_alpha(1.0) == (3.0, 0.1)
        q, e = ov.value_error("q")
        np.testing.assert_allclose(e, 0.01)
        t, hist = ov.history("tau_alpha")
        np.testing.assert_array_equal(t, [5.0, 10.0])
        np.testing.assert_array_equal(hist, [2.5, 1.5])
        c = run.chi4()
        assert c.chi4.shape == (2, 5) and float(c.chi4[0, 0]) == 2.0
        np.testing.assert_array_equal(c.tau4_interior, [1, 0])
        assert c.attrs["estimator"].startswith("chi4: the pooled")     # bytes become str
        d, de = run.msd().value_error("diffusion")
        assert float(d) == 0.25 and float(de) == 0.02
        assert np.all(np.isnan(run.msd().empty)) and run.msd().empty.shape == (3,)  # no record yet
        v, e = c.value_error("tau4_interior")                           # no _err: NaN beside it
        assert np.all(np.isnan(e))


def test_what_does_not_exist_is_named(run_file):
    path, _ = run_file
    with dynhet.open_run(path) as run:
        with pytest.raises(KeyError, match="no observable 's4'; the run has chi4, msd, overlap"):
            run.s4()
        with pytest.raises(KeyError, match=r"no cutoff a = 2.0 .*it has \[0.6, 1.0\]"):
            run.overlap(2.0)
        with pytest.raises(AttributeError, match="no dataset 'beta'; it has lag_time, q, q_err"):
            run.overlap().beta
        with pytest.raises(ValueError, match="fixed, not a series"):
            run.overlap().history("lag_time")


def test_incomplete_run_says_what_is_missing(tmp_path):
    path = tmp_path / "run.h5"
    with h5py.File(path, "w") as f:
        f.attrs.update(complete=0, missing=b"s4 results")
    with pytest.warns(dynhet.run.IncompleteRunWarning, match="s4 results"):
        run = dynhet.open_run(path)
    assert not run.complete and run.missing == "s4 results" and run.observables() == []
    assert math.isnan(run.packing_fraction) and "incomplete: s4 results" in repr(run)
    run.close()


def test_a_file_that_is_no_run_is_named(tmp_path):
    bad = tmp_path / "nothing.h5"
    bad.write_text("not hdf5")
    with pytest.raises(OSError, match="nothing.h5 is not an HDF5 file"):
        dynhet.open_run(bad)
