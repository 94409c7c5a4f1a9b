"""Equilibration and steadiness run by run: every run of every study read,
its equilibration in units of tau_alpha^CR (the structure's relaxation,
not only the overlap's) and whether its tau_alpha(t0), and its
tau_alpha^CR(t0) where it measured it, stay steady over its production
(size_rows.production_change against steady.steady_limit). The
finite-size tables judge each size's seed mean; this section judges each
run, so that no run's values pass as a steady state's unchecked."""
import math

import numpy as np

from .config import A_MAIN
from .local_measures import TAU_CR, series_measuring
from .size_rows import cutx, production_change
from .steady import steady_limit
from .verdicts import fmt


def std_cut(r):
    """The run's standard results at the main cutoff ({} where it has none)."""
    return (r.get("cut") or {}).get(A_MAIN, {})


def run_change(r, cr):
    """(change in % of tau_alpha, its error, its dof, the verdict): "steady",
    "not steady", or why it cannot be judged."""
    try:
        if not cutx(r, cr).get("tau_alpha", math.nan) > 0:
            return math.nan, math.nan, None, "not judged: no τ_α"
        v, e = production_change(r, cr)
        k = int(np.isfinite(np.asarray(cutx(r, cr)["tau_t0"], float)).sum()) - 2
    except (KeyError, TypeError, ValueError, IndexError):
        return math.nan, math.nan, None, "not measured"
    if not np.isfinite(v):
        return v, e, None, "not judged: fewer than 3 origins"
    if not (np.isfinite(e) and e > 0 and k > 0):
        return v, e, None, "not judged"
    return v, e, k, ("not steady" if abs(v) > steady_limit(k) * e else "steady")


def equilibration_units(A):
    """{(pairs, eps, phi): tau_alpha^CR}: the reference for a run that did
    not measure its own, the largest N that measured it at that density
    (local_measures.series_measuring, over every study read)."""
    return {(p.pairs, p.eps, p.phi): p.mean(TAU_CR)[0] for p in series_measuring(A, TAU_CR)}


def all_runs(A):
    """(study, Point, run) of every complete run read, each once."""
    seen, out = set(), []
    for pts in (A.points.values(), A.extra.values()):
        for p in pts:
            for r in p.runs:
                if id(r) not in seen:
                    seen.add(id(r))
                    out.append((r.get("study") or getattr(p, "study", None) or getattr(A, "study_name", "this study"), p, r))
    return out


def change_cell(v, e, why):
    if why == "not measured":
        return "—"
    if why.startswith("not judged"):
        return (f"{v:.3g}, " if np.isfinite(v) else "") + why
    return f"{fmt(v, e)} {why}"


def across_protocols(rows):
    """Where studies of different equilibration times ran the same system
    (kick pairs, eps, phi, N), their runs' mean tau_alpha at each
    equilibration time, and the change from the shortest to the longest
    with its error (the standard errors of the two means, from the seeds'
    spread, combined): slow ageing that no run's own tau_alpha(t0) can show
    (a growth as t_w^0.3 adds some 5% over a production of a sixth of t_w).
    Lines only; no verdict beyond the number of errors."""
    groups = {}
    for study, p, r, _, t_eq, _, _, tau, _ in rows:
        if np.isfinite(t_eq) and np.isfinite(tau):
            sys_ = (p.pairs, p.eps, p.phi, p.N)
            groups.setdefault(sys_, {}).setdefault((round(t_eq, 1), study), []).append(tau)
    out = []
    for (pairs, eps, phi, n), by in sorted(groups.items()):
        if len({t for t, _ in by}) < 2:
            continue
        stats = []
        for (t, study), taus in sorted(by.items()):
            m = float(np.mean(taus))
            se = float(np.std(taus, ddof=1) / math.sqrt(len(taus))) if len(taus) > 1 else math.nan
            stats.append((t, study, m, se, len(taus)))
        lo, hi = stats[0], stats[-1]
        d, e = hi[2] - lo[2], math.hypot(hi[3], lo[3])
        # Welch-Satterthwaite: two means of 2 or 3 seeds each leave an error known to a few dof only
        dof = e ** 4 / sum(x[3] ** 4 / (x[4] - 1) for x in (lo, hi)) if np.isfinite(e) and e > 0 else math.nan
        change = (f": {100 * d / lo[2]:+.0f}% from the shortest to the longest"
                  + (f", {abs(d) / e:.1f} of their combined errors ({dof:.2g} dof)" if np.isfinite(e) and e > 0 else
                     " (one run at one of them: no error)"))
        cells = "; ".join(f"{m:.3g}" + (f" ± {se:.2g}" if np.isfinite(se) else "") + f" after {t:.4g} ({study}, "
                          f"{k} run{'s' * (k > 1)})" for t, study, m, se, k in stats)
        out.append(f"- φ = {phi:g}, N = {n}" + ("" if (pairs, eps) == ("neighbours", 0.9) else f" ({pairs}, ε {eps:g})")
                   + f": τ_α {cells}{change}.")
    if out:
        out = ["", "**τ_α against the equilibration time.** Where studies of different equilibration times ran the "
               "same system, the mean τ_α of their runs at each (the standard error of the mean from the seeds' "
               "spread): a τ_α that grows with the equilibration time is ageing too slow for any run's own "
               "τ_α(t0) to show over its production.", ""] + out
    return out


def steady_section(A):
    """The section's lines (finite_size.md)."""
    ref = equilibration_units(A)
    rows, per_study = [], {}
    for study, p, r in sorted(all_runs(A), key=lambda x: (x[0], x[1].pairs, -x[1].eps, x[1].phi, x[1].N,
                                                          x[2].get("name", ""))):
        has_cr = A_MAIN in (r.get("cut_cr") or {})
        changes = (run_change(r, False), run_change(r, True) if has_cr else (math.nan, math.nan, None, "not measured"))
        own = cutx(r, True).get("tau_alpha", math.nan) if has_cr else math.nan
        own = own if np.isfinite(own) and own > 0 else math.nan
        unit = own if np.isfinite(own) else ref.get((p.pairs, p.eps, p.phi), math.nan)
        t_eq = float(r.get("t_equil", math.nan))
        tau = std_cut(r).get("tau_alpha", math.nan)
        sched = r.get("schedule")
        prod = (sched[0] - 1) * sched[1] / tau if sched and np.isfinite(tau) and tau > 0 else math.nan
        s = per_study.setdefault(study, {"runs": 0, "eq": [], "std": {}, "cr": {}})
        s["runs"] += 1
        for key, (_, _, _, why) in zip(("std", "cr"), changes):
            if why != "not measured":
                kind = why.split(":")[0]
                s[key].setdefault(kind, []).append(f"φ {p.phi:g} N {p.N} seed {r.get('seed')}"
                                                   + ("" if (p.pairs, p.eps) == ("neighbours", 0.9)
                                                      else f" ({p.pairs}, ε {p.eps:g})"))
        if np.isfinite(t_eq) and np.isfinite(unit) and unit > 0:
            s["eq"].append((t_eq / unit, p.phi))
        rows.append((study, p, r, changes, t_eq, unit, own, tau, prod))
    L = ["## Equilibration and steadiness, run by run", "",
         "The size studies (studies/size_standard.toml, studies/size_cage.toml) equilibrate each run for 5 τ_α^CR "
         "of their estimate (run_length.equilibration_tau in units of the cage-relative τ_α^CR, whose estimate is "
         "the pilot's measured value × 1.2: 6 of the pilot's τ_α^CR), so that the structure has relaxed, not only "
         "Q; the other studies count their equilibration in the standard τ_α (their study files say how many; "
         "the lines below give what that came to in τ_α^CR). Every run is checked here: the change of its "
         "τ_α(t0) over the production (the line through τ_α(t0)/τ_α against t0/τ_α, from the first origin to "
         "the last, in % of τ_α), and of its τ_α^CR(t0) where the run measured it, against 0 within the "
         "Student-t limit of 3σ's probability with the dof of the origins' scatter about the line (4.9 errors "
         "for 8 origins); not judged where no error can be had (origins closer than τ_α, or fewer than 4). "
         "At that limit about 3 runs in 1000 would be called not steady by chance. \"equil. / τ_α^CR\": the "
         "run's equilibration time over its own measured τ_α^CR, or (†) over the τ_α^CR measured at the "
         "largest N at that density where the run measured none. \"production / τ_α\": the span of its "
         "origins over its own τ_α.", ""]
    for study, s in sorted(per_study.items()):
        eq = s["eq"]
        parts = []
        for key, what in (("std", "τ_α(t0)"), ("cr", "τ_α^CR(t0)")):
            d = s[key]
            if not d:
                continue
            off = d.get("not steady", [])
            parts.append(f"{what}: {len(d.get('steady', []))} steady, {len(off)} not steady"
                         + (f" ({'; '.join(off)})" if off else "") + f", {len(d.get('not judged', []))} not judged")
        L.append(f"- **{study}**, {s['runs']} runs: " + "; ".join(parts)
                 + (f". Equilibration {min(eq)[0]:.3g} to {max(eq)[0]:.3g} τ_α^CR (the least at φ = {min(eq)[1]:g})"
                    if eq else "") + ".")
    L += across_protocols(rows)
    L += ["", "| study | kick pairs | ε | φ | N | seed | equilibration | equil. / τ_α^CR | τ_α | production / τ_α | "
              "τ_α(t0) change, % | τ_α^CR(t0) change, % |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    def num(x, f):
        return format(x, f) if np.isfinite(x) else "—"
    for study, p, r, changes, t_eq, unit, own, tau, prod in rows:
        cells = [change_cell(v, e, why) for v, e, _, why in changes]
        eq = (f"{t_eq / unit:.3g}" + ("" if np.isfinite(own) else " †")
              if np.isfinite(t_eq) and np.isfinite(unit) and unit > 0 else "—")
        L.append(f"| {study} | {p.pairs} | {p.eps:g} | {p.phi:g} | {p.N} | {r.get('seed', '—')} | {num(t_eq, '.4g')} | "
                 f"{eq} | {num(tau, '.3g')} | {num(prod, '.3g')} | {cells[0]} | {cells[1]} |")
    L.append("")
    return L
