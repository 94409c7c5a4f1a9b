"""Finite size: tau_alpha and D (with theta) against N at densities run at several N."""
import math

import matplotlib.pyplot as plt
import numpy as np

from .. import fits as sf
from .config import A_MAIN, EPS_MAIN
from .points import fit_series, point_error
from .quantities import tau
from .verdicts import fmt
from .plotting import colours, errorbar, log_axes


class SizeTable(dict):
    """{N: Point} of one density, all of one protocol (`protocol`, the
    leading one: leading_protocol); `others`: [(study, N, runs)] the sizes
    only studies of another protocol ran, left out of the table, to be named
    beside it."""
    def __init__(self, protocol, points, others):
        super().__init__(points)
        self.protocol, self.others = protocol, others


def main_candidates(A, has=lambda p: True, lead_by="cr"):
    """The points of the main series (neighbours, eps 0.9) that `has` takes
    and whose sizes are not held back (held_sizes, by the same leading
    protocol as the table's: lead_by)."""
    held = held_sizes(A, has, lead_by)
    return [p for p in list(A.points.values()) + list(A.extra.values())
            if p.pairs == "neighbours" and abs(p.eps - EPS_MAIN) < 1e-9 and has(p) and not held(p)]


def protocol_of(A, study):
    """A study's protocol: its run lengths' unit, equilibration, origins and
    their spacing (Analysis.protocols, from each study's study.toml; the lag
    range is not part of it: it sets what a run reaches, and a cell says
    "not reached"). None where the study file does not say (all such
    studies count as one)."""
    return getattr(A, "protocols", {}).get(study)


def leading_protocol(A, phi, ps, lead_by="cr", planned_too=False):
    """The protocol whose runs a density's against-N table takes: the one
    whose studies run phi at the most N (their unfinished sizes counted:
    planned_sizes); among as many, with lead_by "cr" the one with the
    cage-relative measures (studies/size_cage.toml: run lengths in units of
    tau_alpha^CR), with "n" the one reaching the largest N (D against N:
    studies/d_size.toml to 10^6); then the most runs. With "cr" a protocol
    that measured neither chi4 nor the cage-relative overlap (d_size) leads
    only where no other ran. Among the protocols
    with points in ps, or (planned_too) with sizes planned at phi at all."""
    planned = planned_sizes(A, ps).get(phi, {})
    studies = {}
    for st in set(planned) | {study_of(p) for p in ps}:
        studies.setdefault(protocol_of(A, st), set()).add(st)

    def key(pr):
        own = [p for p in ps if study_of(p) in studies[pr]]
        sizes = set().union(*(planned.get(st, set()) for st in studies[pr])) | {p.N for p in own}
        cr = any(A_MAIN in (r.get("cut_cr") or {}) for p in own for r in p.runs)
        # the tables of every measure: a protocol of the overlap and the MSD alone (d_size, for
        # D against N) does not lead them, whatever its sizes, where one measured chi4 or the
        # cage-relative overlap
        rich = cr or any("chi4" in (r.get("cut") or {}).get(A_MAIN, {}) for p in own for r in p.runs)
        if lead_by == "cr":
            return (rich, len(sizes), cr, sum(len(p.runs) for p in own), str(pr))
        return (len(sizes), max(sizes), sum(len(p.runs) for p in own), str(pr))
    with_points = [pr for pr in studies if any(study_of(p) in studies[pr] for p in ps)]
    return max(with_points if with_points and not planned_too else studies, key=key)


def points_by_phi_n(A, has=lambda p: True, lead_by="cr"):
    """{phi: SizeTable} of the main dynamics over this study and the --also
    studies, each density's sizes of one protocol (the same run lengths in
    units of the same relaxation time, the same origins, at every N:
    leading_protocol); at a size that several of its studies ran, the point
    with the most runs, and among as many the study that runs that phi at
    the most N (then the one with the cage-relative measures). The sizes
    only another protocol ran are named in the table's `others`, not used
    (d_size's one-seed N = 10^6 at phi 0.76, 5 tau_alpha of equilibration
    and 4 origins, is not a column of scale's table). Only densities with
    more than one N."""
    by_phi = {}
    for p in main_candidates(A, has, lead_by):
        by_phi.setdefault(p.phi, []).append(p)
    out = {}
    for phi, ps in sorted(by_phi.items()):
        lead = leading_protocol(A, phi, ps, lead_by)
        mine = [p for p in ps if protocol_of(A, study_of(p)) == lead]
        sizes = {}
        for p in mine:
            sizes.setdefault(study_of(p), set()).add(p.N)
        rank = lambda p: (len(p.runs), len(sizes[study_of(p)]), any(A_MAIN in (r.get("cut_cr") or {}) for r in p.runs))
        d = {}
        for p in mine:
            if p.N not in d or rank(p) > rank(d[p.N]):
                d[p.N] = p
        others = sorted({(str(study_of(p)), p.N, len(p.runs)) for p in ps if p.N not in d},
                        key=lambda x: (x[1], x[0]))
        if len(d) > 1:
            out[phi] = SizeTable(lead, d, others)
    return out


def others_note(d, lead="; not in this table", close=""):
    """The sizes a density's table leaves out (SizeTable.others), as a clause; "" without."""
    others = getattr(d, "others", [])
    if not others:
        return ""
    return (f"{lead}, another study's protocol: "
            + ", ".join(f"N {n} of {st} ({k} run{'s' if k > 1 else ''})" for st, n, k in others) + close)


def held_sizes(A, has=lambda p: True, lead_by="cr"):
    """p -> whether point p's size is held back: no conclusion from a size
    whose runs did not all finish, nor another protocol's run in its place (a
    size that a study of the leading protocol, its unfinished sizes counted,
    has not finished is held back at that phi, not filled from a study of
    other run lengths; lead_by: leading_protocol's tie rule)."""
    waiting = waiting_sizes(A, has, lead_by)
    return lambda p: bool(unfinished_runs(A, p)) or waiting_for(waiting, p, A) is not None


def waiting_sizes(A, has=lambda p: True, lead_by="cr"):
    """protocol_waiting over the main series' points whose runs all finished
    (held_sizes, and Analysis.promote_largest_n)."""
    done = [p for p in list(A.points.values()) + list(A.extra.values())
            if p.pairs == "neighbours" and abs(p.eps - EPS_MAIN) < 1e-9 and has(p) and not unfinished_runs(A, p)]
    return protocol_waiting(A, done, lead_by)


def protocol_waiting(A, allp, lead_by="cr"):
    """{(phi, N): (study, runs unfinished)} of the main series where a study
    of the leading protocol (leading_protocol over every size planned at phi,
    unfinished ones counted: at phi 0.76 scale's five sizes tie d_size's,
    and the cage-relative scale leads) has runs of that N unfinished (the
    first such study by name). Another protocol's unfinished size holds
    nothing back: d_size's unfinished N = 262144 does not hide scale's
    finished one."""
    planned, main = planned_sizes(A, allp), unfinished_main(A)
    by_phi = {}
    for p in allp:
        by_phi.setdefault(p.phi, []).append(p)
    lead, out = {}, {}
    for st, ph, n, k in sorted(main):
        phi = next((f for f in planned if abs(f - ph) < 1e-9), ph)
        if phi not in lead:
            lead[phi] = leading_protocol(A, phi, by_phi.get(phi, []), lead_by, planned_too=True)
        if protocol_of(A, st) == lead[phi] and (phi, n) not in out:
            out[(phi, n)] = (st, k)
    return out


def unfinished_main(A):
    """[(study, phi, N, runs unfinished)] of the main series (Analysis.unfinished)."""
    return [(st, ph, n, k) for (st, pairs, eps, ph, n), k in getattr(A, "unfinished", {}).items()
            if k and pairs == "neighbours" and abs(eps - EPS_MAIN) < 1e-9]


def planned_sizes(A, allp):
    """{phi: {study: set of N}}: the sizes of points allp, and the sizes
    with runs unfinished of the main series (a study's protocol counts the
    sizes it will have)."""
    planned = {}
    for p in allp:
        planned.setdefault(p.phi, {}).setdefault(study_of(p), set()).add(p.N)
    for st, ph, n, _ in unfinished_main(A):
        phi = next((f for f in planned if abs(f - ph) < 1e-9), ph)
        planned.setdefault(phi, {}).setdefault(st, set()).add(n)
    return planned


def waiting_for(waiting, p, A=None):
    """(study, runs unfinished) of the leading protocol holding point p's size
    back (protocol_waiting), or None; with A, never for a point of that very
    protocol (another of its studies finished that size: it is that
    protocol's run, not a stand-in). Without the studies' protocols
    (A.protocols empty: made by hand) nothing is exempt: holding back is the
    side to err on."""
    v = next((v for (ph, n), v in waiting.items() if abs(ph - p.phi) < 1e-9 and n == p.N), None)
    if v is not None and A is not None and getattr(A, "protocols", None) and \
            protocol_of(A, v[0]) == protocol_of(A, study_of(p)) and study_of(p) != v[0]:
        return None
    return v


def unfinished_runs(A, p):
    """How many runs of point p's study at its (pairs, eps, phi, N) are not
    complete (Analysis.unfinished; 0 for an Analysis without that record)."""
    return getattr(A, "unfinished", {}).get((study_of(p), p.pairs, p.eps, p.phi, p.N), 0)


def held_back(A, phi):
    """The sizes of the main series at phi left out because runs of them are
    unfinished: [(N, study, runs unfinished)]."""
    out = []
    for (st, pairs, eps, ph, n), k in sorted(getattr(A, "unfinished", {}).items()):
        if pairs == "neighbours" and abs(eps - EPS_MAIN) < 1e-9 and abs(ph - phi) < 1e-9 and k:
            out.append((n, st, k))
    return out


def study_of(p):
    """The study a point came from (an --also point says; a run says its own)."""
    return getattr(p, "study", None) or (p.runs[0].get("study") if p.runs else None)


def common_densities(multi):
    """({N: {phi: Point}}, the densities of the largest N that has at least
    3 of them): a cross-density fit at each N over the same densities."""
    per_n = {}
    for d in multi.values():
        for n, p in d.items():
            per_n.setdefault(n, {})[p.phi] = p
    wide = [n for n, ps in per_n.items() if len(ps) >= 3]
    return per_n, (sorted(per_n[max(wide)]) if wide else [])


Z_CONVERGED = 2.0   # values within 2 combined standard errors agree


def flat_slope(d):
    """(slope per doubling of N, its error) of the weighted straight line
    through d = [(N, value, error)] against log2 N (weights 1/error^2; the
    error from the weights, not the residuals: the values' own errors)."""
    x = np.log2([n for n, _, _ in d])
    y = np.array([v for _, v, _ in d])
    w = 1.0 / np.array([e for _, _, e in d]) ** 2
    xm, ym = (w * x).sum() / w.sum(), (w * y).sum() / w.sum()
    sxx = (w * (x - xm) ** 2).sum()
    return float((w * (x - xm) * (y - ym)).sum() / sxx), float(1.0 / math.sqrt(sxx))


def levels_off(d3):
    """Whether, of three sizes [(N, value, error)], the change per doubling
    of N over the last step differs from that over the step before by more
    than Z_CONVERGED combined errors: 200, 250, 251 (errors 0.7) level off;
    27, 24, 21 (errors 1, 1, 3) fall on as they fell."""
    (n1, v1, e1), (n2, v2, e2), (n3, v3, e3) = d3
    a, b = math.log2(n2 / n1), math.log2(n3 / n2)
    s1, s2 = (v2 - v1) / a, (v3 - v2) / b
    err = math.sqrt((e1 / a) ** 2 + (e2 * (1 / a + 1 / b)) ** 2 + (e3 / b) ** 2)
    return abs(s2 - s1) > Z_CONVERGED * err


def size_verdict(ns, vals, errs):
    """Converged or drifting, from the numbers (the one rule of every
    against-N verdict: the finite-size tables and the reproduction's rows):
    the smallest N0 such that the value at every N >= N0 agrees with the
    largest N's within Z_CONVERGED combined errors (at least two sizes) and
    the weighted line against log2 N through the sizes from N0 on, and at
    least the three largest where there are three, is flat within
    Z_CONVERGED of its error (a steady drift whose every step is within the
    errors is a drift: 30, 27, 24, 21 with errors 1, 1, 1, 3 each agree with
    21 from 4096 on, and fall by 1.5 ± 0.6 per doubling), unless N0 is the
    second largest and the last step levels off from the one before
    (levels_off: 200, 250, 251 converge from the middle size); otherwise
    drifting. Either way the change per doubling
    of N between the two largest sizes with its error, which bounds what
    "converged" means. Returns (text, N0 or None, drift, error)."""
    d = [(n, v, e) for n, v, e in zip(ns, vals, errs) if np.isfinite(v) and np.isfinite(e) and e > 0]
    if len({n for n, _, _ in d}) != len(d):
        raise ValueError(f"size_verdict: a size given twice ({sorted(n for n, _, _ in d)})")
    if len(d) < 2:
        return ("one N only" if d else "no data"), None, math.nan, math.nan
    d.sort()
    nmax, vmax, emax = d[-1]
    n1, v1, e1 = d[-2]
    per = math.log2(nmax / n1)
    drift, derr = (vmax - v1) / per, math.hypot(emax, e1) / per
    rel = f" ({100 * drift / abs(v1):+.0f}%)" if v1 else ""
    change = f"{fmt(drift, derr)} per doubling of N{rel} from N = {n1} to {nmax}"
    n0, sloped = None, None
    for k in range(len(d) - 1):
        if not all(abs(v - vmax) <= Z_CONVERGED * math.hypot(e, emax) for _, v, e in d[k:-1]):
            continue
        # the line through the sizes from N0 on (three or more) must be flat; two sizes that agree
        # within their errors converge only where the three largest lie flat too, or where the last
        # step is flatter than the one before it beyond the errors (the approach levels off)
        if len(d) >= 3:
            b, be = flat_slope(d[min(k, len(d) - 3):])
            if abs(b) > Z_CONVERGED * be and not (len(d) - k == 2 and levels_off(d[-3:])):
                sloped = sloped or (d[min(k, len(d) - 3)][0], b, be)
                continue
        n0 = d[k][0]
        break
    # a longer range that drifts says so beside any verdict of its tail
    steady = (f"; over N = {sloped[0]} to {nmax} the line in log2 N changes by {fmt(sloped[1], sloped[2])} per "
              f"doubling, {abs(sloped[1]) / sloped[2]:.1f}σ from flat" if sloped else "")
    if n0 is not None:
        return (f"converged from N = {n0} on (within {Z_CONVERGED:g}σ of N = {nmax}; {change}{steady})",
                n0, drift, derr)
    return f"drifting: {change}{steady}", None, drift, derr


def n_verdict(vals):
    """size_verdict of a value {N: (value, error)} (an exponent fitted at each N)."""
    ns = sorted(vals)
    return size_verdict(ns, [vals[n][0] for n in ns], [vals[n][1] for n in ns])[0]


def d_n_results(A):
    """D against N at each density run at several N, and theta of
    D ~ tau_alpha^-theta at each N over the densities it has (studies/d_size.toml):
    in two dimensions box-scale flows carry part of D and may make both
    depend on the box."""
    dD = lambda r: (r.get("D", math.nan), r.get("D_err", math.nan))
    multi = points_by_phi_n(A, lambda p: np.isfinite(p.mean(dD)[0]), lead_by="n")
    if not multi:
        A.row("D against N (box-scale flows)", "3.2 (D, θ)", "not studied",
              "one N per density (add studies/d_size.toml with --also)", "not run", "", [])
        return
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    cells, used = [], []
    for (phi, d), col in zip(multi.items(), colours(len(multi))):
        ns = sorted(d)
        vals = [d[n].mean(dD) for n in ns]
        errorbar(ax[0], ns, [v[0] for v in vals], [point_error(v) for v in vals], fmt="o-", color=col, label=f"φ = {phi:g}")
        cells.append(f"φ {phi:g}: " + ", ".join(f"{fmt(v[0], point_error(v))} (N {n})" for n, v in zip(ns, vals))
                     + others_note(d, " [not taken", "]"))
        used += list(d.values())
    log_axes(ax[0], "N", "D", "D against the number of particles")
    # theta at each N over the same densities at every N (like with like: the
    # densities of the largest N with at least 3 of them; theta' of the
    # highest densities differs from theta), at each N that has them all
    per_n, common = common_densities(multi)
    th = {}
    if common:
        for n, ps in sorted(per_n.items()):
            if all(phi in ps for phi in common):
                f = A.fit(f"D_tau_N{n}", fit_series([ps[phi] for phi in common], dD, sf.power, xrun=tau))
                if f.ok:
                    th[n] = (-f.p["s"], f.error("s"), len(common))
    if th:
        ns = sorted(th)
        errorbar(ax[1], ns, [th[n][0] for n in ns], [th[n][1] for n in ns], fmt="o-", color="k")
    ax[1].set_xscale("log")
    ax[1].set_xlabel("N")
    ax[1].set_ylabel("θ (D ∝ τ_α^-θ, φ = " + ", ".join(f"{x:g}" for x in common) + ")")
    ax[1].set_title("θ against N")
    f = A.save(fig, "D_N.png")
    A.row("D against N (box-scale flows)", "3.2 (D, θ)", "not studied", "; ".join(cells), "figure", f, used)
    if len(th) >= 2:
        A.row("θ against N (D ∝ τ_α^-θ at each N)", "3.2, fig. D-vs-tau", "not studied",
              ", ".join(f"N {n}: {fmt(th[n][0], th[n][1])}" for n in sorted(th))
              + " (each over φ = " + ", ".join(f"{x:g}" for x in common) + ")", n_verdict(th), f, used)


def tau_n_results(A):
    """tau_alpha against N at each density run at several N (this study's
    points and those of --also studies with the same dynamics)."""
    multi = points_by_phi_n(A)
    if not multi:
        A.row("τ_α against N (finite size)", "2 (N = 3.6 x 10^5 to 4 x 10^6)", "not studied",
              "one N per density in this study (add one with --also, e.g. results/size_standard)", "not run", "", [])
        return
    fig, ax = plt.subplots(figsize=(6, 4.5))
    cells, used = [], []
    for (phi, d), col in zip(multi.items(), colours(len(multi))):
        ns = sorted(d)
        vals = [d[n].mean(tau) for n in ns]
        errorbar(ax, ns, [v[0] for v in vals], [v[1] for v in vals], fmt="o-", color=col, label=f"φ = {phi:g}")
        cells.append(f"φ {phi:g}: " + ", ".join(f"{fmt(v[0], v[1])} (N {n}, {d[n].mean(tau)[3]} seed{'s' if d[n].mean(tau)[3] > 1 else ''})"
                                                 for n, v in zip(ns, vals)) + others_note(d, " [not taken", "]"))
        used += list(d.values())
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("N")
    ax.set_ylabel(f"τ_α (ε = {EPS_MAIN:g}, a = {A_MAIN:g})")
    ax.legend(fontsize=8)
    ax.set_title("τ_α against the number of particles")
    f = A.save(fig, "tau_alpha_N.png")
    A.row("τ_α against N (finite size)", "2 (N = 3.6 x 10^5 to 4 x 10^6)", "not studied", "; ".join(cells), "figure", f, used)


def kappa_n_results(A):
    """kappa of the slow clusters' collapse (clusters.collapse_fit) at each N,
    over the same densities at every N (those of the largest N with at
    least 3, as for theta): whether the paper's estimator moves with the box
    (at small N the box cuts the largest clusters off)."""
    from .clusters import collapse_fit, has_clusters
    multi = points_by_phi_n(A, lambda p: any(has_clusters(r) for r in p.runs))
    per_n, common = common_densities(multi)
    if not common:
        A.row("κ by the collapse against N", "3.3, fig. dist-collapse", "not studied",
              "fewer than 3 densities with clusters at several N", "not run", "", [])
        return
    ks, used = {}, []
    for n, ps in sorted(per_n.items()):
        if all(phi in ps for phi in common):
            f, err, _ = collapse_fit(A, [ps[phi] for phi in common], f"kappa_collapse_N{n}")
            if f.ok:
                ks[n] = (f.p["kappa"], err, f.quality)
                used += [ps[phi] for phi in common]
    if len(ks) < 2:
        A.row("κ by the collapse against N", "3.3, fig. dist-collapse", "not studied",
              "the collapse at fewer than 2 N", "not determined", "", used)
        return
    ns = sorted(ks)
    fig, ax = plt.subplots(figsize=(5.5, 4.2))
    errorbar(ax, ns, [ks[n][0] for n in ns], [ks[n][1] for n in ns], fmt="o-", color="k")
    ax.axhline(1.8, color="0.6", ls=":", label="paper ≈ 1.8")
    ax.set_xscale("log")
    ax.set_xlabel("N")
    ax.set_ylabel("κ of the collapse (N_c ≥ 1)")
    ax.set_title("κ against N, φ = " + ", ".join(f"{x:g}" for x in common))
    ax.legend(fontsize=8)
    f = A.save(fig, "kappa_N.png")
    A.row("κ by the collapse against N (the paper's estimator at each N)", "3.3, fig. dist-collapse", "not studied",
          ", ".join(f"N {n}: {fmt(ks[n][0], ks[n][1])} (quality {ks[n][2]:.2g})" for n in ns)
          + " (each over φ = " + ", ".join(f"{x:g}" for x in common) + ")", n_verdict(ks), f, used)
