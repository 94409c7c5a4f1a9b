"""The paper's results from a study's runs (issue: the paper from our own runs).

Usage: analyse_study.py STUDY_DIR [--table FILE] [--quiet]

Reads STUDY_DIR/index.toml and every complete run's run.h5 and writes
  STUDY_DIR/study.h5         every per-run and per-point quantity used, every
                             fit with its error, range and quality
  STUDY_DIR/figures/*.png    one figure per result of the paper (sec. 3)
  STUDY_DIR/reproduction.md  one row per result: the paper's number, ours
                             with its error, agreement, the CPU time behind it
  STUDY_DIR/finite_size.md   every measure against N where a density was run
                             at several N, with a verdict (converged or drifting)
(--table FILE writes the table there as well, e.g. docs/reproduction.md;
--finite-size FILE the finite-size report, its figures in finite_size/ beside it).
"""
import argparse
import math
import os
import sys
import time

import matplotlib

matplotlib.use("Agg")  # a batch tool: figures to files

from .. import fits as sf
from .config import A_MAIN, CONVENTIONS, EPS_MAIN, say
from .study import Analysis

# What a section needs (a key of a run's cut), and the observable that gives it.
NEEDS = {"chi4": "chi4", "s4_q": "s4", "cl_lag": "clusters", "D": "msd", "D_cr": "msd with cage_relative"}
from .overlap import ageing_results, overlap_results, tau_results
from .transport import d_results, pdx_results
from .clusters import cluster_results
from .chi4_s4 import chi4_results, fss_results, joint_fit, s4_results
from .size import d_n_results, kappa_n_results, tau_n_results
from .local_measures import local_n_results, local_phi_results
from .cutoff import cutoff_results
from .restitution import restitution_results
from .appendix import appendix_results
from .driving import driving_results, driving_rows
from .finite_size import write_finite_size
from .restate import exists as restate_exists
from .output import write_h5, write_table


def stated_args(args):
    """The command line as the documents state it: without --out and its
    directory (where the scratch output went is not what made the numbers)."""
    out, skip = [], False
    for x in args:
        if skip:
            skip = False
        elif x == "--out":
            skip = True
        elif not x.startswith("--out="):
            out.append(x)
    return out


def out_dir(study_dir, out):
    """Where the analysis writes: --out, else the study directory, else (a
    results archive, which holds runs only) runs/analysis-<study> of the
    repository."""
    from ..archive import is_archive
    if out:
        return out
    if not is_archive(study_dir):
        return study_dir
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
    return os.path.join(root, "runs", "analysis-" + os.path.basename(os.path.abspath(study_dir).rstrip("/")))


DOC = __doc__.rstrip("\n") + "\n\nConventions " + CONVENTIONS


def main(argv=None):
    ap = argparse.ArgumentParser(description=DOC.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=DOC.split("\n\n", 1)[1])
    ap.add_argument("study_dir", help="a study directory (run_study.sh --out) or a results archive (results/<study>)")
    ap.add_argument("--out", metavar="DIR",
                    help="write study.h5, reproduction.md, finite_size.md and figures/ here (default: the study "
                         "directory; for a results archive, runs/analysis-<study> beside the repository's results/)")
    ap.add_argument("--table", help="also write the reproduction table here (e.g. docs/reproduction.md)")
    ap.add_argument("--finite-size", metavar="FILE",
                    help="also write the finite-size report here (e.g. docs/finite_size.md)")
    ap.add_argument("--discussion", help="a Markdown file appended to the table (what we found about each disagreement)")
    ap.add_argument("--also", action="append", default=[], metavar="STUDY_DIR",
                    help="another study whose runs add points: tau_alpha against N where it ran other N, and the "
                         "cutoff figure from whichever study's lags reach furthest")
    ap.add_argument("--largest-n", action="store_true",
                    help="at each density of the study, take the point of the largest N over it and the --also "
                         "studies for every row and fit (the table says which N each density has)")
    ap.add_argument("--command", metavar="TEXT",
                    help="the command the documents state as having made them (default: this one, without --out); "
                         "launch_scripts/reproduce.sh names itself")
    ap.add_argument("--restate", metavar="OLD_TABLE",
                    help="an earlier reproduction.md (a file, or COMMIT:PATH from git history): append, for each row it judged \"differs\", the verdict now")
    ap.add_argument("--restate-via", action="append", default=[], metavar="LABEL=TABLE",
                    help="a table made between --restate's and this one (repeatable, in order): a column of its "
                         "verdicts, and the change column says at which step each verdict moved")
    a = ap.parse_args(argv)
    if a.restate and not restate_exists(a.restate):
        raise SystemExit(f"analyse_study: --restate {a.restate}: no such file")
    via = []
    for v in a.restate_via:
        label, eq, path = v.rpartition("=")  # the last "=": a label may hold one (N = 4096)
        if not eq or not label or not path:
            raise SystemExit(f"analyse_study: --restate-via {v}: give LABEL=TABLE (e.g. \"other seeds=old.md\")")
        if not restate_exists(path):
            raise SystemExit(f"analyse_study: --restate-via {v}: no such file {path}")
        via.append((label, path))
    if via and not a.restate:
        raise SystemExit("analyse_study: --restate-via needs --restate (the table the steps start from)")
    t0 = time.time()
    A = Analysis(a.study_dir, a.also, out_dir(a.study_dir, a.out))
    os.makedirs(A.out, exist_ok=True)
    if a.largest_n:
        if not a.also:
            raise SystemExit("analyse_study: --largest-n takes the largest N over the --also studies: give at least one")
        say("analyse_study: largest N: " + (", ".join(f"φ {p.phi:g} ({p.pairs}, ε {p.eps:g}): N = {p.N} from "
                                                       f"{p.study} ({len(p.runs)} seed{'s' if len(p.runs) > 1 else ''})"
                                                       for p in A.promote_largest_n()) or "no --also study has a larger N"))
    if not A.points:
        raise SystemExit(f"analyse_study: no complete run with a = {A_MAIN} in {a.study_dir}"
                         + (f" ({len(A.skipped)} left out: {A.skipped[0][0]}: {A.skipped[0][1]}, ...)" if A.skipped else ""))
    say(f"analyse_study: {sum(len(p.runs) for p in A.points.values())} runs at {len(A.points)} points"
        + (f"; {len(A.skipped)} runs left out (not complete)" if A.skipped else ""))
    failed = []

    def step(name, fn, *args, needs=(), on=None):
        on = on or A  # the analysis the section runs on (the cage-relative view, say)
        say(f"  {name}" + (", cage-relative" if on is not A else ""))
        if not A.series():
            A.row(name, "—", "—", f"no run of the main series (pairs = neighbours, ε = {EPS_MAIN:g})", "not determined", "", [])
            return None
        # A study that does not compute an observable (its scene's
        # observables.compute) has no result that needs it: said, not failed.
        lacking = [k for k in needs
                   if not any(k in r["cut"].get(A_MAIN, {}) or k in r for p in on.series() for r in p.runs)]
        if lacking:
            on.row(name, "—", "—", "not computed in this study (" + ", ".join(NEEDS[k] for k in lacking) + ")",
                   "not run", "", [])
            return None
        try:
            return fn(on, *args)
        except Exception as e:  # one result that cannot be made must not cost the others
            import traceback
            traceback.print_exc()
            label = name + (" (cage-relative)" if on is not A else "")  # never mistaken for the standard row
            failed.append(label)
            A.row(label, "—", "—", f"analysis failed: {type(e).__name__}: {e}", "failed", "", [])
            return None

    for name, fn, needs in (("overlap", overlap_results, ()), ("ageing", ageing_results, ()),
                            ("D", d_results, ("D",)), ("P(dx)", pdx_results, ())):
        step(name, fn, needs=needs)
    # The joint fit first: the critical fits are also given with its phi_c.
    joint = step("joint fit of tau_alpha, chi4, xi", joint_fit, needs=("chi4", "s4_q"))
    res = step("tau_alpha(phi)", tau_results, joint)
    phi_c = res[0].p["xc"] if res and res[0].ok else math.nan
    phi_c_why = sf.cannot_judge(res[0], "xc") if res and res[0].ok else None
    step("clusters", cluster_results, phi_c, phi_c_why, joint, needs=("cl_lag",))
    step("chi4", chi4_results, phi_c, joint, needs=("chi4",))
    step("S4 and xi", s4_results, joint, needs=("s4_q",))
    step("finite size", fss_results, joint, needs=("chi4", "s4_q"))
    step("tau_alpha against N", tau_n_results)
    step("D against N", d_n_results)
    step("kappa against N", kappa_n_results, needs=("cl_lag",))
    step("cage-relative tau_alpha and bond breaking against phi", local_phi_results)
    step("cage-relative tau_alpha and bond breaking against N", local_n_results)
    step("cutoff a", cutoff_results)
    step("restitution", restitution_results)
    step("appendix", appendix_results, needs=("chi4", "s4_q"))
    if A.has_cage_relative():
        # tau_alpha, the joint fit, chi4, S4 and xi, the clusters again, of
        # the cage-relative displacements: the same code on a view of the runs.
        C = A.cage_relative_view()
        joint_cr = step("joint fit of tau_alpha, chi4, xi", joint_fit, needs=("chi4", "s4_q"), on=C)
        res_cr = step("tau_alpha(phi)", tau_results, joint_cr, on=C)
        phi_c_cr = res_cr[0].p["xc"] if res_cr and res_cr[0].ok else math.nan
        why_cr = sf.cannot_judge(res_cr[0], "xc") if res_cr and res_cr[0].ok else None
        step("clusters", cluster_results, phi_c_cr, why_cr, joint_cr, needs=("cl_lag",), on=C)
        step("chi4", chi4_results, phi_c_cr, joint_cr, needs=("chi4",), on=C)
        step("S4 and xi", s4_results, joint_cr, needs=("s4_q",), on=C)
        step("D", d_results, needs=("D_cr",), on=C)   # theta of the cage-relative D against tau_alpha^CR
    A.driving = ({}, "")
    step("driving rules", driving_results)
    driving_rows(A)
    write_h5(A, os.path.join(A.out, "study.h5"))
    cmd = a.command or "launch_scripts/analyse_study.sh " + " ".join(stated_args(argv if argv is not None else sys.argv[1:]))
    write_table(A, os.path.join(A.out, "reproduction.md"), cmd, a.discussion, a.restate, via)
    if a.table:
        write_table(A, a.table, cmd, a.discussion, a.restate, via)
    try:
        densities = write_finite_size(A, os.path.join(A.out, "finite_size.md"), cmd)
        if a.finite_size:
            write_finite_size(A, a.finite_size, cmd)
        say(f"  finite size: {densities} densities run at several N")
    except Exception:  # the report must not cost the table
        import traceback
        traceback.print_exc()
        failed.append("finite-size report")
    differ = [r["item"] for r in A.rows if r["verdict"].startswith("differs")]
    say(f"analyse_study: {len(A.rows)} rows, {len(differ)} differ from the paper; {len(A.fits)} fits; "
        f"study.h5, reproduction.md and {(len(os.listdir(A.figdir)) if os.path.isdir(A.figdir) else 0)} figures in {A.out} ({time.time() - t0:.1f} s)")
    if failed:
        say(f"analyse_study: FAILED: {', '.join(failed)} (the rest is written)")
        return 1
    return 0
