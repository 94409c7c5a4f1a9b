"""A scene as the simulator reads it. Its defaults and what the simulator
derives from it (radii and masses, the box, G_c, the Enskog collision
frequency, the kick rate and amplitude, the frames, the simulated time) come
from the C++ description of the scene (common/scene_keys.cpp, the defaults
of scene.hpp, the formulas of model.hpp), never from copies here:

    from dynhet import scene
    scene.default("system", "packing_fraction")    # 0.7, the default scene's
    r = scene.resolved({"system": {"packing_fraction": 0.8}})
    r["driving"]["kick_rate"], r["model"]["kick_rate"]   # "enskog", its number

DEFAULTS is the default scene resolved at build time (sim_node - --resolved
into _scene.py); resolved() asks the build's sim_node for any other scene,
so a scene the simulator refuses raises SceneError with its reasons.
"""
import copy
import functools
import subprocess
import tomllib

from ._scene import DEFAULTS_TOML
from .study.paths import SIM
from .study.toml_io import toml_dump

DEFAULTS = tomllib.loads(DEFAULTS_TOML)


class SceneError(ValueError):
    """A scene the simulator refuses; the message is sim_node's, key by key."""


def default(table, key):
    """The default of a scene key (e.g. "observables", "cutoff_a" -> [0.6])."""
    return copy.deepcopy(DEFAULTS[table][key])


def resolved(scene):
    """The scene (tables as a dict, or TOML text) with every key, the
    defaults filled in, and its [model] table, as sim_node --resolved
    prints them."""
    text = scene if isinstance(scene, str) else toml_dump(scene)
    return copy.deepcopy(_resolved(text))


@functools.lru_cache(maxsize=4096)
def _resolved(text):
    r = subprocess.run([SIM, "-", "--resolved"], input=text, capture_output=True, text=True)
    if r.returncode != 0:
        raise SceneError(r.stderr.strip() or f"{SIM} - --resolved: exit {r.returncode}")
    return tomllib.loads(r.stdout)
