"""The finite-size report (issue 27): every quantity against N at each
density run at several N, standard and cage-relative side by side, with a
verdict computed from the numbers: converged within errors from which N on,
or still drifting (and by how much per doubling of N). Written by
analyse_study.sh --finite-size PATH from the study and its --also studies."""
import math
import os
import shutil

import matplotlib.pyplot as plt
import numpy as np

from .config import A_MAIN, EPS_MAIN
from .plotting import colours, errorbar
from .quantities import PER_RUN, XI_MIN, chi0_at_tau, kappa_of, s4_at_tau, whole_box_s4
from .runs import blocks_span
from .points import MIN_CAL_DOF, ensure_calibrated, spread_ratio as pooled_spread
from .size import points_by_phi_n
from .verdicts import fmt
from ..fits import interp_ln_t

# chi4^P (the peak of chi4(t)) per sub-box size: a run's grid counts for a
# size when its <N_r> is within a factor 1.6 of it and is not the whole box.
SUBBOX_SIZES = (32, 128, 512, 2048, 8192, 32768)
MIN_SHELLS = 5      # xi needs at least this many q shells below q xi = 1 (issue 27, item 4)
Z_CONVERGED = 2.0   # values within 2 combined standard errors agree


def cutx(r, cr):
    return r["cut_cr" if cr else "cut"][A_MAIN]


def chi4p_of(size):
    """chi4^P of the grid with sub-boxes of about `size` particles; NaN where the
    run has no such grid or its peak is not interior (a bound, not a peak)."""
    def fn(r, cr=False):
        c = cutx(r, cr)
        ns = np.asarray(c["chi4_N"], float)
        for g in np.argsort(np.abs(np.log(ns / size))):
            if ns[g] >= 0.999 * r["N"] or not (size / 1.6 <= ns[g] <= size * 1.6):
                continue
            if not c["tau4_interior"][g]:
                return math.nan, math.nan
            return c["chi4_peak"][g], c["chi4_peak_err"][g]
        return math.nan, math.nan
    return fn


def xi_shells(r, cr=False):
    """(xi, error, shells): the whole box's OZ xi at tau_alpha and how many q
    shells lie below q xi = 1; xi is NaN with fewer than MIN_SHELLS shells
    (not resolved at this N) or below XI_MIN."""
    c = cutx(r, cr)
    t = c["tau_alpha"]
    g = whole_box_s4(c)
    off = int(np.sum(c["s4_nshells"][:g]))
    q = np.asarray(c["s4_q"][off:off + int(c["s4_nshells"][g])])
    xi = np.interp(math.log(t), np.log(c["s4_lag"]), c["xi_t"][:, g]) if np.isfinite(t) else math.nan
    if not np.isfinite(xi):
        return math.nan, math.nan, 0
    shells = int(np.sum((q > 0) & (q * xi <= 1.0)))
    rel = c["s4_oz_xi_err"][g] / c["s4_oz_xi"][g] if c["s4_oz_xi"][g] > 0 else math.nan
    if shells < MIN_SHELLS or xi < XI_MIN:
        return math.nan, math.nan, shells
    return xi, abs(xi) * rel, shells


def shells_note(p, cr):
    """The q shells below q xi = 1 of a point's runs, as a cell's suffix:
    " [7 q]" (the fewest over its seeds, " [5-7 q]" where they differ); ""
    without runs or where no run has xi."""
    if p is None:
        return ""
    ks = []
    for r in p.runs:
        try:
            _, _, k = xi_shells(r, cr)
        except (KeyError, TypeError, IndexError, ValueError):
            continue
        if k:
            ks.append(k)
    if not ks:
        return ""
    return f" [{min(ks)} q]" if min(ks) == max(ks) else f" [{min(ks)}-{max(ks)} q]"


def with_cr(fn):
    """A per-run function of the standard results made to take cr=True."""
    def f(r, cr=False):
        if not cr:
            return fn(r)
        view = dict(r, cut=r["cut_cr"])
        return fn(view)
    return f


def tau_of(r, cr=False):
    c = cutx(r, cr)
    return c["tau_alpha"], c["tau_alpha_err"]


def tau_b_of(r, cr=False):
    return PER_RUN["tau_b"](r)


def c_b_at(times):
    """C_B(t), the fraction of bonds intact (bond breaking), at a fixed time
    per density, interpolated in ln t. Its error: the run's quoted one (the
    standard error over origins, taken as independent) and the
    interpolation's in quadrature, but only where jackknife blocks of origins
    spanning t fit four times into the run's origins (runs.blocks_span, the
    nodes' rule); else none, and the point takes its seeds' spread. `times`
    is ((phi, t), ...); NaN beyond a run's lags."""
    at = dict(times)

    def fn(r, cr=False):
        t = at.get(round(float(r["packing_fraction"]), 6), math.nan)
        v, ie = interp_ln_t(r["c_b_lag"], r["c_b"], t)
        if not blocks_span(t, r.get("schedule")):
            return v, math.nan
        e, _ = interp_ln_t(r["c_b_lag"], r["c_b_err"], t)
        return v, math.hypot(e, ie if np.isfinite(ie) else 0.0)
    return fn


def c_b_times(multi):
    """Per density, the longest lag that every run of it (at every N) reached:
    where C_B is compared across N."""
    out = []
    for phi, d in multi.items():
        last = [float(r["c_b_lag"][-1]) for p in d.values() for r in p.runs if len(r.get("c_b_lag", ()))]
        if last:
            out.append((round(float(phi), 6), min(last)))
    return tuple(out)


# (name, file name, per-run function (r, cr) -> (value, error), has a
# cage-relative version, log axis). C_B's time depends on the runs: quantities().
TAU_ROWS = [("τ_α", "tau_alpha", tau_of, True, True),
            ("τ_B (bond breaking)", "tau_b", tau_b_of, False, True)]
CHI4P_ROWS = [(f"χ4^P, sub-boxes of {n}", f"chi4p_{n}", chi4p_of(n), True, True) for n in SUBBOX_SIZES]
REST_ROWS = [("χ0 of S4 (whole box, at τ_α)", "chi0", with_cr(chi0_at_tau), True, True),
             ("ξ of S4 (whole box, at τ_α)", "xi", lambda r, cr=False: xi_shells(r, cr)[:2], True, True),
             ("κ (slow clusters)", "kappa", with_cr(kappa_of), True, False),
             ("d_f (slow clusters)", "d_f", lambda r, cr=False: (cutx(r, cr)["cl_slow_d_f"], cutx(r, cr)["cl_slow_d_f_err"]),
              True, False)]
QUANTITIES = TAU_ROWS + CHI4P_ROWS + REST_ROWS


def quantities(multi):
    """Every row of the report: QUANTITIES and C_B at each density's common
    last lag (bond breaking measured where tau_B lies beyond the lags)."""
    cb = [("C_B at the longest common lag (bond breaking)", "c_b", c_b_at(c_b_times(multi)), False, False)]
    return TAU_ROWS + cb + CHI4P_ROWS + REST_ROWS


def tau_b_bound(p):
    """Where some run of the point never saw C_B fall to 1/e: the mean over
    its seeds of tau_B or, where not reached, the last lag, a lower bound on
    the point's tau_B; None where every run reached it (or none measured
    C_B)."""
    vals, short = [], False
    for r in p.runs:
        lag = r.get("c_b_lag")
        if lag is None or not len(lag):
            continue
        tb = r.get("tau_b", math.nan)
        if np.isfinite(tb):
            vals.append(tb)
        elif beyond_lags(r):
            vals.append(float(lag[-1]))
            short = True
        else:  # no tau_B for another reason (C_B below 1/e at the first lag): no bound either
            return None
    return float(np.mean(vals)) if short else None


def beyond_lags(r):
    """Whether a run's C_B stayed above 1/e to its last lag (tau_B beyond it)."""
    cb = r.get("c_b")
    return cb is not None and len(cb) > 0 and np.isfinite(cb[-1]) and cb[-1] > math.exp(-1)


def missing_cell(slug, p, cr):
    """The text of a cell with no value that says why: tau_B beyond the lags
    (with a lower bound), xi not resolved; None for a plain "—"."""
    if p is None:
        return None
    if slug == "tau_b":
        b = tau_b_bound(p)
        if b is not None:
            measured = [r for r in p.runs if len(r.get("c_b_lag", ()))]
            n = sum(1 for r in measured if not np.isfinite(r.get("tau_b", math.nan)))
            return f"> {b:.3g} ({n} of {len(measured)} seeds: C_B > 1/e at the last lag)"
    if slug in ("xi", "chi0"):
        why = sorted({s4_reason(r, cr, slug) for r in p.runs} - {None})
        return " / ".join(why) if why else None
    return None


def s4_reason(r, cr, slug):
    """Why a run has no whole-box xi (or chi0) at tau_alpha: "τ_α not
    reached", "no OZ fit" (the S4 node refused its fit at that lag: xi beyond
    the box, below the q range, or its jackknife error not below xi), "ξ <
    0.3" (not determined), "not resolved" (fewer than MIN_SHELLS q shells
    below q xi = 1); None where it has one, or no S4."""
    try:
        c = cutx(r, cr)
        if not len(c.get("xi_t", ())):
            return None
        t = c["tau_alpha"]
        if not np.isfinite(t):
            return "τ_α not reached"
        g = whole_box_s4(c)
        xi = np.interp(math.log(t), np.log(c["s4_lag"]), c["xi_t"][:, g])
        if not np.isfinite(xi):
            return "no OZ fit"
        if slug == "chi0":
            return None
        if xi < XI_MIN:
            return f"ξ < {XI_MIN:g}"
        return "not resolved" if xi_shells(r, cr)[2] < MIN_SHELLS else None
    except (KeyError, TypeError, IndexError, ValueError):
        return None


def size_verdict(ns, vals, errs):
    """Converged or drifting, from the numbers: the smallest N0 such that the
    value at every N >= N0 agrees with the largest N's within Z_CONVERGED
    combined errors (at least two sizes); otherwise the drift per doubling of N
    between the two largest sizes. Returns (text, N0 or None, drift, error)."""
    d = [(n, v, e) for n, v, e in zip(ns, vals, errs) if np.isfinite(v) and np.isfinite(e)]
    if len(d) < 2:
        return ("one N only" if d else "no data"), None, math.nan, math.nan
    d.sort()
    nmax, vmax, emax = d[-1]
    n0 = None
    for k in range(len(d) - 2, -1, -1):
        n, v, e = d[k]
        if abs(v - vmax) <= Z_CONVERGED * math.hypot(e, emax):
            n0 = n
        else:
            break
    if n0 is not None:
        return f"converged from N = {n0} on (within {Z_CONVERGED:g}σ of N = {nmax})", n0, math.nan, math.nan
    n1, v1, e1 = d[-2]
    per = math.log2(nmax / n1)
    drift, derr = (vmax - v1) / per, math.hypot(emax, e1) / per
    rel = drift / abs(v1) if v1 else math.nan
    return (f"drifting: {fmt(drift, derr)} per doubling of N ({100 * rel:+.0f}%) from N = {n1} to {nmax}",
            None, drift, derr)


def spread_ratio(points, fn, cr=False):
    """points.spread_ratio of fn(run, cr): the seeds' spread against the quoted
    errors, pooled over points. Returns (ratio, uncertainty, dof, runs without a
    quoted error)."""
    return pooled_spread(points, lambda r: fn(r, cr))


def spread_section(multi, multi_cr):
    """Issue 27, item 5: per N, the pooled seed-spread ratio of tau_alpha,
    tau_alpha^CR, tau_B and chi4^P over the densities run there."""
    ns = sorted({n for d in multi.values() for n in d})
    rows = []
    for name, _, fn, has_cr_version, _ in TAU_ROWS + CHI4P_ROWS:
        for cr in ((False, True) if has_cr_version else (False,)):
            src = multi_cr if cr else multi
            cells, any_data = [], False
            for n in ns:
                r, u, dof, unq = spread_ratio([d[n] for d in src.values() if n in d], fn, cr)
                if dof:
                    any_data = True
                    cells.append(f"{r:.2f} ± {u:.2f} ({dof})")
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


def measured_error(m):
    """The error of a per-point mean that was measured: the runs' quoted
    error, else the seeds' standard error; NaN where there is neither (one
    seed quoting none: tau_B where its blocks cannot span it). Not
    point_error's 10% stand-in, which the fits use as a weight."""
    _, e, sem, _ = m
    return e if np.isfinite(e) and e > 0 else (sem if np.isfinite(sem) and sem > 0 else math.nan)


def cell(m):
    v, _, _, n = m
    if not np.isfinite(v):
        return "—"
    e = measured_error(m)
    return (fmt(v, e) if np.isfinite(e) else f"{v:.4g} (no error)") + ("" if n > 1 else " ¹")


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
    verdict = size_verdict(ns, [m[0] for m in ms], [measured_error(m) for m in ms])
    return ns, ms, verdict


def c_b_reach(p):
    """The longest lag every run of a point followed C_B to (0 without bond breaking)."""
    lags = [float(r["c_b_lag"][-1]) for r in p.runs if len(r.get("c_b_lag", ()))]
    return min(lags) if lags and len(lags) == len(p.runs) else 0.0


def tau_b_points(A, multi):
    """{phi: {N: Point}} for the tau_B rows: at each density and N the point,
    of this study or an --also study, that followed C_B furthest (the
    longest lags every run of it reached; then the most runs), chosen by
    its protocol, never by whether its seeds saw C_B fall to 1/e (that would
    pick the seeds that crossed early). Studies with longer lags
    (studies/cage_bonds.toml) thus give tau_B where the main runs stop short
    of it; where the chosen point's seeds did not all reach it, its cell is
    the bound."""
    out = {}
    for phi, d in multi.items():
        dd = dict(d)
        for p in list(A.points.values()) + list(A.extra.values()):
            if p.phi != phi or p.pairs != "neighbours" or abs(p.eps - EPS_MAIN) > 1e-9 or not c_b_reach(p):
                continue
            q = dd.get(p.N)
            if q is None or (c_b_reach(p), len(p.runs)) > (c_b_reach(q), len(q.runs)):
                dd[p.N] = p
        out[phi] = dd
    return out


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


def lags_in_tau_cr(d, ns):
    """Per N, the longest lag of the overlap over the run's own measured
    tau_alpha^CR (the range over seeds): whether every N ran as long in
    units of the structural relaxation; "" without tau_alpha^CR."""
    out = []
    for n in ns:
        x = []
        for r in d[n].runs:
            c = r.get("cut", {}).get(A_MAIN, {})
            lag, t = c.get("lag"), c.get("tau_cr", math.nan)
            if lag is not None and len(lag) and np.isfinite(t) and t > 0:
                x.append(float(lag[-1]) / t)
        if x:
            out.append(f"N {n}: {min(x):.2g}" + (f"-{max(x):.2g}" if max(x) > min(x) * 1.005 else ""))
    return ", ".join(out)


def has_cr(p):
    return any(r.get("cut_cr") and A_MAIN in r["cut_cr"] for r in p.runs)


def plot_quantity(A, name, slug, fn, has_cr_version, log_y, multi, multi_cr):
    fig, ax = plt.subplots(figsize=(6, 4.3))
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
    ax.legend(fontsize=7)
    return A.save(fig, f"fs_{slug}.png")


def plot_s4_q(A, multi, multi_cr):
    """S4(q, tau_alpha) of the whole box at every N, one panel per density,
    standard (solid) and cage-relative (dashed), the mean over seeds: where
    the curve has an Ornstein-Zernike plateau below q = 1/xi, and where it
    still rises at the box's smallest q (xi beyond the box: "no OZ fit")."""
    phis = list(multi)
    fig, axes = plt.subplots(1, len(phis), figsize=(4.0 * len(phis), 3.7), squeeze=False)
    drawn = False
    for ax, phi in zip(axes[0], phis):
        ns = sorted(multi[phi])
        for n, col in zip(ns, colours(len(ns))):
            for cr, ls in ((False, "o-"), (True, "s--")):
                p = (multi_cr.get(phi, {}) if cr else multi[phi]).get(n)
                curves = []
                for r in (p.runs if p is not None else []):
                    try:
                        curves.append(s4_at_tau(dict(r, cut=r["cut_cr"]) if cr else r))
                    except (KeyError, TypeError, IndexError, ValueError):
                        continue
                if not curves:
                    continue
                q0 = np.asarray(curves[0][0], float)
                same = [np.asarray(s_, float) for q_, s_ in curves if len(q_) == len(q0) and np.allclose(q_, q0)]
                y = np.nanmean(same, axis=0)
                ok = np.isfinite(y) & (y > 0) & (q0 > 0)
                if not ok.any():
                    continue
                ax.loglog(q0[ok], y[ok], ls, ms=2.5, lw=1, color=col, mfc="none" if cr else col,
                          label=f"N = {n}" + (" (cage-relative)" if cr else ""))
                drawn = True
        ax.set_title(f"φ = {phi:g}: S4(q, τ_α), whole box")
        ax.set_xlabel("q")
        if ax.has_data():
            ax.legend(fontsize=6)
    if not drawn:
        plt.close(fig)
        return ""
    axes[0][0].set_ylabel("S4(q, τ_α) (mean over seeds)")
    return A.save(fig, "fs_s4_q.png")


def calibration_note(A, multi, multi_cr, multi_tb=None):
    """The factors by which each quantity's quoted errors are scaled
    (points.calibration, pooled over each study's points)."""
    ensure_calibrated(list(A.points.values()) + list(A.extra.values()))
    def populations(*sources):
        return {id(p.population): p.population for src in sources for d in src.values() for p in d.values()}
    main_pops, tb_pops = populations(multi, multi_cr), populations(multi, multi_tb or {})
    applied = []
    for name, slug, fn, has_cr_version, _ in quantities(multi):
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


def write_finite_size(A, path, command):
    """The report at `path`; its figures next to it in finite_size/ (copied
    from the study's figures/)."""
    multi = points_by_phi_n(A)
    # the cage-relative rows from the points that have them (another study's,
    # where the point with most runs at that phi and N has none)
    multi_cr = {phi: {n: p for n, p in d.items() if has_cr(p)} for phi, d in points_by_phi_n(A, has_cr).items()}
    L = ["# Finite size: every measure against N", "",
         "Generated by `launch_scripts/analyse_study.sh` (do not edit by hand) from the studies in "
         + ", ".join(f"`{os.path.relpath(s, os.path.dirname(os.path.abspath(path)))}`" for s in [A.dir] + A.also)
         + f". Command: `{command}`", "",
         f"Each cell: the mean over seeds with its error (the runs' own errors, jackknife over origin blocks, "
         f"combined, times the study's factor below where its seeds scatter more; the seeds' spread where no run "
         f"quotes one; \"no error\" where one seed quotes none, and such a "
         f"size takes no part in the verdict); ¹ one seed. A verdict is computed from the "
         f"numbers: **converged** from the smallest N whose value and every larger N's agree with the largest "
         f"N's within {Z_CONVERGED:g} combined errors; otherwise **drifting**, with the change per doubling of N "
         f"between the two largest sizes. χ4^P is the peak of χ4(t) of sub-boxes of about that many particles "
         f"(interior peaks only); ξ is the whole box's Ornstein-Zernike ξ at τ_α, taken only where at least "
         f"{MIN_SHELLS} q shells lie below q ξ = 1 (else \"not resolved\" at this N; \"no OZ fit\": the S4 node refused the fit at τ_α, for ξ beyond the "
         f"box, below the q range, or with a jackknife error not below ξ); [k q]: the shells below "
         f"q ξ = 1 of its runs (the range over seeds), which are the q points its OZ fit ran over (the S4 node "
         f"fits over q ξ ≤ 1, and over the 3 smallest q where fewer lie there). a = {A_MAIN}, ε = 0.9, "
         f"neighbour kick pairs. Nothing here is tuned toward the paper's numbers.", ""]
    if not multi:
        L += ["No density was run at more than one N.", ""]
    multi_tb = tau_b_points(A, multi)
    L += calibration_note(A, multi, multi_cr, multi_tb)
    rows, cb_at = quantities(multi), c_b_times(multi)
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
                cells = [w or cell(m) for m, w in zip(ms, why)]
                if slug == "xi":  # how many q shells its fits had below q xi = 1 (issue 27, item 4)
                    cells = [c + shells_note(dd.get(n), cr) for c, n in zip(cells, qn)]
                L.append(f"| {label} | " + " | ".join(cells) + f" | {text} |")
        seeds = ", ".join(f"N {n}: {len(d[n].runs)}" for n in ns)
        spans = lags_in_tau_cr(d, ns)
        crs = multi_cr.get(phi, {})
        if crs and any(crs.get(n) is not d.get(n) for n in crs):
            seeds += "; cage-relative rows: " + ", ".join(f"N {n}: {len(p.runs)}" for n, p in sorted(crs.items()))
        tbs = [(n, p) for n, p in sorted(multi_tb.get(phi, {}).items()) if p is not d.get(n)]
        if tbs:
            seeds += "; τ_B row: " + ", ".join(f"N {n}: {len(p.runs)} of study {getattr(p, 'study', '?')}"
                                               for n, p in tbs)
        L += ["", f"Runs (seeds) per N: {seeds}." + (f" Longest lag in units of each run's own measured "
                                                      f"τ_α^CR (the same at every N where the protocol is): {spans}."
                                                      if spans else ""), ""]
    if multi:
        L += spread_section(multi, multi_cr)
        L += ["## Plots", ""]
        for name, slug, fn, has_cr_version, log_y in rows:
            f = plot_quantity(A, name, slug, fn, has_cr_version, log_y, multi_tb if slug == "tau_b" else multi,
                              multi_cr)
            if f:
                figures.append(f)
                L.append(f"- {name}: ![{name}](finite_size/{os.path.basename(f)})")
        f = plot_s4_q(A, multi, multi_cr)
        if f:
            figures.append(f)
            L.append("- S4(q, τ_α) of the whole box at every N, standard (filled, solid) and cage-relative (open, "
                     "dashed): where it levels off below q = 1/ξ (an Ornstein-Zernike ξ the box resolves) and where "
                     f"it still rises at the box's smallest q: ![S4(q)](finite_size/{os.path.basename(f)})")
        L.append("")
    out_dir = os.path.dirname(os.path.abspath(path))
    os.makedirs(out_dir, exist_ok=True)
    fig_dir = os.path.join(out_dir, "finite_size")
    if figures:
        os.makedirs(fig_dir, exist_ok=True)
        for f in figures:
            shutil.copy(os.path.join(A.dir, f), os.path.join(fig_dir, os.path.basename(f)))
    with open(path, "w") as fh:
        fh.write("\n".join(L))
    return len(multi)
