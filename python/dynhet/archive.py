"""The results archive: each complete run of a study reduced to what the study
analysis reads, one file per run, with its provenance, listed in an index
with a content hash.

    results/<study>/
        index.toml          [archive] (what this is), [runs."<run>"] (the
                            run's axes, state, CPU, file, bytes, sha256),
                            [pilots."<pilot>"] (the pilots' tau_alpha and CPU)
        study.toml          the study file the runs were made by
        base_scene.toml     its base scene, as read when the study started
        runs/<run>.h5.gz    one reduced run.h5 per run, gzip-compressed (Archive.path
                            gives a readable copy, decompressed once into a cache)

A reduced run.h5 keeps run.h5's layout (dynhet.run reads it as it reads a
run): the root attributes, h5md/, parameters/, every observable group with
each time series cut to its final record (the result; the study analysis
reads nothing else of it: value with one record, its step and time the
series group's attributes), and, for a run that kept its frames, two frames
of particles/all (the first origin and the frame nearest tau_alpha: the
snapshots of slow and fast particles). provenance/ holds the resolved scene,
the build, the command, CPU and wall seconds, the dates and the original
file's size and hash. No frames beyond those, no checkpoints, journals or
logs.

An entry is written to a temporary name, synced and renamed, then the index
is rewritten the same way under a file lock: a file the index does not list,
or lists with another hash, is not an entry and is never read as one
(Archive.path refuses it by name)."""
import fcntl
import hashlib
import math
import os
import socket
import time

import h5py
import numpy as np

from .scene import default
from .study.paths import BUILD
from .study.toml_io import read_toml, toml_value, write_atomic

FORMAT = 1
MAX_BYTES = 1 << 20          # one entry at most 1 MiB at any N
COMPRESS_OVER = 1024         # bytes: larger datasets are stored gzip-compressed
A_SNAPSHOT = default("observables", "cutoff_a")[0]  # whose tau_alpha picks the snapshot frame (analysis.config.A_MAIN)
RUN_KEYS = ("state", "tau_estimate", "tau_source", "tau_alpha", "wall_s", "cpu_s", "cpu_unrecorded", "attempts",
            "requeues", "finished")
PILOT_KEYS = ("state", "tau_alpha", "unit", "guess", "attempts", "packing_fraction", "series", "wall_s",
              "cpu_s", "system_key", "reused_from")


class ArchiveError(Exception):
    """An archive or an entry that cannot be read or written as one (the
    message names it and says why)."""


def sha256_of(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def gzip_file(src, dst):
    """dst: src gzip-compressed, synced. An entry's thousands of small HDF5
    objects (a run of eight cutoffs has some 4000) cost more in headers than
    their data; compressed, the headers all but vanish (1.8 MB -> 0.57 MB)."""
    import gzip
    import shutil
    with open(src, "rb") as fin, open(dst, "wb") as raw:
        with gzip.GzipFile(fileobj=raw, mode="wb", compresslevel=6, mtime=0) as out:
            shutil.copyfileobj(fin, out, 1 << 20)
        raw.flush()
        os.fsync(raw.fileno())


def readable(p, digest):
    """An entry as a file h5py reads: a .h5.gz entry decompressed once into a
    cache named by its hash (DYNHET_ARCHIVE_CACHE, default the system's
    temporary directory), written atomically; a plain .h5 as it is."""
    import gzip
    import tempfile
    if not p.endswith(".gz"):
        return p
    cache = os.environ.get("DYNHET_ARCHIVE_CACHE", os.path.join(tempfile.gettempdir(), "dynhet-archive"))
    os.makedirs(cache, exist_ok=True)
    out = os.path.join(cache, digest + ".h5")
    if not os.path.exists(out):
        tmp = f"{out}.tmp.{os.getpid()}"
        with gzip.open(p, "rb") as fin, open(tmp, "wb") as fout:
            for block in iter(lambda: fin.read(1 << 20), b""):
                fout.write(block)
        os.replace(tmp, out)
    return out


def is_archive(d):
    """Whether directory d is a results archive (its index has an [archive] table)."""
    p = os.path.join(d, "index.toml")
    try:
        return "archive" in read_toml(p)
    except (OSError, ValueError):
        return False


# -- reducing a run.h5

def _copy_attrs(src, dst):
    for k, v in src.attrs.items():
        dst.attrs[k] = v


def _write(dst, name, data):
    data = np.asarray(data)
    kw = {}
    if data.nbytes > COMPRESS_OVER and data.ndim > 0:
        kw = dict(compression="gzip", compression_opts=6, shuffle=True)
    return dst.create_dataset(name, data=data, track_times=False, **kw)


def _copy_tree(src, dst, reduce_series):
    """Copy group src into dst; a time series (a group with step, time,
    value) keeps its final record only if reduce_series."""
    _copy_attrs(src, dst)
    for name, obj in src.items():
        if isinstance(obj, h5py.Group):
            g = dst.create_group(name)
            if reduce_series and "value" in obj and isinstance(obj["value"], h5py.Dataset):
                _final_record(obj, g)
            else:
                _copy_tree(obj, g, reduce_series)
        else:
            d = _write(dst, name, obj[()])
            _copy_attrs(obj, d)


def _final_record(series, g):
    """An H5MD time series (step, time, value) reduced to its final record:
    value keeps its record axis (one record), step and time become the
    group's attributes (two datasets of one number each would be most of an
    entry's size)."""
    _copy_attrs(series, g)
    v = series["value"]
    d = _write(g, "value", v[-1:] if v.shape and v.shape[0] else v[()])
    _copy_attrs(v, d)
    for part in ("step", "time"):
        if part in series and series[part].shape and series[part].shape[0]:
            g.attrs[part] = series[part][-1]


def _snapshot_frames(f):
    """Indices of the frames the snapshot figure reads: the first, and the
    one whose lag from it is nearest the run's tau_alpha at a = 0.6
    (analysis.runs.snapshot); None where the run kept no frames."""
    pa = f.get("particles/all")
    if pa is None or "position" not in pa:
        return None
    times = pa["position/time"][()]
    if len(times) < 2:
        return [0] if len(times) else None
    ov = f.get(f"observables/overlap/a{A_SNAPSHOT:g}")
    tau = float(ov["tau_alpha/value"][-1]) if ov is not None and "tau_alpha" in ov else math.nan
    if not (math.isfinite(tau) and tau > 0):
        return [0]
    j = int(np.argmin(np.abs(np.log(np.maximum(times - times[0], 1e-300)) - math.log(tau))))
    return sorted({0, j})


def _copy_particles(f, out):
    frames = _snapshot_frames(f)
    if frames is None:
        return
    src = f["particles/all"]
    dst = out.create_group("particles/all")
    _copy_attrs(src, dst)
    for name, obj in src.items():
        if isinstance(obj, h5py.Group) and "value" in obj and name in ("position", "image"):
            g = dst.create_group(name)
            _copy_attrs(obj, g)
            for part, ds in obj.items():
                d = _write(g, part, ds[frames] if ds.shape and ds.shape[0] else ds[()])
                _copy_attrs(ds, d)
        elif isinstance(obj, h5py.Group):
            _copy_tree(obj, dst.create_group(name), reduce_series=True)
        else:
            d = _write(dst, name, obj[()])
            _copy_attrs(obj, d)
    dst.attrs["archived_frames"] = np.asarray(frames, np.int64)


def reduce_run(run_h5, out_path, provenance):
    """Write the reduced copy of run_h5 to out_path (see the module's
    docstring); provenance: {name: scalar or string} stored in provenance/."""
    with h5py.File(run_h5, "r") as f, h5py.File(out_path, "w", libver="latest") as out:
        if int(f.attrs.get("complete", 0)) != 1:
            raise ArchiveError(f"{run_h5}: not complete (complete = {f.attrs.get('complete', 0)}): "
                               "only complete runs are archived")
        if "observables" not in f:
            raise ArchiveError(f"{run_h5}: no observables group: not a run file")
        _copy_attrs(f, out)
        for top in ("h5md", "parameters"):
            if top in f:
                _copy_tree(f[top], out.create_group(top), reduce_series=False)
        _copy_tree(f["observables"], out.create_group("observables"), reduce_series=True)
        _copy_particles(f, out)
        pv = out.create_group("provenance")
        for k, v in provenance.items():
            pv.attrs[k] = v


def provenance_of(run_dir, status, study_name, command):
    """What made a run: its resolved scene, the build that ran it, the command,
    its CPU and wall time, when it finished and when it was archived."""
    run_h5 = os.path.join(run_dir, "run.h5")
    build = build_id()
    scene_path = os.path.join(run_dir, "scene.toml")
    scene = open(scene_path).read() if os.path.exists(scene_path) else ""
    out = {"study": study_name, "run": os.path.basename(run_dir.rstrip("/")), "build": build,
           "study_layer_commit": _checkout_commit(),
           "commit": build.split("-")[1] if build.count("-") >= 1 else "", "scene_toml": scene,
           "build_dir": BUILD,
           "command": command, "archived": time.strftime("%Y-%m-%dT%H:%M:%S"), "archived_on": socket.gethostname(),
           "source_bytes": os.path.getsize(run_h5), "source_sha256": sha256_of(run_h5)}
    for k in ("cpu_s", "wall_s", "attempts", "started", "finished", "host", "tau_source", "tau_estimate"):
        if k in status:
            out[k] = status[k]
    return out


def build_id():
    """The identity of the build whose programs ran the runs (BUILD_DIR's
    common/build_id.cpp: version-commit[-dirty-hash], what checkpoint parts
    are stamped with); "" where it cannot be read."""
    import re
    try:
        text = open(os.path.join(BUILD, "common", "build_id.cpp")).read()
    except OSError:
        return ""
    m = re.search(r'kBuildId = "([^"]*)"', text)
    return m.group(1) if m else ""


def _checkout_commit():
    """The commit of the checkout this package runs from (the study layer that
    planned the run; the build names the simulator's), with "-dirty" where
    python/ or studies/ differ from it."""
    import subprocess
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    try:
        head = subprocess.run(["git", "-C", root, "rev-parse", "--short=12", "HEAD"], capture_output=True, text=True,
                              timeout=10).stdout.strip()
        dirty = subprocess.run(["git", "-C", root, "status", "--porcelain", "--", "python", "studies"],
                               capture_output=True, text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return ""
    return head + ("-dirty" if head and dirty else "")


# -- the archive of one study

class Archive:
    """A study's results archive in directory d (results/<study>)."""

    def __init__(self, d):
        self.dir = os.path.abspath(d)
        self.index_path = os.path.join(self.dir, "index.toml")

    def exists(self):
        return os.path.exists(self.index_path)

    def read(self):
        """The index: {"archive": {...}, "runs": {...}, "pilots": {...}}."""
        if not self.exists():
            return {"archive": {}, "runs": {}, "pilots": {}}
        try:
            idx = read_toml(self.index_path)
        except ValueError as e:
            raise ArchiveError(f"{self.index_path}: not valid TOML ({e})") from None
        if "archive" not in idx:
            raise ArchiveError(f"{self.index_path}: not a results archive's index (no [archive] table)")
        idx.setdefault("runs", {})
        idx.setdefault("pilots", {})
        return idx

    def runs(self):
        return self.read()["runs"]

    def path(self, name, entry=None):
        """The verified file of run `name`: refused by name where it is
        missing, of another size or of another hash than the index says."""
        entry = entry if entry is not None else self.runs().get(name)
        if entry is None:
            raise ArchiveError(f"{self.dir}: no run {name!r} in the archive's index")
        p = os.path.join(self.dir, entry["file"])
        if not os.path.exists(p):
            raise ArchiveError(f"{self.dir}: entry {name!r}: its file {entry['file']} is missing")
        if os.path.getsize(p) != int(entry["bytes"]) or sha256_of(p) != entry["sha256"]:
            raise ArchiveError(f"{self.dir}: entry {name!r}: {entry['file']} does not match the index "
                               f"(size {os.path.getsize(p)} against {entry['bytes']}, or its hash): refused; "
                               "restore it from git (git checkout -- the file) or archive the run again")
        return readable(p, entry["sha256"])

    def _locked(self):
        os.makedirs(self.dir, exist_ok=True)
        lock = open(os.path.join(self.dir, ".lock"), "w")
        fcntl.flock(lock, fcntl.LOCK_EX)
        return lock

    def claim(self, study):
        """Create the archive for `study` (a study.model.Study) or check that
        it holds that very study."""
        from .study.toml_io import toml_dump
        with self._locked():
            copy = os.path.join(self.dir, "study.toml")
            if os.path.exists(copy):
                self.check_study(study)
            else:
                with open(copy + ".tmp", "wb") as fh:
                    fh.write(study.text)
                    fh.flush()
                    os.fsync(fh.fileno())
                os.replace(copy + ".tmp", copy)
            base = os.path.join(self.dir, "base_scene.toml")
            if not os.path.exists(base):
                write_atomic(base, toml_dump(study.base, "# the study's base scene, as read when the study started"))
            idx = self.read()
            if not idx["archive"]:
                idx["archive"] = {"format": FORMAT, "study": study.name,
                                  "description": getattr(study, "description", "") or ""}
                self._write_index(idx)

    def check_study(self, study):
        """Refuses (ArchiveError) an archive that holds another study than
        `study`; one that holds none yet, or this one, passes. Writes nothing."""
        from .study.rundir import same_toml
        copy = os.path.join(self.dir, "study.toml")
        if os.path.exists(copy) and not same_toml(open(copy, "rb").read(), study.text):
            raise ArchiveError(f"{self.dir} archives another study than {study.path} ({copy} differs): "
                               "give another archive, or restore the study file")

    def add_run(self, name, run_dir, status, axes, study_name, command):
        """Reduce run_dir/run.h5 into runs/<name>.h5 and list it; returns its
        index entry. Refuses an entry over MAX_BYTES (naming its largest
        datasets) rather than keep it."""
        rdir = os.path.join(self.dir, "runs")
        os.makedirs(rdir, exist_ok=True)
        final = os.path.join(rdir, name + ".h5.gz")
        tmp = f"{final}.tmp.{socket.gethostname()}.{os.getpid()}"
        prov = provenance_of(run_dir, status, study_name, command)
        try:
            reduce_run(os.path.join(run_dir, "run.h5"), tmp + ".h5", prov)
            gzip_file(tmp + ".h5", tmp)
            size = os.path.getsize(tmp)
            if size > MAX_BYTES:
                raise ArchiveError(f"{name}: the reduced run is {size} bytes compressed, over {MAX_BYTES}: largest "
                                   "datasets " + ", ".join(f"{n} ({b} bytes)" for n, b in largest_datasets(tmp + ".h5")[:4]))
            digest = sha256_of(tmp)
        finally:
            if os.path.exists(tmp + ".h5"):
                os.remove(tmp + ".h5")
        if not os.path.exists(tmp):
            raise ArchiveError(f"{name}: the entry was not written")
        entry = dict(axes)
        entry.update({k: status[k] for k in RUN_KEYS if k in status})
        entry.update({"state": "complete", "file": os.path.relpath(final, self.dir), "bytes": size,
                      "sha256": digest, "source_sha256": prov["source_sha256"]})
        with self._locked():
            os.replace(tmp, final)
            idx = self.read()
            idx["runs"][name] = entry
            self._write_index(idx)
        return entry

    def add_pilot(self, name, status):
        with self._locked():
            idx = self.read()
            idx["pilots"][name] = {k: status[k] for k in PILOT_KEYS if k in status}
            self._write_index(idx)

    def _write_index(self, idx):
        a = idx["archive"]
        text = [f"# dynhet results archive of study {a.get('study', '?')}: one reduced run.h5 per complete run",
                "# (launch_scripts/archive_study.sh, or run_study.sh with the study's archive); written by the",
                "# tools, never by hand: an entry whose file differs from its size or sha256 here is refused.",
                "", "[archive]"]
        text += [f"{k} = {toml_value(v)}" for k, v in a.items()]
        for section in ("runs", "pilots"):
            for name in sorted(idx[section]):
                text += ["", f'[{section}."{name}"]']
                text += [f"{k} = {toml_value(v)}" for k, v in idx[section][name].items()]
        write_atomic(self.index_path, "\n".join(text) + "\n")


def largest_datasets(path):
    out = []
    with h5py.File(path, "r") as f:
        f.visititems(lambda n, o: out.append((n, o.id.get_storage_size())) if isinstance(o, h5py.Dataset) else None)
    return sorted(out, key=lambda x: -x[1])


# -- results/README.md

README_HEAD = """# results: the archived runs every generated document comes from

Each folder is one study's results archive (python/dynhet/archive.py): its
study file, its base scene, index.toml (every archived run with its axes,
CPU time, size and sha256, and the pilots' tau_alpha) and runs/, one reduced
run.h5 per complete run with its provenance (the resolved scene, the build,
the study layer's commit, the command, CPU seconds, dates). Run directories
are scratch; this is the record. `launch_scripts/run_study.sh
studies/<study>.toml` writes into results/<study> as each run completes and
resumes from it; `launch_scripts/analyse_study.sh results/<study>` analyses
it. This page is generated (`launch_scripts/study.py results`).

| study | what | command | runs archived | CPU-hours | size |
|---|---|---|---|---|---|
"""


def study_summary(d):
    """(name, description, runs archived, runs planned, CPU-hours, bytes) of one archive."""
    from .study.model import Study, StudyError
    idx = Archive(d).read()
    runs = idx["runs"]
    try:
        planned = len(list(Study(os.path.join(d, "study.toml"), os.path.join(d, "base_scene.toml")).points()))
    except (StudyError, OSError):
        planned = None
    cpu = (sum(float(r.get("cpu_s", 0.0)) for r in runs.values())
           + sum(float(p.get("cpu_s", 0.0)) for p in idx["pilots"].values())) / 3600
    size = sum(int(r.get("bytes", 0)) for r in runs.values())
    return idx["archive"].get("study", os.path.basename(d)), idx["archive"].get("description", ""), len(runs), \
        planned, cpu, size


def check_provenance(root, files):
    """What a check's reduced run (run.h5.gz) records of how it was made:
    its hash, its command and its CPU (or wall) seconds."""
    import zlib
    if "run.h5.gz" not in files:
        return []
    p = os.path.join(root, "run.h5.gz")
    digest = sha256_of(p)
    try:
        with h5py.File(readable(p, digest), "r") as f:
            a = dict(f["provenance"].attrs) if "provenance" in f else {}
    except (OSError, EOFError, zlib.error) as e:   # not gzip, cut short, corrupt
        return [f"run.h5.gz not readable: {e}"]
    out = [f"run.h5.gz sha256 {digest[:16]}…"]
    out += [f"command `{a['command']}`"] if "command" in a else []
    if "cpu_s" in a:
        out.append(f"{float(a['cpu_s']) / 3600:.2f} CPU-hours")
    elif "wall_s" in a:
        out.append(f"{float(a['wall_s']) / 3600:.2f} hours of wall time, CPU not recorded")
    return out


def results_readme(results):
    """The text of results/README.md: one line per archived study."""
    lines = [README_HEAD]
    total = 0
    for s in sorted(os.listdir(results)):
        d = os.path.join(results, s)
        if not is_archive(d):
            continue
        name, what, n, planned, cpu, size = study_summary(d)
        total += size
        of = f" of {planned}" if planned is not None else ""
        lines.append(f"| `{s}` | {what} | `launch_scripts/run_study.sh studies/{name}.toml` | {n}{of} | {cpu:.2f} "
                     f"(runs and pilots) | {size / 2**20:.1f} MiB |\n")
    checks = []   # folders of single runs beside the studies, each with a README that says what and how
    for root, dirs, files in sorted(os.walk(results)):
        dirs[:] = sorted(x for x in dirs if not is_archive(os.path.join(root, x)))
        if root != results and "README.md" in files:
            with open(os.path.join(root, "README.md")) as fh:
                title = fh.readline().lstrip("# ").strip()
            size = sum(os.path.getsize(os.path.join(root, f)) for f in files)
            total += size
            checks.append(f"- `{os.path.relpath(root, results)}`: {title} ({size / 2**10:.0f} KiB"
                          + "".join(f"; {x}" for x in check_provenance(root, files))
                          + "; its README.md says how it was made)\n")
    if checks:
        lines.append("\nChecks: single runs beside the studies, each with the scene, the reduced run and how it was made.\n\n")
        lines += checks
    lines.append(f"\nIn all {total / 2**20:.1f} MiB of entries (the folder is kept under 150 MB).\n")
    return "".join(lines)
