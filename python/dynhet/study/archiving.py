"""A study and its results archive (dynhet.archive): each run's entry written
the moment the run completes, each pilot's tau_alpha kept, and a study whose
run directories are gone resumed from the archive (archived runs count as
complete; archived pilots are not run again)."""
import os
import sys

from ..archive import Archive, ArchiveError
from .model import AXES, StudyError
from .paths import ROOT
from .rundir import archived_status, read_status, write_status


def resolve(path):
    """An archive path of a study file or flag: absolute, or relative to the
    repository (results/<study>)."""
    return path if os.path.isabs(path) else os.path.join(ROOT, path)


def command_of(sd):
    return (f"launch_scripts/run_study.sh {os.path.relpath(sd.study.path, ROOT)}"
            + (f" (study directory {sd.dir})" if sd.dir else ""))


def archive_run(sd, p, status, log=print):
    """Write run p's entry (its run.h5 reduced, with provenance); a failure is
    said and leaves the run complete (its directory still holds it: archive
    it later with launch_scripts/archive_study.sh)."""
    if sd.archive is None:
        return
    name = sd.study.run_name(p)
    try:
        e = sd.archive.add_run(name, sd.run_dir(p), status, {a: p[a] for a in AXES}, sd.study.name, command_of(sd))
        log(f"{name}: archived in {os.path.relpath(sd.archive.dir, ROOT)} ({e['bytes'] / 1024:.0f} KiB)")
    except (ArchiveError, OSError) as e:
        log(f"{name}: NOT archived: {e}")


def archive_pilot(sd, name, status):
    if sd.archive is not None:
        try:
            sd.archive.add_pilot(name, status)
        except (ArchiveError, OSError) as e:
            print(f"pilot {name}: NOT archived: {e}", file=sys.stderr, flush=True)


def restored_run(sd, p):
    """Run p's status from the archive, written into its directory, where the
    archive holds it and the directory does not hold it complete; None
    otherwise. A corrupted entry is refused by name (StudyError)."""
    if sd.archive is None:
        return None
    name = sd.study.run_name(p)
    entry = sd.archive.runs().get(name)
    if entry is None:
        return None
    try:
        sd.archive.path(name, entry)
    except ArchiveError as e:
        raise StudyError(str(e)) from None
    st = dict(archived_status(entry, p), archived=os.path.join(sd.archive.dir, entry["file"]))
    os.makedirs(sd.run_dir(p), exist_ok=True)
    write_status(sd.run_dir(p), st)
    return st


def restore_archived(sd, points, log=print):
    """Every run of points that the archive holds and its directory does not
    hold complete, restored (restored_run) before an executor plans its
    queue, so that the queue, its order and its ETA hold only what is to
    run; returns how many."""
    n = 0
    for p in points:
        if read_status(sd.run_dir(p)).get("state") == "complete":
            continue
        try:
            n += restored_run(sd, p) is not None
        except (StudyError, OSError) as e:
            # left to its run (do_run), which meets the same entry and fails by name, alone
            log(f"{sd.study.run_name(p)}: NOT restored from the archive: {e}")
    if n:
        log(f"study {sd.study.name}: {n} runs complete in the archive {sd.archive.dir}; not run again")
    return n


def restored_pilot(sd, name, d):
    """A pilot's complete status from the archive (written into d), or None."""
    if sd.archive is None:
        return None
    st = sd.archive.read()["pilots"].get(name)
    if not st or st.get("state") != "complete":
        return None
    os.makedirs(d, exist_ok=True)
    write_status(d, dict(st, restored_from=sd.archive.dir))
    return dict(st)


def archive_existing(sd, log=print):
    """Archive every complete run (and pilot) of a study directory that the
    archive lacks or holds from another run.h5; returns (added, kept, not
    complete)."""
    from ..archive import sha256_of
    added = kept = left = 0
    have = sd.archive.runs()
    for p in sd.study.points():
        name, d = sd.study.run_name(p), sd.run_dir(p)
        st = read_status(d)
        if st.get("state") != "complete" or not os.path.exists(os.path.join(d, "run.h5")):
            left += int(name not in have)
            continue
        if name in have and have[name].get("source_sha256") in (None, sha256_of(os.path.join(d, "run.h5"))):
            kept += 1
            continue
        archive_run(sd, p, st, log)
        added += 1
    pdir = os.path.join(sd.dir, "pilots")
    if os.path.isdir(pdir):
        for name in sorted(os.listdir(pdir)):
            st = read_status(os.path.join(pdir, name))
            if st.get("state") == "complete":
                archive_pilot(sd, name, st)
    return added, kept, left
