"""The study file: axes, series, overrides and run lengths, checked; its points and each point's scene."""
import copy
import math
import os
import tomllib

from .. import schema
from ..scene import default
from .toml_io import read_toml


class StudyError(Exception):
    pass


class StudyInterrupted(Exception):
    pass


AXES = {  # axis -> (scene table, key, type)
    "packing_fraction": ("system", "packing_fraction", float),
    "restitution": ("system", "restitution", float),
    "n_particles": ("system", "n_particles", int),
    "seed": ("system", "seed", int),
    "pairs": ("driving", "pairs", str),
}
RUN_LENGTH_KEYS = {
    "tau_alpha": str,  # "scene" | "pilot" | "interpolate"
    "unit": str,  # "tau_alpha" | "tau_alpha_cr": the relaxation time the run lengths are counted in
    "equilibration_tau": float,
    "lag_max_tau": float,
    "lag_min_tau": float,
    "origin_spacing_tau": float,
    "origins": int,
    "pilot_particles": int,
    "pilot_margin": float,
    "max_attempts": int,
    "tau_guess": list,
    # The equilibration's own unit ("" = unit): long enough for the structure
    # (tau_alpha^CR) while production and lags count the standard tau_alpha,
    # which falls with N. A second pilot measures it, at pilot_particles_cr.
    "equilibration_unit": str,
    "pilot_particles_cr": int,
    "tau_guess_cr": list,
}
RUN_LENGTH_DEFAULTS = dict(tau_alpha="scene", unit="tau_alpha", equilibration_tau=10.0, lag_max_tau=4.0, lag_min_tau=0.02,
                           origin_spacing_tau=1.0, origins=8, pilot_particles=2048, pilot_margin=1.2, max_attempts=3,
                           tau_guess=[], equilibration_unit="", pilot_particles_cr=4096, tau_guess_cr=[])


def check_type(where, v, typ):
    if typ is float:
        ok = isinstance(v, (int, float)) and not isinstance(v, bool)
    else:
        ok = isinstance(v, typ) and not (typ is int and isinstance(v, bool))
    if not ok:
        raise StudyError(f"{where}: value {v!r} is {type(v).__name__}, expected {typ.__name__}")
    return float(v) if typ is float else v


class Study:
    def __init__(self, path, base_scene=None):
        """base_scene: read the base scene from this file instead (a study
        directory's copy, for its tasks wherever they run)."""
        self.path = os.path.abspath(path)
        try:
            self.text = open(self.path, "rb").read()
            data = tomllib.loads(self.text.decode())
        except FileNotFoundError:
            raise StudyError(f"{path}: no such study file")
        except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
            raise StudyError(f"{path}: not valid TOML: {e}")
        self.errors = []
        known = {"study", "scene", "axes", "series", "run_length", "override"}
        for k in data:
            if k not in known:
                self.errors.append(f"{k}: unknown key or table; known: {', '.join(sorted(known))}")
        st = data.get("study", {})
        for k in st:
            if k not in ("name", "description", "scene", "prepared_states", "run_plots", "archive"):
                self.errors.append(f"study.{k}: unknown key; known keys in [study]: name, description, scene, "
                                   "prepared_states, run_plots, archive")
        # Each run's own figures (run_scene.sh's PNGs); the study's analysis
        # draws its figures either way.
        self.run_plots = st.get("run_plots", True)
        if not isinstance(self.run_plots, bool):
            self.errors.append(f"study.run_plots: value {self.run_plots!r} must be true or false")
            self.run_plots = True
        # The results archive each complete run is reduced into (dynhet.archive),
        # relative to the repository: "results/<name>"; none if not given.
        self.archive = st.get("archive")
        if self.archive is not None and (not isinstance(self.archive, str) or not self.archive):
            self.errors.append(f"study.archive: value {self.archive!r} must be a directory (a non-empty string, "
                               "e.g. \"results/<name>\")")
            self.archive = None
        self.description = st.get("description", "")
        # true or "compressed": compression once per (N, phi, ratio, seed);
        # "equilibrated": also the equilibration, once per run dynamics
        # (extended, never repeated, when a run needs more); false: neither.
        ps = st.get("prepared_states", True)
        if not (isinstance(ps, bool) or ps in ("compressed", "equilibrated")):
            self.errors.append(f"study.prepared_states: value {ps!r} must be true, false, \"compressed\" or "
                               "\"equilibrated\"")
            ps = True
        self.prepared_states = {True: "compressed", False: None}.get(ps, ps) if isinstance(ps, bool) else ps
        self.equilibrated_states = self.prepared_states == "equilibrated"
        self.name = st.get("name", os.path.splitext(os.path.basename(path))[0])
        if not isinstance(self.name, str) or not self.name or "/" in self.name:
            self.errors.append(f"study.name: value {self.name!r} must be a non-empty string without '/'")
        # The base scene: a path (relative to the study file) or an inline [scene] table.
        if "scene" in st and "scene" in data:
            self.errors.append("study.scene: give the base scene as a path or as a [scene] table, not both")
        if base_scene:
            self.base = read_toml(base_scene)
        elif "scene" in st:
            if not isinstance(st["scene"], str):
                self.errors.append(f"study.scene: value {st['scene']!r} must be a path (string)")
                self.base = {}
            else:
                sp = os.path.join(os.path.dirname(self.path), st["scene"])
                try:
                    self.base = read_toml(sp)
                except FileNotFoundError:
                    self.errors.append(f"study.scene: no scene file {sp}")
                    self.base = {}
                except tomllib.TOMLDecodeError as e:
                    self.errors.append(f"study.scene: {sp} is not valid TOML: {e}")
                    self.base = {}
        elif "scene" in data:
            self.base = data["scene"]
            if not isinstance(self.base, dict):
                self.errors.append("scene: must be a table of scene tables ([scene.system], ...)")
                self.base = {}
        else:
            self.base = {}
        # [axes]: one product of axes; or [[series]]: several, the runs their union.
        if "axes" in data and "series" in data:
            self.errors.append("series: give [axes] or [[series]], not both")
        blocks = [("axes", data.get("axes", {}))]
        if "series" in data:
            if not isinstance(data["series"], list):
                self.errors.append("series: must be an array of tables ([[series]])")
            else:
                blocks = [(f"series[{i}]", b) for i, b in enumerate(data["series"])]
        self.series = [self.read_axes(where, b) for where, b in blocks]
        self.axes = {}  # every value of each axis over all series
        for ax in self.series:
            for k, vals in ax.items():
                self.axes.setdefault(k, [])
                self.axes[k] += [v for v in vals if v not in self.axes[k]]
        rl = dict(RUN_LENGTH_DEFAULTS)
        for k, v in data.get("run_length", {}).items():
            if k not in RUN_LENGTH_KEYS:
                self.errors.append(f"run_length.{k}: unknown key; known: {', '.join(RUN_LENGTH_KEYS)}")
                continue
            try:
                rl[k] = check_type(f"run_length.{k}", v, RUN_LENGTH_KEYS[k])
            except StudyError as e:
                self.errors.append(str(e))
        if rl["tau_alpha"] not in ("scene", "pilot", "interpolate"):
            self.errors.append(f"run_length.tau_alpha: value {rl['tau_alpha']!r} is not allowed; "
                               'allowed: "scene" (the scene\'s own times), "pilot", "interpolate"')
        if rl["unit"] not in ("tau_alpha", "tau_alpha_cr"):
            self.errors.append(f"run_length.unit: value {rl['unit']!r} is not allowed; allowed: \"tau_alpha\", "
                               '"tau_alpha_cr" (the cage-relative tau_alpha, which does not fall with N)')
        if rl["equilibration_unit"] not in ("", "tau_alpha", "tau_alpha_cr"):
            self.errors.append(f"run_length.equilibration_unit: value {rl['equilibration_unit']!r} is not allowed; "
                               'allowed: "tau_alpha", "tau_alpha_cr" (default: run_length.unit)')
        rl["equilibration_unit"] = rl["equilibration_unit"] or rl["unit"]
        if not (1.0 <= rl["pilot_margin"] <= 10.0):
            self.errors.append(f"run_length.pilot_margin: value {rl['pilot_margin']} is not allowed; allowed: 1 to 10")
        for k in ("equilibration_tau", "lag_max_tau", "lag_min_tau", "origin_spacing_tau"):
            if not (rl[k] > 0 and math.isfinite(rl[k])):
                self.errors.append(f"run_length.{k}: value {rl[k]} must be > 0")
        if rl["lag_min_tau"] >= rl["lag_max_tau"]:
            self.errors.append("run_length.lag_min_tau: must be smaller than run_length.lag_max_tau")
        for k, lo in (("origins", 1), ("pilot_particles", 100), ("max_attempts", 1)):
            if rl[k] < lo:
                self.errors.append(f"run_length.{k}: value {rl[k]} must be >= {lo}")
        for table in ("tau_guess", "tau_guess_cr"):
            guesses = []
            for g in rl[table]:
                if (not isinstance(g, list) or len(g) != 2 or not all(isinstance(x, (int, float)) for x in g)
                        or not g[1] > 0):
                    self.errors.append(f"run_length.{table}: entry {g!r} must be [phi, tau_alpha > 0]")
                    continue
                guesses.append((float(g[0]), float(g[1])))
            rl[table] = sorted(guesses)
        self.run_length = rl
        self.overrides = []
        for i, o in enumerate(data.get("override", [])):
            where = f"override[{i}]"
            if not isinstance(o, dict) or set(o) - {"when", "set"} or "set" not in o:
                self.errors.append(f"{where}: an override is {{when = {{axis = value, ...}}, set = {{table = {{key = value}}}}}}")
                continue
            when = o.get("when", {})
            for k, v in when.items():
                if k not in AXES:
                    self.errors.append(f"{where}.when.{k}: unknown axis; known: {', '.join(AXES)}")
                elif k in self.axes and check_type(f"{where}.when.{k}", v, AXES[k][2]) not in self.axes[k]:
                    self.errors.append(f"{where}.when.{k}: value {v!r} is not on axis {k} {self.axes[k]}")
            if not isinstance(o["set"], dict) or not all(isinstance(t, dict) for t in o["set"].values()):
                self.errors.append(f"{where}.set: must be scene tables, e.g. {{system = {{n_particles = 4096}}}}")
                continue
            self.overrides.append((when, o["set"]))
        if self.errors:
            raise StudyError(f"{path}: invalid study ({len(self.errors)} problem"
                             f"{'s' if len(self.errors) > 1 else ''}):\n  " + "\n  ".join(self.errors))

    def read_axes(self, where, block):
        axes = {}
        if not isinstance(block, dict):
            self.errors.append(f"{where}: must be a table of axes")
            return axes
        for k, v in block.items():
            if k not in AXES:
                self.errors.append(f"{where}.{k}: unknown axis; known: {', '.join(AXES)}")
                continue
            if not isinstance(v, list) or not v:
                self.errors.append(f"{where}.{k}: value {v!r} must be a non-empty array")
                continue
            try:
                vals = [check_type(f"{where}.{k}", x, AXES[k][2]) for x in v]
            except StudyError as e:
                self.errors.append(str(e))
                continue
            if len(set(vals)) != len(vals):
                self.errors.append(f"{where}.{k}: each value may be listed once")
                continue
            axes[k] = vals
        return axes

    def base_value(self, axis):
        table, key, _ = AXES[axis]
        return self.base.get(table, {}).get(key, default(table, key))

    def points(self):
        """Every run: a dict of axis values, in a fixed order (phi slowest)."""
        names = list(AXES)
        runs = []
        for ax in self.series:
            block = [{}]
            for a in names:
                block = [dict(r, **{a: v}) for r in block for v in ax.get(a, [self.base_value(a)])]
            runs += [r for r in block if r not in runs]
        # Overrides of an axis' own key (a larger N at low phi) show in the point.
        for r in runs:
            for when, st in self.overrides:
                if self.matches(r, when):
                    for a, (table, key, typ) in AXES.items():
                        if key in st.get(table, {}):
                            r[a] = typ(st[table][key])
        order = ["pairs", "restitution", "n_particles", "packing_fraction", "seed"]
        return sorted(runs, key=lambda r: tuple(r[a] for a in order))

    @staticmethod
    def matches(p, when):
        return all(p[k] == (float(v) if AXES[k][2] is float else v) for k, v in when.items())

    def run_name(self, p):
        s = f"phi{p['packing_fraction']:.4f}_eps{p['restitution']:.3f}_n{p['n_particles']}_seed{p['seed']}"
        if "pairs" in self.axes:
            s += f"_{p['pairs']}"
        return s

    def series_key(self, p):  # points whose tau_alpha may be interpolated in phi
        return (p["restitution"], p["pairs"], p["n_particles"])

    def split_units(self):
        """Whether the equilibration counts another tau_alpha than production."""
        return self.run_length["equilibration_unit"] != self.run_length["unit"]

    def scene(self, p, tau=None, pilot=False, tau_eq=None, unit=None):
        """The scene of run p as tables; with tau, run lengths in units of it,
        the equilibration in units of tau_eq where given (the equilibration's
        own unit); unit: the pilot's (default run_length.unit)."""
        unit = unit or self.run_length["unit"]
        sc = copy.deepcopy(self.base)
        for a, (table, key, _) in AXES.items():
            sc.setdefault(table, {})[key] = p[a]
        for when, st in self.overrides:
            if self.matches(p, when):
                for table, kv in st.items():
                    sc.setdefault(table, {}).update(kv)
        if tau is not None:
            rl = self.run_length
            eq, origins, lag_max = rl["equilibration_tau"], rl["origins"], rl["lag_max_tau"]
            if pilot:  # short and small: only tau_alpha (or tau_alpha^CR) is wanted
                eq, origins = min(eq, 5.0), min(origins, 4)
                cap = rl["pilot_particles_cr"] if unit != rl["unit"] else rl["pilot_particles"]
                sc["system"]["n_particles"] = min(int(sc["system"]["n_particles"]), cap)
                sc["observables"] = {"compute": ["overlap"], "cutoff_a": self.cutoffs(sc)}
                for t in ("chi4", "s4", "clusters", "msd", "displacement"):
                    sc.pop(t, None)
            sc.setdefault("run", {})["equilibration_time"] = round(eq * (tau_eq if tau_eq and not pilot else tau), 6)
            sc["run"].pop("production_time", None)
            sched = sc.setdefault("schedule", {})
            sched["origins"] = origins
            sched["origin_spacing"] = round(rl["origin_spacing_tau"] * tau, 6)
            sched["lag_min"] = round(rl["lag_min_tau"] * tau, 6)
            sched["lag_max"] = round(lag_max * tau, 6)
        if unit == "tau_alpha_cr" and (pilot or not self.split_units()):
            # lengths in tau_alpha^CR: every run (and pilot) of it measures it
            sc.setdefault("observables", {})["cage_relative"] = True
        return sc

    def tau_group(self, unit=None):
        """The run.h5 group whose tau_alpha the run lengths (or unit's) are counted in."""
        return schema.cage_relative("overlap") if (unit or self.run_length["unit"]) == "tau_alpha_cr" else "overlap"

    @staticmethod
    def cutoffs(sc):
        return sc.get("observables", {}).get("cutoff_a", default("observables", "cutoff_a"))

    def first_cutoff(self, sc):
        return self.cutoffs(sc)[0]
