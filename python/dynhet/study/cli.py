"""dynhet studies: a sweep of scenes, run on this machine or on a Slurm
cluster, resumable. launch_scripts/run_study.sh is the command; this is its
engine. A run stays what it is (launch_scripts/run_scene.sh: one scene, its
processes on a private bus, one run.h5); a study only writes scenes, starts
runs, reads their files and keeps their status on disk.

  study.py run STUDY.toml [--executor local|slurm] [--jobs K] [--out DIR] [--dry-run] [--no-figures]
                          [--partition P] [--time T] [--mem M] [--sbatch ARG]...
  study.py task DIR NAME      one run of a study directory (what a Slurm task runs)
  study.py index DIR [--analyse [--no-figures]]
                              write DIR/index.toml from the runs' status files (and then, every
                              run complete, the study analysis: what the Slurm index job runs)
  study.py results [DIR]      write DIR/README.md (default results/): a line per archived study
  study.py archive DIR [--to ARCHIVE]
                              reduce every complete run of study directory DIR into its results
                              archive (the study's [study] archive, or ARCHIVE): dynhet.archive

The study file format is in studies/README.md."""
import argparse
import os
import signal
import subprocess
import sys

from .paths import ROOT, SIM
from .toml_io import toml_dump, write_atomic
from .model import Study, StudyError
from .rundir import StudyDir
from .index import dry_run, plan, run_order, write_index
from .local import analyse, run_local
from .slurm import run_slurm, task


def raise_interrupt(*_):
    raise KeyboardInterrupt


def main():
    signal.signal(signal.SIGTERM, raise_interrupt)
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("study")
    r.add_argument("--executor", choices=["local", "slurm"], default="local")
    r.add_argument("--jobs", type=int, default=0, help="runs at once (local: default the cores / 2, at least 1; "
                                                       "slurm: array tasks at once, default no limit)")
    r.add_argument("--out", help="study directory (default runs/study-<name>)")
    r.add_argument("--dry-run", action="store_true")
    r.add_argument("--fresh", action="store_true",
                   help="the --out directory holds another study (or anything but a study): move it into "
                        "DIR/old-<time>/ and start this one (nothing is deleted)")
    r.add_argument("--order", choices=["longest", "shortest"], default="longest",
                   help="which runs start first: the longest estimated (default: the least wall time on a few "
                        "cores) or the shortest (the most runs complete and archived by any moment, for a "
                        "machine that may be lost before the study ends)")
    r.add_argument("--first", metavar="GLOB", action="append", default=[],
                   help="start the runs whose names match this shell pattern before all others (repeatable: "
                        "the first pattern's runs first), e.g. --first 'phi0.7900_*_n65536_*': the runs a "
                        "result waits for, ahead of the rest")
    r.add_argument("--archive", metavar="DIR",
                   help="the results archive each complete run is reduced into (default: the study file's "
                        "[study] archive, relative to the repository; none if it names none)")
    r.add_argument("--no-figures", action="store_true",
                   help="the study analysis at the end writes its text and study.h5 but draws no figure "
                        "(analyse_study.sh --no-figures); on Slurm, the index job's analysis too")
    r.add_argument("--partition")
    r.add_argument("--time")
    r.add_argument("--mem")
    r.add_argument("--signal-lead", type=float, default=120,
                   help="slurm: seconds before the time limit at which a task is told to checkpoint and stop "
                        "(sbatch --signal). A stop takes the sim's whole engine to disk: 5-6 s at N = 10^6 and "
                        "21 s at 4 x 10^6 measured on a loaded 2-core machine (docs/checkpoints.md); default 120")
    r.add_argument("--max-requeues", type=int, default=20,
                   help="slurm: a task interrupted by its time limit goes back in the queue at most this often")

    r.add_argument("--sbatch", action="append", default=[], help="extra sbatch flag, e.g. --sbatch=--qos=long")
    t = sub.add_parser("task")
    t.add_argument("dir")
    t.add_argument("name")
    i = sub.add_parser("index")
    i.add_argument("dir")
    i.add_argument("--analyse", action="store_true", help="then, if every run is complete, the study analysis")
    i.add_argument("--no-figures", action="store_true", help="with --analyse: the analysis draws no figure")
    ar = sub.add_parser("archive")
    ar.add_argument("dir")
    ar.add_argument("--to", metavar="ARCHIVE", help="the archive directory (default: the study's own)")
    rs = sub.add_parser("results")
    rs.add_argument("dir", nargs="?", default=os.path.join(ROOT, "results"))
    a = ap.parse_args()
    if a.cmd == "index" and a.no_figures and not a.analyse:
        ap.error("index --no-figures: the figures are the analysis's, give --analyse as well")
    if a.cmd == "results":
        from ..archive import results_readme
        write_atomic(os.path.join(a.dir, "README.md"), results_readme(a.dir))
        print(f"wrote {os.path.join(a.dir, 'README.md')}")
        return 0
    # A StudyError before anything runs (the study file, the directory, the
    # scenes) is a bad argument, exit 2; once runs start, a run-time failure, 1.
    running = False
    try:
        if a.cmd == "run":
            study = Study(a.study)
            sd = StudyDir(study, a.out or os.path.join(ROOT, "runs", f"study-{study.name}"),
                          os.path.abspath(a.archive) if a.archive else None)
            why = sd.refusal()
            if why and not a.fresh:
                raise StudyError(why)
            run_order(sd, [], {}, a.order, a.first)     # refuses a --first that names no run
            if a.dry_run:
                if why:
                    print(f"# --fresh: what {sd.dir} holds would move into {sd.dir}/old-<time>/")
                elif os.path.exists(os.path.join(sd.dir, "study.toml")):
                    sd.claim()  # (its own study: the archive it names is checked too)
                check_scenes(sd)
                dry_run(sd)
                return 0
            check_scenes(sd)
            moved = sd.claim(fresh=a.fresh)
            if moved:
                print(f"run_study: --fresh: what {sd.dir} held is now in {moved}", flush=True)
            running = True
            if a.executor == "local":
                return run_local(sd, a.jobs or max(1, (os.cpu_count() or 2) // 2), a.order, a.first,
                                 figures=not a.no_figures)
            return run_slurm(sd, a)
        sd = StudyDir(Study(os.path.join(a.dir, "study.toml"), os.path.join(a.dir, "base_scene.toml")), a.dir,
                      os.path.abspath(a.to) if getattr(a, "to", None) else None)
        running = True
        if a.cmd == "archive":
            return archive_dir(sd)
        if a.cmd == "task":
            return task(sd, a.name)
        rows = write_index(sd)
        states = {}
        for row in rows.values():
            states[row["state"]] = states.get(row["state"], 0) + 1
        print(f"study {sd.study.name}: " + ", ".join(f"{v} {k}" for k, v in sorted(states.items())))
        if set(states) != {"complete"}:
            return 1
        return analyse(sd, figures=not a.no_figures) if a.analyse else 0
    except StudyError as e:
        print(f"run_study: {e}", file=sys.stderr)
        return 1 if running else 2
    except KeyboardInterrupt:  # stopped before the executor took over (checking the scenes): nothing ran
        print("run_study: stopped before any run started; the same command starts again", file=sys.stderr)
        return 75  # (interrupted: the same command goes on)


def archive_dir(sd):
    """study.py archive: every complete run of a study directory into its archive."""
    from ..archive import ArchiveError
    from .archiving import archive_existing
    if sd.archive is None:
        raise StudyError(f"{sd.dir}: the study names no archive ([study] archive): give --to DIR")
    try:
        sd.archive.claim(sd.study)
    except ArchiveError as e:
        raise StudyError(str(e)) from None
    added, kept, left = archive_existing(sd)
    n = len(sd.archive.runs())
    print(f"study {sd.study.name}: {added} runs archived now, {kept} already, {left} not complete; "
          f"{n} runs in {sd.archive.dir}", flush=True)
    return 0


def check_scenes(sd):
    """Every point's scene through sim_node --check, before anything runs."""
    if not os.access(SIM, os.X_OK):
        raise StudyError(f"no sim_node at {SIM}: build it first (launch_scripts/setup.sh, or run_study.sh "
                         "without --no-build), or point BUILD_DIR at a build that has it")
    problems = []
    tmp = os.path.join("/tmp", f"dynhet-study-check-{os.getpid()}.toml")
    try:
        for p, sc, *_ in plan(sd):
            write_atomic(tmp, toml_dump(sc))
            r = subprocess.run([SIM, tmp, "--check"], capture_output=True, text=True)
            if r.returncode != 0:
                msg = " ".join(r.stderr.strip().replace(tmp, "scene").split())
                problems.append(f"{sd.study.run_name(p)}: {msg}")
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
    if problems:
        raise StudyError(f"{sd.study.path}: {len(problems)} of the study's scenes would be refused:\n  " +
                         "\n  ".join(problems))
