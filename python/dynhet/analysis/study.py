"""A study's complete runs as points (and those of --also studies), with the table rows and fits made of them."""
import math
import os
import tomllib
from typing import NamedTuple

import matplotlib.pyplot as plt
import numpy as np

from ..archive import Archive, ArchiveError
from ..scene import default
from ..study.model import RUN_LENGTH_DEFAULTS
from .config import A_MAIN, EPS_MAIN
from .runs import read_run
from .points import Point, ensure_calibrated, point_error
from .quantities import PER_RUN


class PhiSeries(NamedTuple):
    """A per-run quantity against the packing fraction over one series of a
    study (Analysis.against_phi); unpacks as (phi, value, error, seeds)."""
    phi: np.ndarray
    """(n_phi,) the packing fractions, increasing."""
    value: np.ndarray
    """(n_phi,) the mean over the point's seeds."""
    error: np.ndarray
    """(n_phi,) its error (the runs' own, scaled to the seeds' spread where they scatter more; NaN: none)."""
    seeds: np.ndarray
    """(n_phi,) how many seeds (complete runs) each point has."""


# A run's dataset name -> the study's name of the same quantity.
QUANTITY_ALIASES = {"D": "diffusion"}


def is_cage_relative_key(key):
    """Whether a run's quantity is a cage-relative one (cut_cr, D_cr,
    tau_cr_err, ...: a "cr" part in its name)."""
    return "cr" in str(key).split("_")


def drawable(ax):
    """Whether a panel's lines hold one point its axes can show (finite, and
    positive on a log axis): a panel of NaN only (a quantity no run of the
    study determined) cannot be log-scaled."""
    import numpy as np
    logx, logy = ax.get_xscale() == "log", ax.get_yscale() == "log"
    for line in ax.get_lines():
        x = np.asarray(line.get_xdata(), float)
        y = np.asarray(line.get_ydata(), float)
        ok = np.isfinite(x) & np.isfinite(y)
        if logx:
            ok &= x > 0
        if logy:
            ok &= y > 0
        if ok.any():
            return True
    return not ax.get_lines() and ax.has_data()  # images, patches: left as they are


def study_protocol(sdir):
    """(unit, equilibration_tau, origins, origin_spacing_tau) of the study
    file its directory holds (run_study.sh copies it there): what makes two
    studies' runs one protocol (size.protocol_of); None without one."""
    try:
        with open(os.path.join(sdir, "study.toml"), "rb") as fh:
            rl = tomllib.load(fh).get("run_length", {})
    except (OSError, tomllib.TOMLDecodeError):
        return None
    rl = dict(RUN_LENGTH_DEFAULTS, **rl)
    return rl["unit"], float(rl["equilibration_tau"]), int(rl["origins"]), float(rl["origin_spacing_tau"])


def planned_runs(sdir):
    """{run name: its axes, state "not archived"} of every run the study file
    of an archive plans (its study.toml and base_scene.toml)."""
    from ..study.model import AXES, Study, StudyError
    try:
        st = Study(os.path.join(sdir, "study.toml"), os.path.join(sdir, "base_scene.toml"))
    except StudyError as e:
        raise SystemExit(f"analyse_study: {sdir}: its study file cannot be read: {e}") from None
    return {st.run_name(p): dict({a: p[a] for a in AXES}, state="not archived") for p in st.points()}


def run_file(sdir, name, m, archive):
    """The run.h5 of index entry m: a study directory's run, or where its
    directory no longer holds it, the archive entry its status names; an
    archive's entry, verified against its hash (a corrupted or changed entry
    is refused by name)."""
    if archive is not None:
        if "file" not in m:  # planned, not archived: no file (the caller counts it unfinished)
            return os.path.join(sdir, "runs", name + ".h5")
        try:
            return archive.path(name, m)
        except ArchiveError as e:
            raise SystemExit(f"analyse_study: {e}") from None
    path = os.path.join(sdir, m["path"], "run.h5")
    if not os.path.exists(path) and m.get("archived"):
        try:   # results/<study>/runs/<run>.h5: its archive is two levels up
            return Archive(os.path.dirname(os.path.dirname(m["archived"]))).path(name)
        except ArchiveError as e:
            raise SystemExit(f"analyse_study: {e}") from None
    return path


class Analysis:
    figures = True  # False: the text alone (save() names each figure and draws none)

    def __init__(self, d, also=(), out=None):
        """d: the study (a study directory or a results archive); also: other
        studies whose runs add points (finite size, longer lags) without
        entering the study's own series; out: where study.h5, the tables and
        figures/ go (default d; an archive holds runs only, so give one)."""
        self.dir = os.path.abspath(d)
        self._out = os.path.abspath(out or d)
        self.points = {}      # the study's own points: (pairs, eps, phi, N) -> Point
        self.extra = {}       # the other studies' points: (study, pairs, eps, phi, N) -> Point
        self.skipped = []
        self.unfinished = {}  # (study, pairs, eps, phi, N) -> runs of that point not complete (promote_largest_n)
        self.held_back = []   # [(point, unfinished runs)]: larger N not taken, runs of it unfinished
        self.cpu = {}
        self.pilot_cpu = 0.0
        self.cpu_runs = 0       # the runs (of every study read) whose CPU self.cpu sums
        self.cpu_resumed = 0    # of those, resumed after an interruption (attempts > 1)
        self.cpu_unrecorded = 0 # attempts killed before they recorded their CPU (not in self.cpu)
        self.also = [os.path.abspath(x) for x in also]
        for k, sd in enumerate([d] + list(also)):
            self.read_study(sd, primary=(k == 0))
        ensure_calibrated(list(self.points.values()) + list(self.extra.values()))
        self.promoted = []
        self.fits = {}
        self.rows = []
        self.figdir = os.path.join(self.out, "figures")  # made by the first figure saved

    @property
    def out(self):
        """Where the analysis writes (the study directory unless told otherwise)."""
        return getattr(self, "_out", None) or self.dir

    def read_study(self, d, primary):
        sdir = os.path.abspath(d)
        idx = os.path.join(sdir, "index.toml")
        if not os.path.exists(idx):
            raise SystemExit(f"analyse_study: {idx} does not exist: is {d} a study directory (run_study.sh --out) "
                             "or a results archive (results/<study>)?")
        with open(idx, "rb") as fh:
            index = tomllib.load(fh)
        runs = index.get("runs", {})
        archive = Archive(sdir) if "archive" in index else None
        if archive is not None:  # an archive lists complete runs only: the rest of its study's are unfinished
            runs = dict(planned_runs(sdir), **runs)
        study = os.path.basename(sdir.rstrip("/"))
        self.protocols = getattr(self, "protocols", {})
        self.protocols[study] = study_protocol(sdir)
        for name, m in sorted(runs.items()):
            path = run_file(sdir, name, m, archive)
            try:
                key = (m.get("pairs", default("driving", "pairs")), float(m["restitution"]), float(m["packing_fraction"]),
                       int(m["n_particles"]))
            except (KeyError, TypeError, ValueError):
                key = None
            def unfinished(why):
                self.skipped.append((name, why))
                if key:
                    self.unfinished[(study,) + key] = self.unfinished.get((study,) + key, 0) + 1
            if m.get("state") != "complete" or not os.path.exists(path):
                unfinished(m.get("state", "?"))
                continue
            try:
                r = read_run(path, m)
            except (OSError, KeyError, ValueError) as e:
                unfinished(f"unreadable: {e}")
                continue
            if r["complete"] != 1:
                unfinished("run.h5 not complete")
                continue
            if A_MAIN not in r["cut"]:
                self.skipped.append((name, f"no cutoff a = {A_MAIN}"))
                continue
            if key is None:
                self.skipped.append((name, "its index entry lacks restitution, packing_fraction or n_particles"))
                continue
            r["name"], r["path"], r["study"] = name, path, study
            self.cpu_runs += 1
            self.cpu_resumed += int(m.get("attempts", 1)) > 1
            self.cpu_unrecorded += int(m.get("cpu_unrecorded", 0))
            if primary:
                self.points.setdefault(key, Point(key)).runs.append(r)
                self.cpu[key] = self.cpu.get(key, 0.0) + float(m.get("cpu_s", 0.0))
            else:
                pt = self.extra.setdefault((study,) + key, Point(key))
                pt.study = study
                pt.runs.append(r)
                self.cpu[(study,) + key] = self.cpu.get((study,) + key, 0.0) + float(m.get("cpu_s", 0.0))
        if primary and archive is not None:
            self.pilot_cpu += sum(float(s.get("cpu_s", 0.0)) for s in index.get("pilots", {}).values())
        elif primary:
            for root, _, files in os.walk(os.path.join(sdir, "pilots")):
                if "status.toml" in files:
                    with open(os.path.join(root, "status.toml"), "rb") as fh:
                        self.pilot_cpu += float(tomllib.load(fh).get("cpu_s", 0.0))
        self.study_name = getattr(self, "study_name", study)

    def promote_largest_n(self):
        """At each (pairs, eps, phi) of this study, the point
        of the largest N over this study and the --also studies whose runs
        measured everything this study's point measured, and all of whose
        study's runs at that point are complete, and of a size that the study
        running that phi at the most N has finished (else it is held back:
        self.held_back; size.protocol_waiting), joins this study's points, so that every series (and
        so every row and fit) takes it in place of this study's own; other
        studies' densities are not added. Returns the promoted points (also
        in self.promoted). What the point measured means the standard
        measures: the cage-relative ones (keys with a "cr" part) are the
        cage-relative view's, which keeps the largest N that has them
        (a study of the standard measures alone, studies/size_standard.toml,
        stands in for the paper's rows; the cage-relative rows stay at the
        N whose runs measured them)."""
        from .size import waiting_for, waiting_sizes
        def measured(p):
            keys = set.intersection(*[set(r["cut"].get(A_MAIN, {})) | set(r) for r in p.runs]) if p.runs else set()
            return {k for k in keys if not is_cage_relative_key(k)}
        main = lambda p: p.pairs == "neighbours" and abs(p.eps - EPS_MAIN) < 1e-9
        # a size the leading protocol (size.leading_protocol) has not finished is not filled
        # from another study's runs of other lengths (size.protocol_waiting)
        waiting = waiting_sizes(self)
        best, self.held_back = {}, []
        for k, p in self.extra.items():
            key = k[1:4]
            own = [q for pk, q in self.points.items() if pk[:3] == key]
            if not own:
                continue
            top = max(own, key=lambda q: q.N)
            if p.N <= top.N or not measured(top) <= measured(p):
                continue
            left = getattr(self, "unfinished", {}).get(k)
            if left:   # no conclusion from a size whose runs did not all finish
                self.held_back.append((p, left))
                continue
            wait = waiting_for(waiting, p, self) if main(p) else None
            if wait:
                stand_in = Point(k[1:])
                stand_in.study = wait[0]
                self.held_back.append((stand_in, wait[1]))
                continue
            q = best.get(key)
            if q is None or p.N > q.N or (p.N == q.N and len(p.runs) > len(q.runs)):
                best[key] = p
        # a size of a study that stands in elsewhere (its points measured what this study's did)
        # with no run archived yet is held back as well: planned, not finished
        stands_in = {k[0] for k, p in self.extra.items()
                     if any(pk[:3] == k[1:4] for pk in self.points) and
                     measured(max((q for pk, q in self.points.items() if pk[:3] == k[1:4]), key=lambda q: q.N))
                     <= measured(p)}
        for k, left in getattr(self, "unfinished", {}).items():
            key = k[1:4]
            own = [q.N for pk, q in self.points.items() if pk[:3] == key]
            if left and k not in self.extra and k[0] in stands_in and own and k[4] > max(own):
                stand_in = Point(k[1:])
                stand_in.study = k[0]
                self.held_back.append((stand_in, left))
        # only the sizes above the one taken were held back in its place
        self.held_back = list({(p.study, p.pairs, p.eps, p.phi, p.N): (p, n) for p, n in self.held_back
                               if p.N > getattr(best.get((p.pairs, p.eps, p.phi)), "N", 0)}.values())
        self.promoted = []
        for key, p in sorted(best.items()):
            self.points[key + (p.N,)] = p
            self.promoted.append(p)
        return self.promoted

    # -- selections
    def series(self, pairs="neighbours", eps=EPS_MAIN, N=None):
        """The points of one (pairs, eps) series, one per density: at a density
        run at several N, the largest (or N if given)."""
        by_phi = {}
        for k, p in self.points.items():
            if k[0] == pairs and abs(k[1] - eps) < 1e-9 and (N is None or k[3] == N):
                if p.phi not in by_phi or p.N > by_phi[p.phi].N:
                    by_phi[p.phi] = p
        return [by_phi[phi] for phi in sorted(by_phi)]

    def series_with(self, has, pairs="neighbours", eps=EPS_MAIN, over_studies=False):
        """One point per density of a series: the largest N whose point `has`
        takes (where --largest-n took a larger N that lacks something, such
        as the cage-relative measures or the frames, the study's own point
        still has it). over_studies: also the --also studies' points whose
        runs are all complete, at a density of this study's (a quantity one
        of them measures to larger N than the study that stands in for the
        paper's rows, such as tau_alpha^CR in studies/size_cage.toml); at
        equal N this study's point stays."""
        own_phi = {k[2] for k in self.points if k[0] == pairs and abs(k[1] - eps) < 1e-9}
        cands = list(self.points.items())
        if over_studies:
            unfinished = getattr(self, "unfinished", {})
            cands += [(k[1:], p) for k, p in self.extra.items() if not unfinished.get(k) and k[3] in own_phi]
        by_phi = {}
        for k, p in cands:
            if k[0] == pairs and abs(k[1] - eps) < 1e-9 and has(p):
                if p.phi not in by_phi or p.N > by_phi[p.phi].N:
                    by_phi[p.phi] = p
        return [by_phi[phi] for phi in sorted(by_phi)]

    def common_size(self, series):
        """The largest N every (pairs, eps) of `series` ran (None if they share
        none): series set side by side at one box size, where --largest-n
        would give one of them larger boxes (shorter tau_alpha at the highest
        densities)."""
        sizes = [{k[3] for k in self.points if k[0] == pairs and abs(k[1] - eps) < 1e-9} for pairs, eps in series]
        common = set.intersection(*sizes) if sizes else set()
        return max(common) if common else None

    def restitutions(self, pairs="neighbours"):
        return sorted({k[1] for k in self.points if k[0] == pairs}, reverse=True)

    def cpu_of(self, pts):
        return sum(self.cpu.get(((p.study,) if getattr(p, "study", None) else ()) + (p.pairs, p.eps, p.phi, p.N), 0.0)
                   for p in pts)

    def nearest(self, pts, phi):
        return min(pts, key=lambda p: abs(p.phi - phi)) if pts else None

    def against_phi(self, quantity, pairs="neighbours", eps=EPS_MAIN, N=None):
        """A per-run quantity against phi over one series: a PhiSeries of
        arrays (phi, value: the mean over seeds, error, seeds), one entry per
        density. quantity: a name of quantities.PER_RUN (tau_alpha, beta,
        tau0, diffusion, chi4_tau_alpha, xi_tau_alpha, d_f_slow, tau_b, ...);
        a run's dataset names are the study's (diffusion is msd's, D is
        accepted for it)."""
        quantity = QUANTITY_ALIASES.get(quantity, quantity)
        if quantity not in PER_RUN:
            raise KeyError(f"no quantity {quantity!r}; known: {', '.join(sorted(PER_RUN))}")
        pts = self.series(pairs, eps, N)
        if not pts:  # a series the study lacks: said, not empty arrays
            have = sorted({(k[0], k[1], k[3]) for k in self.points})
            raise KeyError(f"no complete run of the series pairs = {pairs!r}, eps = {eps!r}"
                           + (f", N = {N}" if N is not None else "") + " in this study; it has "
                           + ("; ".join(f"pairs = {q!r}, eps = {e!r}, N = {n}" for q, e, n in have) or "no complete run"))
        ms = [p.mean(PER_RUN[quantity]) for p in pts]
        return PhiSeries(np.array([p.phi for p in pts]), np.array([m[0] for m in ms]),
                         np.array([point_error(m) if m[3] else np.nan for m in ms]), np.array([m[3] for m in ms]))

    def save(self, fig, name):
        """Writes fig to figures/name and returns that path relative to the
        output; without figures (the text alone), names it and writes nothing."""
        path = os.path.join(self.figdir, name)
        if not self.figures:
            plt.close(fig)
            return os.path.relpath(path, self.out)
        os.makedirs(self.figdir, exist_ok=True)
        for ax in fig.axes:
            if not ax.has_data() or not drawable(ax):
                ax.set_xscale("linear")
                ax.set_yscale("linear")
                ax.text(0.5, 0.5, "no data in this study", ha="center", transform=ax.transAxes)
        fig.savefig(path, dpi=110, bbox_inches="tight")
        plt.close(fig)
        return os.path.relpath(path, self.out)

    def row(self, item, section, paper, ours, verdict, figure, pts, note=""):
        mixed = self.sizes_note(item, pts)
        self.rows.append(dict(item=item, section=section, paper=paper, ours=ours, verdict=verdict, figure=figure,
                              cpu=self.cpu_of(pts), note="; ".join(x for x in (note, mixed) if x)))

    def sizes_note(self, item, pts):
        """With --largest-n, a row over densities of several box sizes says so
        (its fit mixes N where tau_alpha still depends on N): "sizes: 8 φ at N
        4096, 4 at N 16384"; "" for one size, without --largest-n, or for the
        rows that set the sizes against each other."""
        if not getattr(self, "promoted", None) or "against N" in item:
            return ""
        per_n = {}
        for p in pts:
            per_n.setdefault(p.N, set()).add(p.phi)
        if len(per_n) < 2:
            return ""
        return "sizes: " + ", ".join(f"{len(per_n[n])} φ at N {n}" for n in sorted(per_n)) + " (the largest N per φ)"

    def fit(self, name, f):
        self.fits[name] = f
        return f

    # -- the other way
    def has_cage_relative(self):
        return any(A_MAIN in r.get("cut_cr", {}) for p in self.points.values() for r in p.runs)

    def cage_relative_view(self):
        """This study with every run's per-cutoff results (overlap, chi4, S4,
        clusters) replaced by their cage-relative versions, runs without them
        left out: the sections' own code states each result the other way.
        Rows and fits go to this analysis, marked "(cage-relative)" and "cr_";
        their verdict against the paper moves to the note (the paper measured
        the standard way: these rows do not count as agreeing or differing);
        figures are saved as cr_<name>."""
        return CageRelativeView(self)


class CageRelativeView(Analysis):
    def __init__(self, base):  # noqa: super().__init__ not called: a view of base, nothing read
        self.__dict__.update(base.__dict__)
        self.base = base

        copies = {}  # one copy per point (a point promoted by --largest-n is in both dicts)

        def swapped(points):
            out = {}
            for k, p in points.items():
                if id(p) not in copies:
                    # (D: the cage-relative one where the run has it, else none: never the standard D
                    # against the cage-relative tau_alpha)
                    runs = [dict(r, cut=r["cut_cr"], D=r.get("D_cr", math.nan), D_err=r.get("D_cr_err", math.nan))
                            for r in p.runs if A_MAIN in r.get("cut_cr", {})]
                    q = None
                    if runs:
                        q = Point((p.pairs, p.eps, p.phi, p.N))
                        q.runs = runs
                        if hasattr(p, "study"):
                            q.study = p.study
                    copies[id(p)] = q
                if copies[id(p)] is not None:
                    out[k] = copies[id(p)]
            return out
        self.points, self.extra = swapped(base.points), swapped(base.extra)
        self.promoted = [copies[id(p)] for p in getattr(base, "promoted", []) if copies.get(id(p)) is not None]
        ensure_calibrated(list(self.points.values()) + list(self.extra.values()))  # it takes each point once

    def save(self, fig, name):
        return self.base.save(fig, "cr_" + name)

    def row(self, item, section, paper, ours, verdict, figure, pts, note=""):
        # (a verdict reads "differs (3.2 σ)", "agrees (0.4 σ); ...": its kind starts it)
        # (and a verdict that is no judgement, "not judged: ...", keeps its reason)
        against = (f"against the paper's standard measure: {verdict}"
                   if verdict.split(" (")[0].split(";")[0] in ("agrees", "differs")
                   else verdict if verdict.startswith(("not judged", "not determined", "not comparable")) else "")
        self.base.row(f"{item} (cage-relative)", section, paper, ours, "—", figure, pts,
                      "; ".join(x for x in (against, note) if x))

    def fit(self, name, f):
        return self.base.fit("cr_" + name, f)
