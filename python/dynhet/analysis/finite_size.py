"""The finite-size report: every quantity against N at each
density run at several N, standard and cage-relative side by side, with a
verdict computed from the numbers: converged within errors from which N on,
or still drifting (and by how much per doubling of N). Written by
analyse_study.sh --finite-size PATH from the study and its --also studies."""
import math
import os
import shutil

import matplotlib.pyplot as plt
import numpy as np

from .config import A_MAIN, shown_path
from .plotting import colours, errorbar
from .quantities import s4_at_tau
from .points import MIN_CAL_DOF, ensure_calibrated, measured_error, spread_ratio as pooled_spread
from .size import Z_CONVERGED, held_back, others_note, points_by_phi_n, size_verdict, study_of
from .size_rows import (CHI4P_ROWS, MIN_SHELLS, TAU_ROWS, c_b_times, chi4p_grid, has_cr, kappa_windows, lags_in_tau_cr,
                        missing_cell, quantities, shells_note, tau_b_bound, tau_b_points)
from .steady import change_dof, steady_verdict, unsteady
from .steady_runs import steady_section
from .verdicts import fmt


def spread_ratio(points, fn, cr=False):
    """points.spread_ratio of fn(run, cr): the seeds' spread against the quoted
    errors, pooled over points. Returns (ratio, uncertainty, dof, runs without a
    quoted error)."""
    return pooled_spread(points, lambda r: fn(r, cr))


def spread_section(multi, multi_cr, multi_tb=None):
    """Per N, the pooled seed-spread ratio of tau_alpha,
    tau_alpha^CR, tau_B and chi4^P over the densities run there (tau_B over
    the points its cells take: multi_tb)."""
    ns = sorted({n for d in multi.values() for n in d})
    rows = []
    for name, slug, fn, has_cr_version, _ in TAU_ROWS + CHI4P_ROWS:
        for cr in ((False, True) if has_cr_version else (False,)):
            src = multi_cr if cr else (multi_tb if slug == "tau_b" and multi_tb is not None else multi)
            cells, any_data = [], False
            for n in ns:
                pts = [d[n] for d in src.values() if n in d]
                r, u, dof, unq = spread_ratio(pts, fn, cr)
                if dof:
                    any_data = True
                    cells.append(f"{r:.2f} ± {u:.2f} ({dof})")
                elif any(np.isfinite(v) for p in pts for _, v, _ in p.values(lambda r: fn(r, cr))) \
                        and all(len(p.runs) == 1 for p in pts):
                    cells.append("one seed: not checkable")
                else:
                    cells.append("no error quoted" if unq else "—")
                    any_data = any_data or unq > 0
            if any_data:
                rows.append(f"| {name}{' — cage-relative' if cr else ''} | " + " | ".join(cells) + " |")
    if not rows:
        return []
    return ["## Error bars against the spread of seeds", "",
            "Per N, pooled over the densities run at several N: the standard deviation of the seeds of a point over "
            "the mean error its runs quote (`spread_ratio`, bench/seed_spread.py's ratio), ± its own uncertainty "
            "(ratio / sqrt(2 dof)), degrees of freedom in brackets. About 1 where the quoted errors are honest; "
            "above 1 they are too small. \"No error quoted\": the runs give none (tau_B where its jackknife "
            "blocks cannot span it: docs/analysis.md), and the cells above use the seeds' spread.", "",
            "| quantity | " + " | ".join(f"N = {n}" for n in ns) + " |",
            "|---|" + "---|" * len(ns)] + rows + [""]


def cell(m, seeds=0):
    """A size's cell: mean ± error, ¹ for one seed; where only n of its
    `seeds` runs have a value (the others not resolved or not reached), the
    mean of those, marked "(n of seeds seeds)": it takes no part in the
    verdict (the seeds that lack it are not a random subset: a xi resolved
    only by the seeds where it came out smaller)."""
    v, quoted, sem, n = m
    if not np.isfinite(v):
        return "—"
    e = measured_error(m)
    part = f" ({n} of {seeds} seeds)" if n < seeds else ""
    # not every run quotes an error and two seeds give one from their spread: one dof, itself uncertain by 70 %
    two = " ²" if n == 2 and np.isfinite(e) and np.isfinite(sem) and e == sem else ""
    return (fmt(v, e) if np.isfinite(e) else f"{v:.4g} (no error)") + ("" if n > 1 else " ¹") + two + part


def quantity_rows(d, fn, cr, ns=None, slug=None):
    """Per-N means (at the sizes ns, default d's; NaN where d has none; their
    errors scaled by their study's calibration, Point.mean) and the verdict
    (sizes without a measured error take no part in it). A tau_B of which
    some seed was not reached is no mean (the rest would bias it low): NaN,
    and its cell gives the bound (missing_cell)."""
    ns = sorted(d) if ns is None else ns
    nan = (math.nan, math.nan, math.nan, 0)
    ms = [d[n].mean(lambda r: fn(r, cr)) if n in d and not (slug == "tau_b" and tau_b_bound(d[n]) is not None)
          else nan for n in ns]
    whole = [n in d and m[3] == len(d[n].runs) for n, m in zip(ns, ms)]   # every seed has it (cell)
    if slug == "tau_t0_change":   # a steady state is 0 at each N, not an N-independent value
        dofs = [change_dof(d[n], cr) if n in d else None for n in ns]
        return ns, ms, (steady_verdict(ns, ms, whole, dofs), None, math.nan, math.nan)
    # a size whose tau_alpha(t0) still moves over its production (of the same measure, standard or
    # cage-relative) is no steady state: shown, marked, and out of the verdict
    off = [n in d and bool(unsteady(d[n], cr)) for n in ns]
    verdict = size_verdict(ns, [m[0] for m in ms], [measured_error(m) if w and not o else math.nan
                                                    for m, w, o in zip(ms, whole, off)])
    shown = sum(np.isfinite(m[0]) for m in ms)
    judged = sum(np.isfinite(m[0]) and w and not o and np.isfinite(measured_error(m)) for m, w, o in zip(ms, whole, off))
    if verdict[1] is None and judged < 2 and shown > judged:   # the cells show sizes the verdict cannot take
        verdict = (f"no verdict: {judged} of the {shown} size{'s' if shown > 1 else ''} shown "
                   f"{'has' if judged == 1 else 'have'} every seed's value with an error and a steady state",
                   None, math.nan, math.nan)
    return ns, ms, verdict


def bound_conflict(ns, ms, bounds):
    """Where a size's tau_B is only a bound and the bound lies above the
    largest measured N's value by more than Z_CONVERGED of its errors, the
    sizes do not agree whatever the verdict over the measured ones says:
    the text saying so, else ""."""
    d = [(n, m[0], measured_error(m)) for n, m in zip(ns, ms) if np.isfinite(m[0]) and np.isfinite(measured_error(m))]
    if not d:
        return ""
    nmax, vmax, emax = max(d)
    over = [(n, b) for n, b in zip(ns, bounds) if b is not None and b > vmax + Z_CONVERGED * emax]
    if not over:
        return ""
    return ("not converged: " + ", ".join(f"N = {n}'s bound > {b:.3g}" for n, b in over)
            + f" lies above N = {nmax}'s {fmt(vmax, emax)}")


def plot_quantity(A, name, slug, fn, has_cr_version, log_y, multi, multi_cr):
    fig, ax = plt.subplots(figsize=(7.6, 4.3))
    drawn = False
    for (phi, d), col in zip(multi.items(), colours(len(multi))):
        for cr in ((False, True) if has_cr_version else (False,)):
            dd = multi_cr.get(phi, {}) if cr else d
            if not dd:
                continue
            ns, ms, _ = quantity_rows(dd, fn, cr, slug=slug)
            x = [n for n, m in zip(ns, ms) if np.isfinite(m[0])]
            if not x:
                continue
            y = [m[0] for m in ms if np.isfinite(m[0])]
            e = [np.nan_to_num(measured_error(m)) for m in ms if np.isfinite(m[0])]
            errorbar(ax, x, y, e, fmt="s--" if cr else "o-", ms=4, color=col, mfc="none" if cr else col,
                        label=f"φ = {phi:g}" + (" (cage-relative)" if cr else ""))
            drawn = True
    if not drawn:
        plt.close(fig)
        return ""
    ax.set_xscale("log")
    if log_y:
        ax.set_yscale("log")
    ax.set_xlabel("N")
    ax.set_ylabel(name)
    ax.set_title(f"{name} against N")
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))  # beside the data, never on it
    return A.save(fig, f"fs_{slug}.png")


def panels_per_phi(A, multi, multi_cr, curve, title, xlabel, ylabel, name, ms):
    """One log-log panel per density, a curve per N, standard (filled, solid)
    and cage-relative (open, dashed): curve(point, cr) -> (x, y), (x, y,
    errors of y) or None.
    The saved figure's path, "" where no curve has data."""
    phis = list(multi)
    cols = min(3, len(phis))                      # three panels a row: readable at six densities
    rows = -(-len(phis) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(5.0 * cols, 4.2 * rows), squeeze=False)
    for ax in axes.flat[len(phis):]:
        ax.set_visible(False)
    drawn = False
    for ax, phi in zip(axes.flat, phis):
        ns = sorted(multi[phi])
        for n, col in zip(ns, colours(len(ns))):
            for cr, ls in ((False, "o-"), (True, "s--")):
                p = (multi_cr.get(phi, {}) if cr else multi[phi]).get(n)
                xy = curve(p, cr) if p is not None else None
                if xy is None:
                    continue
                yerr = xy[2] if len(xy) > 2 else None   # a curve may carry its errors
                errorbar(ax, xy[0], xy[1], yerr, fmt=ls, ms=ms, lw=1, capsize=2, color=col,
                         mfc="none" if cr else col, label=f"N = {n}" + (" (cage-relative)" if cr else ""))
                drawn = True
        ax.set_title(f"φ = {phi:g}: {title}")
        ax.set_xlabel(xlabel)
        if ax.has_data():
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.legend(fontsize=6)
    if not drawn:
        plt.close(fig)
        return ""
    for row in axes:
        row[0].set_ylabel(ylabel)
    fig.tight_layout()
    return A.save(fig, name)


def plot_s4_q(A, multi, multi_cr):
    """S4(q, tau_alpha) of the whole box at every N, one panel per density,
    standard (solid) and cage-relative (dashed), the mean over seeds: where
    the curve has an Ornstein-Zernike plateau below q = 1/xi, and where it
    still rises at the box's smallest q (xi beyond the box: "no OZ fit")."""
    def curve(p, cr):
        curves = []
        for r in p.runs:
            try:
                curves.append(s4_at_tau(dict(r, cut=r["cut_cr"]) if cr else r))
            except (KeyError, TypeError, IndexError, ValueError):
                continue
        if not curves:
            return None
        q0 = np.asarray(curves[0][0], float)
        same = [np.asarray(s_, float) for q_, s_ in curves if len(q_) == len(q0) and np.allclose(q_, q0)]
        y = np.nanmean(same, axis=0)
        ok = np.isfinite(y) & (y > 0) & (q0 > 0)
        return (q0[ok], y[ok]) if ok.any() else None
    return panels_per_phi(A, multi, multi_cr, curve, "S4(q, τ_α), whole box", "q", "S4(q, τ_α) (mean over seeds)",
                          "fs_s4_q.png", 2.5)


def plot_chi4p_subbox(A, multi, multi_cr):
    """The paper's fig. chi4P(a) at every box size: chi4^P against the
    sub-box's particles, one panel per density, a curve per N (the mean over
    seeds with the table's error: size_rows.chi4p_grid; interior peaks
    only; the last point of a curve is the whole box,
    where the study's sub-box sizes reach it: short_of_box),
    standard (filled) and cage-relative (open): where a sub-box's chi4^P
    does not depend on the box around it, and how far the larger boxes
    extend the curve."""
    def curve(p, cr):
        sizes = sorted({round(float(n)) for r in p.runs
                        for n in r.get("cut_cr" if cr else "cut", {}).get(A_MAIN, {}).get("chi4_N", ())})
        pts = [(s, p.mean(chi4p_grid(s, cr))) for s in sizes]
        pts = [(s, m) for s, m in pts if m[3] and np.isfinite(m[0])]
        if not pts:
            return None
        return ([s for s, _ in pts], [m[0] for _, m in pts],
                [measured_error(m) for _, m in pts])
    return panels_per_phi(A, multi, multi_cr, curve, "χ4^P against the sub-box", "particles in the sub-box",
                          "χ4^P (mean over seeds)", "fs_chi4p_subbox.png", 3)


def short_of_box(multi):
    """The caption's exception: the sizes whose sub-boxes stop short of the
    whole box (the study's list of sub-box sizes ends below N), each with its
    largest sub-box; "" where every curve reaches its box."""
    short = {}
    for d in multi.values():
        for n, p in d.items():
            for r in p.runs:
                sizes = r.get("cut", {}).get(A_MAIN, {}).get("chi4_N")
                if sizes is not None and len(sizes) and max(sizes) < 0.99 * n:
                    short[n] = max(short.get(n, 0), round(float(max(sizes))))
    return "".join(f"; at N = {n} it is the largest sub-box its study asks for, {m} particles, short of the box"
                   for n, m in sorted(short.items()))


def calibration_note(A, multi, multi_cr, multi_tb=None):
    """The factors by which each quantity's quoted errors are scaled
    (points.calibration, pooled over each study's points)."""
    ensure_calibrated(list(A.points.values()) + list(A.extra.values()))
    def populations(*sources):
        return {id(p.population): p.population for src in sources for d in src.values() for p in d.values()}
    main_pops, tb_pops = populations(multi, multi_cr), populations(multi, multi_tb or {})
    applied = []
    for name, slug, fn, has_cr_version, _ in quantities(multi, multi_cr):
        pops = tb_pops if slug == "tau_b" else main_pops   # the tau_B rows may take another study's points
        for cr in ((False, True) if has_cr_version else (False,)):
            f = lambda run: fn(run, cr)  # noqa: E731
            groups = {}   # (factor, ratio, uncertainty, dof, borrowed) -> the studies
            for pop in pops.values():
                k, r, u, dof = pop.calibration(f)
                borrowed = pop.borrows(f)
                if k != 1.0:
                    groups.setdefault((k, r, u, dof, borrowed), []).append(pop.name or os.path.basename(A.dir))
            for (k, r, u, dof, borrowed), names in groups.items():
                where = ""
                if len(main_pops) > 1 or len(tb_pops) > 1:
                    where = f", {'studies' if len(names) > 1 else 'study'} {', '.join(sorted(names))}"
                    where += " (too few seeds of their own: pooled over all studies)" if borrowed else ""
                applied.append(f"{name}{' — cage-relative' if cr else ''} × {k:.2f} (ratio {r:.2f} ± {u:.2f}, "
                               f"{dof} dof{where})")
    return ["**Errors scaled to the seeds' spread.** Where the seeds of a study scatter more than their runs' "
            "quoted errors say, pooled over every point of that study (`points.calibration`: at least "
            f"{MIN_CAL_DOF} dof, more than 2 of its uncertainties above 1), the quoted errors of that quantity "
            "are multiplied by that ratio in the tables, plots and verdicts (and in every other report of the "
            "study analysis): " + ("; ".join(applied) if applied else "none needed") +
            ". Quoted errors are never made smaller.", ""]


def drop_stale_figures(fig_dir, figures):
    """Removes the report's figures (fs_*.png) in fig_dir that this report no
    longer names: a figure of a size or measure the data no longer has must
    not stay beside the text as if it were current."""
    keep = {os.path.basename(f) for f in figures}
    if os.path.isdir(fig_dir):
        for name in os.listdir(fig_dir):
            if name.startswith("fs_") and name.endswith(".png") and name not in keep:
                os.remove(os.path.join(fig_dir, name))


def write_finite_size(A, path, command):
    """The report at `path`; its figures next to it in finite_size/ (copied
    from the study's figures/)."""
    multi = points_by_phi_n(A)
    # the cage-relative rows from the points that have them (another study's,
    # where the point with most runs at that phi and N has none)
    multi_cr = points_by_phi_n(A, has_cr)   # (its points have the cage-relative measures: has_cr)
    L = ["# Finite size: every measure against N", "",
         "Generated by `launch_scripts/analyse_study.sh` (do not edit by hand) from the studies in "
         + ", ".join(f"`{shown_path(s)}`" for s in [A.dir] + A.also)
         + f". Command: `{command}`", "",
         f"Each cell: the mean over seeds with its error (the runs' own errors, jackknife over origin blocks, "
         f"combined, times the study's factor below where its seeds scatter more; the seeds' spread where no run "
         f"quotes one; \"no error\" where one seed quotes none, and such a "
         f"size takes no part in the verdict); ¹ one seed: its error is the run's own (jackknife over origin blocks, times the study's factor below where it has one for that quantity), which no spread of seeds checks at that N; \"(k of m seeds)\": only k of the size's m runs have a "
         f"value (the others not resolved or not reached), and it takes no part in the verdict either; ² not every run "
         f"quotes an error, and it is the spread of two seeds (one degree of freedom: itself uncertain by some 70 %); "
         f"‡ not steady: "
         f"the size's τ_α(t0) (of the same measure, standard or cage-relative) moves over its production beyond "
         f"3σ's probability (Student t with the dof of its origins' scatter about the line: 4.9 errors for one run "
         f"of 8 origins, 3.5 for three; the row \"τ_α(t0): change over the production\"), so its values are no "
         f"steady state's: shown, and out of the verdict; where that error has a single dof (²) the limit would be "
         f"236 errors, no check, and the size's steadiness is not judged. Each density's "
         f"table is one protocol's (the same unit of the run lengths, equilibration, origins and their spacing at "
         f"every N: the studies' run_length): the protocol whose studies run that φ at the most N, and among as many "
         f"the one with the cage-relative measures (run lengths in units of τ_α^CR); sizes only another protocol ran "
         f"are named under the table, not used (one exception, said under the table: the τ_B row takes, at each N, "
         f"the study that followed C_B furthest, studies/cage_bonds.toml's lags of 18 τ_α^CR where the table's "
         f"protocol stops at 4). Where several studies of it ran the same φ and N, the one with the "
         f"most seeds; the line under each table names each N's study. A verdict is computed from the "
         f"numbers: **converged** from the smallest N whose value and every larger N's agree with the largest "
         f"N's within {Z_CONVERGED:g} combined errors, and whose weighted line against log2 N (through at least the "
         f"three largest sizes) is flat within {Z_CONVERGED:g} of its error, or, from the second largest N, whose last "
         f"step levels off from the one before beyond the errors (a steady drift in steps each within the errors "
         f"is a drift); otherwise **drifting**; either way with the change per doubling "
         f"of N between the two largest sizes and its error, which says how tightly \"converged\" holds. χ4^P is the peak of χ4(t) of sub-boxes of about that many particles "
         f"(interior peaks only); ξ is the whole box's Ornstein-Zernike ξ at τ_α, taken only where at least "
         f"{MIN_SHELLS} q shells lie below q ξ = 1 (else \"not resolved\" at this N; \"no OZ fit\": the S4 node refused the fit at τ_α, for ξ beyond the "
         f"box, below the q range, or with a jackknife error not below ξ; \"ξ beyond the box\", \"ξ < 0.3\", \"τ_α beyond the S4 "
         f"lags\" say so); [k q]: the shells below "
         f"q ξ = 1 of its runs (the range over seeds), which are the q points its OZ fit ran over (the S4 node "
         f"fits over q ξ ≤ 1, and over the 3 smallest q where fewer lie there). a = {A_MAIN}, ε = 0.9, "
         f"neighbour kick pairs. Nothing here is tuned toward the paper's numbers.", ""]
    if not multi:
        L += ["No density was run at more than one N.", ""]
    multi_tb = tau_b_points(A, multi)
    L += calibration_note(A, multi, multi_cr, multi_tb)
    rows, cb_at, kw = quantities(multi, multi_cr), c_b_times(multi), kappa_windows(multi, multi_cr)
    figures = []
    for phi, d in multi.items():
        ns = sorted(d)
        L += [f"## φ = {phi:g}", "",
              "| quantity | " + " | ".join(f"N = {n}" for n in ns) + " | verdict |",
              "|---|" + "---|" * len(ns) + "---|"]
        for name, slug, fn, has_cr_version, _ in rows:
            for cr in ((False, True) if has_cr_version else (False,)):
                dd = multi_cr.get(phi, {}) if cr else (multi_tb[phi] if slug == "tau_b" else d)
                if not dd:
                    continue
                qn, ms, (text, _, _, _) = quantity_rows(dd, fn, cr, ns, slug)
                why = [missing_cell(slug, dd.get(n), cr) if not np.isfinite(m[0]) else None for n, m in zip(qn, ms)]
                if not any(np.isfinite(m[0]) for m in ms) and not any(why):
                    continue
                if not any(np.isfinite(m[0]) for m in ms):
                    text = ("not reached at any N: C_B stays above 1/e over the runs' lags" if slug == "tau_b"
                            else "no value at any N")
                elif slug == "tau_b":
                    text = bound_conflict(qn, ms, [tau_b_bound(dd[n]) if n in dd else None for n in qn]) or text
                label = name + (" — cage-relative" if cr else "")
                if slug == "c_b":
                    label = f"C_B at t = {dict(cb_at).get(round(float(phi), 6), math.nan):.4g} (bond breaking)"
                if slug == "kappa":   # the window every N of this density fits (size_rows.kappa_windows)
                    hi = kw.get((round(float(phi), 6), cr))
                    label += f", 3 ≤ N_c ≤ {hi:.3g}" if hi is not None else ""
                cells = [w or cell(m, len(dd[n].runs) if n in dd else 0)
                         + (" ‡" if slug != "tau_t0_change" and n in dd and unsteady(dd[n], cr) else "")
                         for m, w, n in zip(ms, why, qn)]
                if slug == "xi":  # how many q shells its fits had below q xi = 1 (MIN_SHELLS)
                    cells = [c + shells_note(dd.get(n), cr) for c, n in zip(cells, qn)]
                L.append(f"| {label} | " + " | ".join(cells) + f" | {text} |")
        seeds = ", ".join(f"N {n}: {len(d[n].runs)} ({study_of(d[n])})" for n in ns) + others_note(d)
        held = [f"N {n} of {st} ({k} run{'s' if k > 1 else ''} not complete)" for n, st, k in held_back(A, phi)]
        if held:
            seeds += "; held back, no conclusion from a size whose runs did not all finish: " + ", ".join(held)
        spans = lags_in_tau_cr(d, ns)
        crs = multi_cr.get(phi, {})
        if crs and any(crs.get(n) is not d.get(n) for n in crs):
            seeds += "; cage-relative rows: " + ", ".join(f"N {n}: {len(p.runs)} ({study_of(p)})"
                                                          for n, p in sorted(crs.items()))
        seeds += others_note(crs, "; cage-relative rows: not in them")
        tbs = [(n, p) for n, p in sorted(multi_tb.get(phi, {}).items()) if p is not d.get(n)]
        if tbs:
            seeds += "; τ_B row: " + ", ".join(f"N {n}: {len(p.runs)} of study {study_of(p)}"
                                               for n, p in tbs)
        L += ["", f"Runs (seeds) per N: {seeds}." + (f" Longest lag in units of each run's own measured "
                                                      f"τ_α^CR (a study in units of τ_α^CR sets every N's lags from its pilot's; a run's own τ_α^CR scatters about that, and so does this ratio): {spans}."
                                                      if spans else ""), ""]
    L += steady_section(A)
    if multi:
        L += spread_section(multi, multi_cr, multi_tb)
        L += ["## Plots", ""]
        for name, slug, fn, has_cr_version, log_y in rows:
            f = plot_quantity(A, name, slug, fn, has_cr_version, log_y, multi_tb if slug == "tau_b" else multi,
                              multi_cr)
            if f:
                figures.append(f)
                L.append(f"- {name}: ![{name}](finite_size/{os.path.basename(f)})")
        for plot, caption, alt in (
                (plot_chi4p_subbox, "χ4^P against the sub-box's particles at every N (the paper's fig. chi4P(a), with "
                 "the sub-box sizes the larger boxes allow; a curve's last point is its whole box"
                 + short_of_box(multi) + "), standard (filled) "
                 "and cage-relative (open)", "χ4^P against the sub-box"),
                (plot_s4_q, "S4(q, τ_α) of the whole box at every N, standard (filled, solid) and cage-relative (open, "
                 "dashed): where it levels off below q = 1/ξ (an Ornstein-Zernike ξ the box resolves) and where it "
                 "still rises at the box's smallest q", "S4(q)")):
            f = plot(A, multi, multi_cr)
            if f:
                figures.append(f)
                L.append(f"- {caption}: ![{alt}](finite_size/{os.path.basename(f)})")
        L.append("")
    out_dir = os.path.dirname(os.path.abspath(path))
    os.makedirs(out_dir, exist_ok=True)
    fig_dir = os.path.join(out_dir, "finite_size")
    if figures and A.figures:
        os.makedirs(fig_dir, exist_ok=True)
        for f in figures:
            shutil.copy(os.path.join(A.out, f), os.path.join(fig_dir, os.path.basename(f)))
    drop_stale_figures(fig_dir, figures)
    with open(path, "w") as fh:
        fh.write("\n".join(L))
    return len(multi)
