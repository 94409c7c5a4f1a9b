"""The reader as freud's and MDAnalysis's users expect it: one number is a
float, every dataset is tab-completable and documented (shape, unit,
meaning), every group is an xarray.Dataset with named dimensions, and a
study's series are named fields. On a committed run of the quick study
(results/quick), so no simulation is needed."""
import glob
import os
import warnings

import numpy as np
import pytest

import dynhet
from dynhet.archive import Archive

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
_QUICK = Archive(os.path.join(ROOT, "results", "quick"))
ENTRIES = [_QUICK.path(n) for n in sorted(_QUICK.runs())]
pytestmark = pytest.mark.skipif(not ENTRIES, reason="results/quick holds no run")


def run():
    return dynhet.open_run(ENTRIES[0])


def test_one_number_is_a_float():
    with run() as r:
        ov = r.overlap()
        assert type(ov.tau_alpha) is float and type(ov["beta"]) is float
        tau, err = ov.value_error("tau_alpha")
        assert (type(tau), type(err)) == (float, float) and (tau, err) == r.tau_alpha()
        q, q_err = ov.value_error("q")
        assert q.shape == q_err.shape == ov.lag_time.shape   # an array stays an array


def test_datasets_complete_and_documented():
    with run() as r:
        ch = r.chi4()
        assert {"chi4", "chi4_err", "lag_time", "subbox_particles", "tau4"} <= set(dir(ch))
        assert ch.unit("lag_time") == "time" and ch.unit("chi4") == "1"
        assert "chi4" in ch.describe("chi4") and "(records, grid, lag)" in ch.describe("chi4")
        assert "lag_time" in dynhet.run.Run.chi4.__doc__


def test_to_xarray_named_dimensions_units_and_coordinates():
    with run() as r:
        ch = r.chi4()
        ds = ch.to_xarray()
        assert ds["chi4"].dims == ("grid", "lag")
        assert np.array_equal(ds["chi4"].values, ch.chi4, equal_nan=True)
        assert np.array_equal(ds["lag"].values, ch.lag_time) and np.array_equal(ds["grid"].values, ch.subbox_particles)
        assert ds["chi4"].attrs["units"] == "1" and ds["lag_time"].attrs["units"] == "time"
        assert float(ds.attrs["cutoff_a"]) == 0.6
        h = r.overlap().to_xarray(history=True)   # an archive entry: the final record only
        assert h["tau_alpha"].dims == ("record",) and h.sizes["record"] == 1
        assert float(h["tau_alpha"][-1]) == r.overlap().tau_alpha


def test_study_series_are_named_and_one_name_per_quantity():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        s = dynhet.open_study(os.path.join(ROOT, "results", "quick"))
    pairs = s.points and next(iter(s.points))[0]
    got = s.against_phi("tau_alpha", pairs=pairs)
    assert got.phi.shape == got.value.shape == got.error.shape == got.seeds.shape
    phi, value, error, seeds = got                    # still unpacks as before
    assert np.array_equal(phi, got.phi)
    d1, d2 = s.against_phi("diffusion", pairs=pairs), s.against_phi("D", pairs=pairs)   # msd's name, and the old one
    assert np.array_equal(d1.value, d2.value)
    with pytest.raises(KeyError, match="no complete run of the series"):
        s.against_phi("tau_alpha", pairs=pairs, eps=0.123)
