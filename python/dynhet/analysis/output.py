"""study.h5 and the reproduction table."""
import math
import os
import re
import time

import h5py
import numpy as np

from .points import MIN_CAL_DOF
from .quantities import PER_RUN, chi4_at_tau, cut, tau, xi_at_tau
from .verdicts import fmt
from .config import A_MAIN, CONVENTIONS, EPS_MAIN, shown_path
from .restate import compare, restate


def write_h5(A, path):
    tmp = path + ".tmp"
    with h5py.File(tmp, "w") as f:
        f.attrs["study_dir"] = A.dir
        f.attrs["created"] = time.strftime("%Y-%m-%dT%H:%M:%S")
        f.attrs["conventions"] = CONVENTIONS.strip()
        pg = f.create_group("points")
        for key, p in sorted(A.points.items()):
            g = pg.create_group(f"{p.pairs}_eps{p.eps:g}_phi{p.phi:g}_n{p.N}")
            g.attrs.update(pairs=p.pairs, restitution=p.eps, packing_fraction=p.phi, n_particles=p.N,
                           seeds=np.array([r["seed"] for r in p.runs]), runs=",".join(r["name"] for r in p.runs),
                           cpu_s=A.cpu_of([p]))
            for name, fn in PER_RUN.items():
                vals = p.values(fn)
                m, e, sem, n = p.mean(fn)
                d = g.create_dataset(name, data=np.array([[v, q] for _, v, q in vals], float))
                d.attrs.update(columns="value, quoted error (one row per seed, in attribute seeds' order)",
                               mean=m, error=e, seed_spread_error=sem, n=n)
            c = cut(p.runs[0])
            g.create_dataset("q_lag", data=c["lag"])
            g.create_dataset("q_mean", data=np.nanmean([cut(r)["q"] for r in p.runs], axis=0))
            if "chi4" in c:
                g.create_dataset("chi4_subbox_particles", data=c["chi4_N"])
                g.create_dataset("chi4_peak_mean", data=np.nanmean([cut(r)["chi4_peak"] for r in p.runs], axis=0))
        fg = f.create_group("fits")
        for name, fit in sorted(A.fits.items()):
            h = fg.create_group(name)
            h.attrs.update(form=fit.form, chi2=fit.chi2, dof=fit.dof, n_points=fit.n, x_min=fit.x_range[0],
                           x_max=fit.x_range[1], note=fit.note or "",
                           error_from=getattr(fit, "error_from", None) or
                           "jackknife over seeds; with fewer than 4 seeds at least err_fit, and where "
                           "chi2/dof > 1 at least err_fit * sqrt(chi2/dof) (err_fit: the fit's own covariance)")
            if np.isfinite(getattr(fit, "quality", math.nan)):
                h.attrs["quality"] = fit.quality  # a collapse's (collapse.py): not a chi2
            quoted = getattr(fit, "quoted", {})
            for n_ in fit.names:
                h.attrs[n_] = fit.p[n_]
                h.attrs[n_ + "_err"] = quoted.get(n_, fit.error(n_))
                h.attrs[n_ + "_err_fit"] = fit.err[n_]
        rg = f.create_group("reproduction")
        dt = h5py.string_dtype()
        for col in ("item", "section", "paper", "ours", "verdict", "figure", "note"):
            rg.create_dataset(col, data=np.array([r[col] for r in A.rows], dtype=object), dtype=dt)
        rg.create_dataset("cpu_s", data=np.array([r["cpu"] for r in A.rows], float))
        if A.skipped:
            f.attrs["skipped_runs"] = "; ".join(f"{n}: {s}" for n, s in A.skipped)
    os.replace(tmp, path)


def calibration_lines(A):
    """Each study's quoted errors against its seeds' spread, per quantity
    (points.calibration): the factor its per-point errors take. The study's
    own points first, then those --largest-n took from other studies."""
    pops = []
    for p in list(A.points.values()):
        if p.population is not None and all(p.population is not q for q in pops):
            pops.append(p.population)
    out = []
    for pop in pops:
        cells = []
        for name, fn in PER_RUN.items():
            k, r, u, dof = pop.calibration(fn)
            borrowed = pop.borrows(fn)
            if dof:
                cells.append(f"{name} {r:.2f} ± {u:.2f} ({dof} dof{', all studies' if borrowed else ''})"
                             + (f" → × {k:.2f}" if k != 1.0 else ""))
        if cells:
            out.append(f"study {pop.name or A.study_name}: " + "; ".join(cells))
    if not out:
        return []
    return ["The seeds' spread over the errors the runs quote, pooled over each study's points (`points.calibration`; "
            "about 1 where the quoted errors are honest; \"all studies\": the study has fewer than "
            f"{MIN_CAL_DOF} dof of its own and takes the ratio pooled over every study analysed with it), and the "
            "factor (→) by which a quantity's quoted errors are scaled where that ratio has at least "
            f"{MIN_CAL_DOF} dof and lies more than 2 of its uncertainties above 1. " + ". ".join(out) + ".", ""]


def hms(s):
    s = int(round(s))
    return f"{s // 3600}:{s % 3600 // 60:02d}:{s % 60:02d}"


CR_SUFFIX = " (cage-relative)"


def side_by_side(rows):
    """Every result the table states both ways, the
    standard measure beside the cage-relative one (its rows "... (cage-
    relative)"), in the table's order; [] where there are none. A pair is
    the same section and the same name up to its numbers (a phi_c held at
    another value, the highest density run), taken in order; a cage-relative
    row without a standard one stands alone."""
    def key(r, item):
        return r["section"], re.sub(r"[0-9]+(?:\.[0-9]+)?", "#", item)
    cr = {}
    for r in rows:
        if r["item"].endswith(CR_SUFFIX):
            cr.setdefault(key(r, r["item"][:-len(CR_SUFFIX)]), []).append(r)
    if not cr:
        return []
    out = ["", "## Standard and cage-relative side by side", "",
           "Every result stated both ways: the standard measure (the paper's; its verdict as in the table) and the "
           "cage-relative one (displacements relative to the cage's centre, which removes the long-wavelength "
           "motion of two dimensions; its comparison with the paper's number is for information only).", "",
           "| result | paper | standard: ours, verdict | cage-relative: ours, against the paper |", "|---|---|---|---|"]

    def cr_cell(c, std_item):
        against = re.search(r"against the paper's standard measure: ((?:agrees|differs)(?: \([0-9.]+ σ\))?)",
                            c["note"] or "")
        # a fit that carries no verdict says so, as the standard column does
        unjudged = re.match(r"(not judged|not determined|not comparable)", c["note"] or "")
        own = c["item"][:-len(CR_SUFFIX)]
        return ((f"[{own}] " if own != std_item else "") + c["ours"]
                + (f"; {against.group(1)}" if against else f"; {unjudged.group(1)}" if unjudged else ""))
    for r in rows:
        if r["item"].endswith(CR_SUFFIX):
            continue
        k = key(r, r["item"])
        if cr.get(k):
            out.append(f"| {r['item']} | {r['paper']} | {r['ours']}; {r['verdict']} | {cr_cell(cr[k].pop(0), r['item'])} |")
    for left in cr.values():   # cage-relative rows no standard row matched
        for c in left:
            out.append(f"| {c['item']} | {c['paper']} | — | {cr_cell(c, c['item'][:-len(CR_SUFFIX)])} |")
    return out


def cpu_caveat(A):
    """What the CPU figures leave out: an attempt killed before it recorded
    its CPU (the study runner counts them, cpu_unrecorded); runs resumed by
    an older runner (attempts > 1) may miss earlier attempts' CPU the same way."""
    k, r = getattr(A, "cpu_unrecorded", 0), getattr(A, "cpu_resumed", 0)
    if not (k or r):
        return ""
    return (f" ({r} of the runs ran in more than one attempt: a resumed run's figure sums its attempts, but an "
            f"attempt killed before it recorded its CPU is not counted" + (f" ({k} such attempts recorded as lost)"
                                                                           if k else "")
            + ", and a run started over counts its last start only)")


def write_table(A, path, command, discussion=None, restate_from=None, via=(), compare_with=None):
    # (a point --largest-n took from another study is that study's runs, not this one's)
    n_runs = sum(len(p.runs) for p in A.points.values() if not any(p is q for q in getattr(A, "promoted", [])))
    total = sum(A.cpu.values())
    L = ["# The paper from our own runs", "",
         "Generated by `launch_scripts/analyse_study.py` (do not edit by hand): every row below comes from the "
         f"study in `{shown_path(A.dir)}`, "
         f"{n_runs} complete runs; {hms(total)} of CPU in the {getattr(A, 'cpu_runs', n_runs)} complete runs "
         f"of every study read and {hms(A.pilot_cpu)} in this study's pilots{cpu_caveat(A)}.",
         "", f"Command: `{command}`", "",
         "The paper: Avila, Castillo, Vollmayr-Lee, Zippelius, *Dynamical heterogeneities in a driven granular "
         "fluid* (`../shared/paper/`), section 3. Errors: jackknife over seeds for every cross-run fit (with fewer than "
         "4 seeds, or where χ²/dof > 1, at least the fit's own error, the latter times sqrt(χ²/dof)); for "
         "per-point values the runs' own errors combined (jackknife over origin blocks), scaled to the seeds' "
         "spread where the study's seeds scatter more than those errors say (below), or the standard error of "
         "the seed mean where no run quotes one. \"agrees\" means within 2 of our standard errors; a row "
         "marked \"differs\" is discussed below the table. CPU is that of the runs behind the row.", ""]
    L += calibration_lines(A)
    cr_note = cr_sizes_note(A)
    if getattr(A, "promoted", None):
        L += ["**At the largest N** (`--largest-n`): at these densities every row and fit takes the point of the "
              "largest N over the studies, not this study's own: "
              + "; ".join(f"φ = {p.phi:g} ({p.pairs}, ε = {p.eps:g}): N = {p.N}, study {p.study}, "
                          f"{len(p.runs)} seed{'s' if len(p.runs) > 1 else ''}" for p in A.promoted)
              + ". The other densities are this study's." + cr_note + largest_n_notes(A), ""]
    elif getattr(A, "held_back", None) or cr_note:
        L += ["**At the largest N** (`--largest-n`): no larger N taken." + cr_note + largest_n_notes(A), ""]
    if A.skipped:
        L += [f"Left out: {len(A.skipped)} runs not complete ({', '.join(sorted({s for _, s in A.skipped}))}).", ""]
    L += ["| result | paper (section, figure) | paper | ours | verdict | figure | CPU |", "|---|---|---|---|---|---|---|"]
    for r in A.rows:
        note = f" ({r['note']})" if r["note"] else ""
        L.append(f"| {r['item']} | {r['section']} | {r['paper']} | {r['ours']}{note} | {r['verdict']} | "
                 f"{figure_link(r['figure'])} | {hms(r['cpu'])} |")
    L += side_by_side(A.rows)
    if getattr(A, "driving_table", None):
        L += ["", "## The two driving rules side by side (ε = 0.9)", "",
              "`driving.pairs = \"neighbours\"` (a kick's partner within reach of the first particle) against `\"any\"` "
              "(two particles from the whole system); the paper does not say which it used (docs/engine.md, \"The "
              "driving model\")." + (f" Both at N = {A.driving_n}, the largest box both rules ran (not the "
                                      f"largest N of the neighbour series alone)." if getattr(A, "driving_n", None)
                                      else ""), "",
              "| quantity | paper | neighbours | any |", "|---|---|---|---|"]
        for lab, paper, a, b in A.driving_table:
            L.append(f"| {lab} | {paper} | {a} | {b} |")
    L += ["", "## Per point (ε, φ): the means over seeds", "",
          "Each point's study; where a larger N of another study stands in for this study's point (`--largest-n`), "
          "the rows take that one and this study's point is listed for comparison only (another protocol: the two "
          "may differ by more than their errors at the densities where τ_α depends on the run lengths).", "",
          "| pairs | ε | φ | N | study | seeds | τ_α | β | τ0 | D | χ4(τ_α) | ξ(τ_α) | d_f slow |",
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for key, p in sorted(A.points.items()):
        cells = []
        for fn in (tau, lambda r: (cut(r)["beta"], cut(r)["beta_err"]), lambda r: (cut(r)["tau0"], cut(r)["tau0_err"]),
                   lambda r: (r["D"], r["D_err"]), chi4_at_tau, xi_at_tau, lambda r: (cut(r)["cl_slow_d_f"], cut(r)["cl_slow_d_f_err"])):
            m, e, _, _ = p.mean(fn)
            cells.append(fmt(m, e))
        L.append(f"| {p.pairs} | {p.eps:g} | {p.phi:g} | {p.N} | {study_cell(A, p)} | {len(p.runs)} | "
                 + " | ".join(cells) + " |")
    if restate_from:
        L += restate(restate_from, A.rows, via)
    if compare_with:
        L += compare(*compare_with, A.rows)
    L.append("")
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path + ".tmp", "w") as fh:
        fh.write("\n".join(L))
        if discussion:
            with open(discussion) as d:
                fh.write("\n" + d.read())
    os.replace(path + ".tmp", path)
    copy_figures(A, os.path.dirname(os.path.abspath(path)))


def figure_link(figure):
    """A row's figure as a link relative to the table (figures/ beside it)."""
    return f"[{os.path.basename(figure)}]({figure})" if figure else "—"


def copy_figures(A, doc_dir):
    """The figures the analysis drew, into figures/ beside a table written
    outside the analysis's own output (docs/reproduction.md: its links then
    resolve in the repository); a figure there that this analysis did not
    draw is removed, never left as if current. Without figures (the text
    alone) the folder is left as the last full analysis drew it."""
    if not A.figures or os.path.abspath(doc_dir) == os.path.abspath(A.out) or not os.path.isdir(A.figdir):
        return
    import shutil
    to = os.path.join(doc_dir, "figures")
    os.makedirs(to, exist_ok=True)
    drawn = {f for f in os.listdir(A.figdir) if f.endswith(".png")}
    for f in drawn:
        shutil.copy(os.path.join(A.figdir, f), os.path.join(to, f))
    for f in os.listdir(to):
        if f.endswith(".png") and f not in drawn:
            os.remove(os.path.join(to, f))


def study_cell(A, p):
    """The per-point table's study of a point, and whether the rows take it:
    a larger N of another study stands in for the study's own (--largest-n)."""
    promoted = getattr(A, "promoted", None) or []
    name = getattr(p, "study", None) or getattr(A, "study_name", "")
    if any(p is q for q in promoted):
        return f"{name} (the rows take it)"
    if any(q.pairs == p.pairs and q.eps == p.eps and q.phi == p.phi for q in promoted):
        return f"{name} (not in the rows)"
    return name


def still_drifting(multi, d, d_cr, n_top):
    """The quantities of the finite-size table (standard and cage-relative)
    whose verdict over the sizes up to n_top at one density says "drifting":
    the rows taken at that N carry them, not only tau_alpha ("name: the drift
    per doubling")."""
    from .finite_size import quantity_rows
    from .steady import change_dof, steady_off
    from .points import measured_error
    from .size_rows import quantities
    out = []
    phi = next(iter(d.values())).phi if d else None
    for name, slug, fn, has_cr_version, _ in quantities(multi, {phi: d_cr} if d_cr else {}):
        if slug == "tau_b":    # its points are another study's (tau_b_points); its own row says
            continue
        for cr in ((False, True) if has_cr_version else (False,)):
            src = d_cr if cr else d
            sub = {n: q for n, q in src.items() if n <= n_top}
            if len(sub) < 2 or n_top not in sub:
                continue
            ns, ms, (text, *_) = quantity_rows(sub, fn, cr, slug=slug)
            if slug == "tau_t0_change":   # not a drift in N: whether the run at that N was steady
                m = ms[ns.index(n_top)]
                if steady_off(m, m[3] == len(sub[n_top].runs), change_dof(sub[n_top], cr)):
                    out.append(f"{name.split(':')[0]}{' — cage-relative' if cr else ''} not steady over the "
                               f"production at N = {n_top} ({fmt(m[0], measured_error(m))} %)")
                continue
            # a drift up to that N, not below it (the change between the two largest sizes ends the
            # verdict's first part; a note on a longer range's line may follow it)
            if text.startswith("drifting") and text.split("; over N = ")[0].endswith(f"to {n_top}"):
                out.append(f"{name}{' — cage-relative' if cr else ''}{text[len('drifting'):]}")
    return out


def cr_sizes_note(A):
    """With --largest-n: the N the cage-relative rows take. tau_alpha^CR and
    tau_B in the rows of relaxation times (and their fits against phi) take
    the largest N over the studies that measured them
    (local_measures.series_measuring), said wherever that is another
    study's point; the cage-relative view (its tau_alpha fits, chi4, S4,
    clusters) keeps the largest N of this study's points that has them,
    said where a promoted point has no cage-relative measures."""
    if not hasattr(A, "promoted"):
        return ""
    from .local_measures import TAU_B, TAU_CR, series_measuring
    cr_at = {p.phi: p for p in series_measuring(A, TAU_CR)}
    b_at = {p.phi: p for p in series_measuring(A, TAU_B)}

    def where(q):
        return f"N = {q.N}" + (f" ({q.study}, {len(q.runs)} seed{'s' * (len(q.runs) > 1)})"
                               if getattr(q, "study", None) else " (this study's)")
    times = []
    for phi in sorted(set(cr_at) | set(b_at)):
        c, b = cr_at.get(phi), b_at.get(phi)
        if not any(getattr(q, "study", None) for q in (c, b) if q is not None):
            continue
        if c is not None and (b is None or b is c):
            times.append(f"φ = {phi:g}: {where(c)}")
        else:
            times.append(f"φ = {phi:g}: " + "; ".join(f"{name} {where(q)}" for name, q in (("τ_α^CR", c), ("τ_B", b))
                                                      if q is not None))
    view = []
    for p in A.promoted:
        if any(A_MAIN in (r.get("cut_cr") or {}) for r in p.runs):
            continue
        own = [q for q in A.points.values() if (q.pairs, q.eps, q.phi) == (p.pairs, p.eps, p.phi)
               and any(A_MAIN in (r.get("cut_cr") or {}) for r in q.runs)]
        if own:
            view.append(f"φ = {p.phi:g}: N = {max(q.N for q in own)}")
    out = ""
    if times:
        out += (" τ_α^CR and τ_B in the rows of relaxation times, and their fits against φ, take the largest N over "
                "the studies read whose runs measured them, where that is another study's: " + "; ".join(times) + ".")
    if view:
        out += (" A study taken above measured no cage-relative quantity: the cage-relative view (the rows marked "
                "cage-relative: its fits of τ_α, χ4 and ξ, χ4, S4 and the clusters, which only this study's runs "
                "measured the cage-relative way) keeps this study's largest N that has them, " + "; ".join(view) + ".")
    return out


def largest_n_notes(A):
    """After the list of promoted points: whether each is a converged N for
    tau_alpha (size_verdict over the sizes of that density: "largest
    converged", else "largest available"), and the larger sizes held back
    because runs of them are unfinished."""
    from .finite_size import quantity_rows   # the finite-size table's own verdicts
    from .steady import unsteady
    from .size import points_by_phi_n
    from .size_rows import has_cr, tau_of
    multi = points_by_phi_n(A)   # the main series (neighbours, eps = 0.9): the others have no sizes of their own here
    multi_cr = points_by_phi_n(A, has_cr)   # (its points have the cage-relative measures: has_cr)
    out = []
    for p in A.promoted:
        main = p.pairs == "neighbours" and abs(p.eps - EPS_MAIN) < 1e-9
        d = multi.get(p.phi, {}) if main else {}
        ns = sorted(n for n in d if n <= p.N)
        if len(ns) < 2 or p.N not in d:
            continue
        _, _, (text, n0, _, _) = quantity_rows({n: d[n] for n in ns}, tau_of, False)
        drifting = still_drifting(multi, d, multi_cr.get(p.phi, {}), p.N)
        # a size that is not steady takes no part in the verdict: not "converged" itself
        converged = n0 is not None and not unsteady(d[p.N], False)
        out.append(f"φ = {p.phi:g}: N = {p.N} is the largest " + ("converged" if converged else "available")
                   + f" N for τ_α ({text})" + (f"; at that N still drifting, or not steady (finite_size.md): {'; '.join(drifting)}"
                                              if drifting else ""))
    if out:
        out = [" Whether that N is converged: " + "; ".join(out) + "."]
    if getattr(A, "held_back", None):
        out.append(" Held back, runs of them unfinished (no conclusion from a size whose runs did not finish): "
                   + "; ".join(f"φ = {p.phi:g}: N = {p.N} of study {p.study} ({n} run{'s' if n > 1 else ''} not "
                               f"complete)" for p, n in A.held_back) + ".")
    return "".join(out)
