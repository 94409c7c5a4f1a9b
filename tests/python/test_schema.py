"""The schema check (dynhet.schema, generated from the observables'
declarations in lcmtypes/*.lcm) against a real run's file, and against
copies of it with one thing wrong; and docs/run_h5.md against what the
declarations generate."""
import os
import shutil
import subprocess
import sys

import h5py
import numpy as np
import pytest

from dynhet.archive import Archive

from dynhet import schema

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
# A finished run of the quick study, committed under results/ (all observables but bond breaking).
QUICK = os.path.join(ROOT, "results", "quick")
RUN = (Archive(QUICK).path("phi0.8000_eps0.900_n4096_seed1_any")
       if "phi0.8000_eps0.900_n4096_seed1_any" in Archive(QUICK).runs() else "")


# Datasets declared after the archived run was recorded (the errors of
# tau_alpha(t0) per origin and of xi(t), chi0(t) per lag), each with the
# dataset of the same shape it is the error of. A run recorded now has
# them (check_h5md.py checks the tiny scene's run against the schema).
NEWER = {"overlap": {"tau_alpha_t0_err": "tau_alpha_t0"},
         "s4": {"xi_lag_err": "xi_lag", "chi0_lag_err": "chi0_lag"}}


def add_newer(path):
    """The archived run with the NEWER datasets added, shaped and typed as
    the dataset each is the error of (NaN: no error)."""
    with h5py.File(path, "a") as f:
        for kind, fields in NEWER.items():
            for base in (kind, kind + "_cr"):
                for g in (f[f"observables/{base}"].values() if f"observables/{base}" in f else []):
                    for name, like in fields.items():
                        if like in g and name not in g:
                            f.copy(g[like], g, name)
                            g[name]["value"][...] = np.nan


@pytest.fixture
def run_copy(tmp_path):
    if not os.path.exists(RUN):
        pytest.skip(f"no {RUN}")
    p = tmp_path / "run.h5"
    shutil.copy(RUN, p)
    add_newer(str(p))
    return str(p)


def test_a_real_run_fits_but_for_what_was_declared_after_it(run_copy):
    if not os.path.exists(RUN):
        pytest.skip(f"no {RUN}")
    newer = {name for fields in NEWER.values() for name in fields}
    problems = schema.check(RUN)
    assert problems and all(p.endswith(": missing") and p.split(": ")[0].rsplit("/", 1)[1] in newer
                            for p in problems), problems
    assert schema.check(run_copy) == []


def test_a_missing_dataset_is_refused(run_copy):
    with h5py.File(run_copy, "a") as f:
        del f["observables/chi4/a0.6/tau4"]
    assert schema.check(run_copy) == ["observables/chi4/a0.6/tau4: missing"]


def test_a_missing_group_is_refused(run_copy):
    with h5py.File(run_copy, "a") as f:
        del f["observables/s4/a0.6"]
    assert schema.check(run_copy) == ["observables/s4/a0.6: missing"]


def test_a_misshaped_series_is_refused(run_copy):
    path = "observables/overlap/a0.6/q/value"
    with h5py.File(run_copy, "a") as f:
        v = f[path][()]
        del f[path]
        f[path] = v[:, :-1]  # one lag short of lag_time
    problems = schema.check(run_copy)
    assert len(problems) == 1 and problems[0].startswith(path) and "n_lags" in problems[0]


def test_a_misshaped_flat_array_is_refused(run_copy):
    path = "observables/chi4/a0.6/chi4/value"
    with h5py.File(run_copy, "a") as f:
        v = f[path][()]
        del f[path]
        f[path] = v.transpose(0, 2, 1)  # [record][lag][grid] instead of [record][grid][lag]
    assert any(p.startswith(path) for p in schema.check(run_copy))


def test_a_wrong_dtype_and_attribute_are_refused(run_copy):
    with h5py.File(run_copy, "a") as f:
        g = f["observables/msd"]
        v = g["lag_time"][()]
        del g["lag_time"]
        g["lag_time"] = v.astype(np.float32)
        del g.attrs["fraction_all"]
    problems = schema.check(run_copy)
    assert "observables/msd/lag_time: dtype float32, expected float64" in problems
    assert "observables/msd: attribute fraction_all missing" in problems


def test_every_declared_field_has_unit_and_meaning():
    units = {"length", "time", "particles", "count", "index", "1/length", "length^2", "length^2/time", "1"}
    for d in schema.OBSERVABLES:
        for f in d["fields"]:
            assert f["unit"] in units and f["meaning"], (d["name"], f["name"])


def test_reader_docstrings_come_from_the_declarations():
    import dynhet.run
    doc = dynhet.run.Run.chi4.__doc__
    assert "tau4: series (records, grid) float64 [time]" in doc
    assert dynhet.run.Run.overlap_cr.__doc__.startswith("observables/overlap_cr/a<cutoff>")


def test_run_h5_doc_is_what_the_declarations_generate(tmp_path):
    lcm = sorted(os.path.join(ROOT, "lcmtypes", n) for n in os.listdir(os.path.join(ROOT, "lcmtypes"))
                 if n.endswith(".lcm"))
    out = tmp_path / "run_h5.md"
    subprocess.run([sys.executable, os.path.join(ROOT, "lcmtypes", "gen_observables.py"), "--doc", str(out)] + lcm,
                   check=True)
    with open(os.path.join(ROOT, "docs", "run_h5.md")) as f:
        committed = f.read()
    assert committed == out.read_text(), (
        "docs/run_h5.md is not what lcmtypes/*.lcm declare: run "
        "lcmtypes/gen_observables.py --doc docs/run_h5.md lcmtypes/*.lcm")
