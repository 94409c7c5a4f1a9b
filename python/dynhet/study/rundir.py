"""A study directory on disk: status files, a run's result, the lock, tau_alpha from finished runs."""
import math
import os
import subprocess
import threading
import time
import tomllib

from .toml_io import read_toml, toml_dump, write_atomic
from .model import AXES, StudyError


def read_status(d):
    p = os.path.join(d, "status.toml")
    if not os.path.exists(p):
        return {}
    try:
        return read_toml(p)
    except tomllib.TOMLDecodeError:
        return {"state": "unknown"}


def write_status(d, st):
    write_atomic(os.path.join(d, "status.toml"), toml_dump(st, "# dynhet study run status (run_study.sh reads it)"))


def run_h5_result(path, cutoff, group="overlap"):
    """(complete, tau_alpha) of a run.h5 (group overlap_cr: the cage-relative tau_alpha)."""
    out = subprocess.run(
        ["/usr/bin/python3", "-c",
         "import h5py,sys,math\n"
         "f=h5py.File(sys.argv[1],'r')\n"
         "c=int(f.attrs.get('complete',0))\n"
         "g=f.get('observables/'+sys.argv[3]+'/a'+sys.argv[2])\n"
         "t=float(g['tau_alpha/value'][-1]) if g is not None else float('nan')\n"
         "print(c, t)", path, f"{cutoff:g}", group],
        capture_output=True, text=True)
    if out.returncode != 0:
        return 0, float("nan")
    c, t = out.stdout.split()
    return int(c), float(t)


def archived_status(entry, p):
    """A run's status from its archive entry (the run's axes p): complete,
    where the entry's file is."""
    st = {k: v for k, v in entry.items() if k not in ("file", "bytes", "sha256")}
    st.update({a: p[a] for a in AXES})
    st["state"] = "complete"
    return st


def same_toml(a, b):
    """Whether two study files (bytes) say the same study: equal, or equal once
    parsed (comments, spacing and order of keys are not the study, nor is
    where its results are archived, [study] archive)."""
    if a == b:
        return True
    try:
        ta, tb = tomllib.loads(a.decode()), tomllib.loads(b.decode())
    except (UnicodeDecodeError, tomllib.TOMLDecodeError):
        return False
    for t in (ta, tb):
        if isinstance(t.get("study"), dict):
            t["study"].pop("archive", None)
    return ta == tb


class StudyDir:
    def __init__(self, study, out, archive=None):
        """archive: the results archive's directory (a --archive flag), else
        the study file's [study] archive, else the one a study directory
        recorded when it started (archive.txt: a Slurm task's), else none."""
        from ..archive import Archive
        from .archiving import resolve
        self.study = study
        self.dir = os.path.abspath(out)
        self.runs_dir = os.path.join(self.dir, "runs")
        self.lock = threading.Lock()
        recorded = os.path.join(self.dir, "archive.txt")
        if archive is None and study.archive:
            archive = resolve(study.archive)
        if archive is None and os.path.exists(recorded):
            archive = open(recorded).read().strip() or None
        self.archive = Archive(archive) if archive else None

    def refusal(self):
        """Why the directory cannot take this study (None if it can): it holds
        another study, this study with another base scene, or anything
        without a study.toml (what the study would write into or over is
        never taken for its own). Earlier studies moved aside (old-*) do
        not count."""
        copy_path = os.path.join(self.dir, "study.toml")
        base_path = os.path.join(self.dir, "base_scene.toml")
        how = f"give another --out, or --fresh to move what it holds into {self.dir}/old-<time>/ (nothing is deleted)"
        if os.path.exists(copy_path):
            if not same_toml(open(copy_path, "rb").read(), self.study.text):
                return (f"{self.study.path} differs from the study that {self.dir} holds ({copy_path}): a changed "
                        f"study is never mixed into old runs; restore the study file, or {how}")
            if os.path.exists(base_path) and open(base_path).read() != self.base_text():
                return (f"the base scene of {self.study.path} changed since {self.dir} was started ({base_path} "
                        f"holds the old one): restore the scene, or {how}")
            return None
        there = self.foreign_entries()
        if there:
            return (f"{self.dir} is not a study directory (no study.toml) and holds "
                    f"{', '.join(there[:8])}{', ...' if len(there) > 8 else ''}: {how}")
        return None

    def foreign_entries(self):
        if not os.path.isdir(self.dir):
            return []
        return sorted(e for e in os.listdir(self.dir) if not e.startswith("old-"))

    def base_text(self):
        return toml_dump(self.study.base, "# the study's base scene, as read when the study started")

    def move_aside(self):
        """--fresh: everything the directory holds (but earlier old-*) into
        DIR/old-<time>/; returns that path."""
        stamp = time.strftime("%Y%m%d-%H%M%S")
        to, k = os.path.join(self.dir, f"old-{stamp}"), 1
        while os.path.exists(to):
            k += 1
            to = os.path.join(self.dir, f"old-{stamp}-{k}")
        os.makedirs(to)
        for e in self.foreign_entries():
            os.rename(os.path.join(self.dir, e), os.path.join(to, e))
        return to

    def claim(self, fresh=False):
        """Create the directory or check it holds this very study; with
        fresh, whatever else it holds is moved aside first (returns where,
        or None)."""
        why, moved = self.refusal(), None
        if why and not fresh:
            raise StudyError(why)
        if why:
            moved = self.move_aside()
        os.makedirs(self.runs_dir, exist_ok=True)
        copy_path = os.path.join(self.dir, "study.toml")
        base_path = os.path.join(self.dir, "base_scene.toml")
        base_text = self.base_text()
        if not os.path.exists(copy_path):
            with open(copy_path, "wb") as f:
                f.write(self.study.text)
        if not os.path.exists(base_path):
            write_atomic(base_path, base_text)
        if self.archive is not None:
            from ..archive import ArchiveError
            try:
                self.archive.claim(self.study)
            except ArchiveError as e:
                raise StudyError(str(e)) from None
            write_atomic(os.path.join(self.dir, "archive.txt"), self.archive.dir + "\n")
        return moved

    def run_dir(self, p):
        return os.path.join(self.runs_dir, self.study.run_name(p))

    def archive_index(self):
        """The archive's index ({"runs": ..., "pilots": ...}; empty without an
        archive), read once per change of its file."""
        from ..archive import ArchiveError
        if self.archive is None or not self.archive.exists():
            return {"runs": {}, "pilots": {}}
        st = os.stat(self.archive.index_path)
        stamp = (st.st_ino, st.st_size, st.st_mtime_ns)
        if getattr(self, "_index_stamp", None) != stamp:
            try:
                self.archive.check_study(self.study)
                self._index, self._index_stamp = self.archive.read(), stamp
            except ArchiveError as e:
                raise StudyError(str(e)) from None
        return self._index

    def status(self, p):
        """Run p's status as running the study would find it: its directory's;
        where that does not say complete and the archive holds the run (its
        directory gone, as on a new machine), the archive's entry, complete,
        where its file is there at its size. Nothing is written (archiving.restored_run writes it when the run
        comes up)."""
        st = read_status(self.run_dir(p))
        if st.get("state") == "complete":
            return st
        entry = self.archive_index()["runs"].get(self.study.run_name(p))
        if entry is None or not self.archived_file_fits(entry):
            return st
        return archived_status(entry, p)

    def archived_file_fits(self, entry):
        """Whether an archive entry's file is there at the size its index
        says (its hash is checked when the run is restored)."""
        try:
            return os.path.getsize(os.path.join(self.archive.dir, entry["file"])) == int(entry["bytes"])
        except (OSError, KeyError, TypeError, ValueError):
            return False

    def pilot_statuses(self):
        """{name: status} of the pilots: the study directory's, and the
        archive's where the directory lacks them complete."""
        out = {}
        pdir = os.path.join(self.dir, "pilots")
        if os.path.isdir(pdir):
            out = {name: read_status(os.path.join(pdir, name)) for name in os.listdir(pdir)}
        for name, st in self.archive_index()["pilots"].items():
            if out.get(name, {}).get("state") != "complete" and st.get("state") == "complete":
                out[name] = dict(st)
        return out

    def finished_taus(self, p):
        """(phi, tau_alpha) of complete runs and pilots of p's series; the
        pilots of another N count where they ran the same system (a pilot
        runs min(N, run_length.pilot_particles) particles), so that a size
        not yet piloted is estimated from its density's pilots, not from the
        study's tau_guess alone."""
        pts = []
        key = self.study.series_key(p)
        # (only where pilots set run lengths: with interpolated lengths the count of
        # finished points decides whether a run interpolates, and must be its own N's)
        pp = self.study.run_length.get("pilot_particles", 0) if self.study.run_length["tau_alpha"] == "pilot" else 0
        pilot_n = min(key[2], pp) if pp else key[2]
        for q in self.study.points():
            if self.study.series_key(q) != key:
                continue
            st = self.status(q)
            if st.get("state") == "complete" and math.isfinite(st.get("tau_alpha", float("nan"))):
                pts.append((q["packing_fraction"], st["tau_alpha"]))
        for st in self.pilot_statuses().values():
            if st.get("unit", self.study.run_length["unit"]) != self.study.run_length["unit"]:
                continue  # the equilibration's pilot, of the other tau_alpha
            ser = tuple(st.get("series", []))
            if st.get("state") == "complete" and len(ser) == 3 and ser[:2] == (key[0], key[1]) and (
                    ser[2] == key[2] or (pp and min(ser[2], pp) == pilot_n)):
                pts.append((st["packing_fraction"], st["tau_alpha"]))
        by_phi = {}
        for ph, t in pts:
            by_phi.setdefault(ph, []).append(t)
        return sorted((ph, math.exp(sum(map(math.log, ts)) / len(ts))) for ph, ts in by_phi.items())

    @staticmethod
    def interpolate(pts, phi):
        """ln tau linear in phi between the nearest points (or from the nearest two at the ends)."""
        if len(pts) < 2:
            return None
        for ph, t in pts:
            if abs(ph - phi) < 1e-12:
                return t
        below = [x for x in pts if x[0] < phi]
        above = [x for x in pts if x[0] > phi]
        if below and above:
            a, b = below[-1], above[0]
        elif below:
            a, b = below[-2] if len(below) > 1 else below[-1], below[-1]
        else:
            a, b = above[0], above[1]
        if a[0] == b[0]:
            return None
        s = (math.log(b[1]) - math.log(a[1])) / (b[0] - a[0])
        return math.exp(math.log(a[1]) + s * (phi - a[0]))

    def guess(self, p, finished=True, table="tau_guess"):
        """A prior guess of tau_alpha: finished points (between them ln tau
        linear in phi), then the study's tau_guess table, then 1. Beyond the
        finished points' range the table's shape, scaled to the nearest
        finished point: ln tau is far from linear in phi near the transition,
        and a line through two high densities extrapolated down undershoots
        (a finite-size study: 0.78 and 0.80 put 0.76 at 3.6, where the table has a
        third of 0.78's). Estimates only (the dry run, the ETA, the order of
        the runs) unless the study's run lengths interpolate."""
        phi = p["packing_fraction"]
        g = self.study.run_length[table]
        pts = self.finished_taus(p) if finished and table == "tau_guess" else []
        exact = [t for ph, t in pts if abs(ph - phi) < 1e-12]
        if exact:
            return exact[0], "interpolated from finished points"
        if pts and len(g) >= 2 and not pts[0][0] < phi < pts[-1][0]:
            near = pts[0] if phi < pts[0][0] else pts[-1]
            return (near[1] * self.interpolate(g, phi) / self.interpolate(g, near[0]),
                    f"the study's tau_guess scaled to the finished point at phi = {near[0]:g}")
        t = self.interpolate(pts, phi)
        if t:
            return t, ("interpolated" if pts[0][0] < phi < pts[-1][0] else "extrapolated") + " from finished points"
        if len(g) >= 2:
            return self.interpolate(g, phi), "the study's tau_guess"
        if len(g) == 1:
            return g[0][1], "the study's tau_guess"
        return 1.0, "no estimate (1.0)"
