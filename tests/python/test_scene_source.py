"""The scene's defaults and the model's formulas have one source, the C++
description of the scene (common/scene_keys.cpp) and model.hpp: the package
reads them (dynhet.scene) and the study's estimates compute with the rate the
engine is given, never with a copy."""
import math
import os
import re
import subprocess

import pytest

from dynhet import scene
from dynhet.study import estimates
from dynhet.study.paths import SIM

PACKAGE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python", "dynhet")


def engine_check(sc):
    """sim_node --check of scene sc: the kick rate the engine is built with
    (engine_params) and the simulated time, as it prints them."""
    from dynhet.study.toml_io import toml_dump
    r = subprocess.run([SIM, "-", "--check"], input=toml_dump(sc), capture_output=True, text=True, check=True)
    facts = dict(line.split(": ", 1) for line in r.stdout.splitlines() if ": " in line)
    return float(facts["kick_rate"]), float(facts["sim_time"])


SCENES = [
    {},
    {"system": {"packing_fraction": 0.805, "n_particles": 4096}},
    {"system": {"packing_fraction": 0.6, "radius_ratio": 1.0}},
    {"system": {"packing_fraction": 0.76, "radius_ratio": 2.0}, "driving": {"contact_value": "henderson"}},
    {"system": {"packing_fraction": 0.7}, "driving": {"kick_rate": 12.5}},
    {"schedule": {"origins": 4, "origin_spacing": 3.5, "lag_max": 40.0}, "run": {"equilibration_time": 7.0}},
]


@pytest.mark.parametrize("sc", SCENES)
def test_the_estimates_use_the_kick_rate_and_run_length_of_the_engine(sc):
    rate, sim_time = engine_check(sc)
    assert estimates.kick_rate(sc) == rate  # the same double: one formula
    r = scene.resolved(sc)
    assert math.isclose(r["model"]["sim_time"], sim_time, rel_tol=1e-5)  # --check prints %g
    assert r["model"]["sim_time"] == r["run"]["equilibration_time"] + r["run"]["production_time"]
    cpu, _ = estimates.estimate(sc, 1)
    n = r["system"]["n_particles"]
    events = n * r["model"]["collision_frequency"] * r["model"]["sim_time"]
    assert cpu > events / estimates.events_per_second(n)


def test_the_enskog_rate_grows_with_phi_and_the_paper_formula_holds_for_one_species():
    # omega = 2.59 phi G_c / sqrt(pi), G_c Henderson's for r2/r1 = 1 (the
    # mixture's recipe reduces to it); the numbers are sim_node's
    for phi in (0.3, 0.7, 0.8):
        r = scene.resolved({"system": {"packing_fraction": phi, "radius_ratio": 1.0}})["model"]
        g = (1 - 7 * phi / 16) / (1 - phi) ** 2
        assert math.isclose(r["contact_value"], g, rel_tol=1e-12)
        assert math.isclose(r["kick_rate"], 2.59 * phi * g / math.sqrt(math.pi), rel_tol=1e-12)
    rates = [scene.resolved({"system": {"packing_fraction": p}})["model"]["kick_rate"] for p in (0.6, 0.7, 0.8)]
    assert rates == sorted(rates)


def test_defaults_are_the_simulators():
    d = scene.resolved({})
    for table, keys in d.items():
        if table == "model":
            continue
        for key, value in keys.items():
            assert scene.default(table, key) == value, f"{table}.{key}"
    assert d["model"]["radius"] == [1.0, scene.default("system", "radius_ratio")]


def test_a_scene_the_simulator_refuses_is_refused_with_its_reasons():
    with pytest.raises(scene.SceneError, match="system.restitution: value 1.5 is not allowed"):
        scene.resolved({"system": {"restitution": 1.5}})


def test_no_scene_default_or_model_formula_is_copied_into_the_package():
    # The model's constants (2.59 of omega, 1.43 of r2/r1, 9/16 of g_ij,
    # 7 phi/16 of Henderson's g) and `.get(<scene key>, <number>)` of a scene
    # table stay in C++; the package asks dynhet.scene.
    keys = {k for t, ks in scene.DEFAULTS.items() if t != "model" for k in ks}
    copied = re.compile(r"\b(2\.59|1\.43)\b|9 / 16|7 \* phi / 16|\.get\(\"(" + "|".join(sorted(keys))
                        + r")\", *\[?[-0-9.]")
    found = []
    for base, _, files in os.walk(PACKAGE):
        for f in files:
            if f.endswith(".py") and f not in ("_scene.py", "_observables.py"):
                with open(os.path.join(base, f)) as fh:
                    for i, line in enumerate(fh, 1):
                        code = line.split("#", 1)[0]
                        if copied.search(code):
                            found.append(f"{os.path.relpath(os.path.join(base, f), PACKAGE)}:{i}: {line.strip()}")
    assert not found, "scene defaults or model formulas copied:\n" + "\n".join(found)


ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
BEGIN, END = "<!-- begin: sim_node --scene-reference -->\n", "<!-- end: sim_node --scene-reference -->"


def scene_reference():
    return subprocess.run([SIM, "--scene-reference"], capture_output=True, text=True, check=True).stdout


def described_keys():
    keys, table = set(), None
    for line in scene_reference().splitlines():
        if m := re.match(r"### \[(\w+)\]$", line):
            table = m.group(1)
        elif m := re.match(r"\| `(\w+)` \|", line):
            keys.add((table, m.group(1)))
    return keys


def test_the_scene_reference_in_the_docs_is_the_descriptions():
    with open(os.path.join(ROOT, "docs", "scenes.md")) as f:
        text = f.read()
    assert BEGIN in text and END in text, "docs/scenes.md has no scene reference section"
    section = text.split(BEGIN, 1)[1].split(END, 1)[0]
    assert section == scene_reference(), (
        "docs/scenes.md's scene reference is not what common/scene_keys.cpp describes: put the output of "
        "sim_node --scene-reference between its markers")


def test_the_default_scene_lists_every_key_the_description_has():
    # set, or as a comment "# key = ..." under its table
    listed, table = set(), None
    with open(os.path.join(ROOT, "scenes", "default.toml")) as f:
        for line in f:
            if m := re.match(r"\[(\w+)\]", line):
                table = m.group(1)
            elif table and (m := re.match(r"#? ?(\w+) *=", line)):
                listed.add((table, m.group(1)))
    described = described_keys()
    assert len(described) > 50
    assert listed == described, (f"scenes/default.toml lacks {sorted(described - listed)}; "
                                 f"lists keys no scene has: {sorted(listed - described)}")
