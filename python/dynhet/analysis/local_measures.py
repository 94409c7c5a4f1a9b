"""Cage-relative tau_alpha and bond breaking: tau_alpha^CR(phi) and
tau_B(phi) with the power-law and VFT fits of tau_alpha(phi), and the three
against N where a density was run at several N (studies/cage.toml). Rows only
where some run measured them ([observables] cage_relative, "bond_breaking")."""
import math

import matplotlib.pyplot as plt
import numpy as np

from .config import A_MAIN, EPS_MAIN, say
from .overlap import tau_fits
from .plotting import errorbar
from .points import measured_error, point_error, series_arrays
from .quantities import PER_RUN, tau
from .size import points_by_phi_n, size_verdict
from .verdicts import fmt

TAU_CR, TAU_B = PER_RUN["tau_alpha_cr"], PER_RUN["tau_b"]
MEASURES = (("τ_α", tau, "k", "o"), ("τ_α^CR (cage-relative)", TAU_CR, "tab:purple", "s"),
            ("τ_B (bond breaking)", TAU_B, "tab:green", "^"))


def measured(p, fn):
    return np.isfinite(p.mean(fn)[0])


def series_measuring(A, fn):
    """One point per density of the main series: the largest N whose runs
    measured fn. With --largest-n a study of the standard measures alone
    stands in for the series at some densities (Analysis.promote_largest_n);
    then (--largest-n) the cage-relative and bond-breaking times take the
    largest N over every study read whose runs measured them and are all
    complete (a study of
    those measures alone, studies/size_cage.toml, runs them to larger N
    than the study of the paper's rows)."""
    return A.series_with(lambda p: measured(p, fn), over_studies=fn is not tau and hasattr(A, "promoted"))


def local_phi_results(A):
    per = {fn: series_measuring(A, fn) for _, fn, _, _ in MEASURES}
    if not per[TAU_CR] and not per[TAU_B]:
        say("    no run measured tau_alpha^CR or tau_B: no rows")
        return
    fig, ax = plt.subplots(figsize=(6.5, 4.6))
    for label, fn, col, m in MEASURES:
        sel = per[fn]
        x, y, e = series_arrays(sel, fn)
        errorbar(ax, x, y, e, fmt=m, ms=4, color=col, label=label)
        if len(sel) < 4 or fn is tau:
            continue
        fp, fv = tau_fits(A, sel, "eps0.9_" + ("cr" if fn is TAU_CR else "B"), fn)
        xx = np.linspace(x.min(), x.max(), 200)
        if fp.ok:
            ax.plot(xx, fp.p["A"] * (fp.p["xc"] - xx) ** -fp.p["g"], "--", color=col, lw=0.8)
        name = label.split(" ")[0]
        for f, what, key in ((fp, "power law: φ_c", "xc"), (fv, "VFT: φ_0", "x0")):
            extra = (f", γ {fmt(f.p['g'], f.error('g'))}" if key == "xc" else f", B {fmt(f.p['B'], f.error('B'))}")
            A.row(f"{name}(φ) {what}", "not in the paper", "not measured",
                  fmt(f.p[key], f.error(key), 4) + extra + f", χ²/dof {f.chi2_dof():.2g}", "—", "", sel, f.note)
    ax.set_yscale("log")
    ax.set_xlabel("φ")
    ax.set_ylabel("relaxation time")
    ax.legend(fontsize=8)
    ax.set_title(f"τ_α, cage-relative τ_α^CR and bond-breaking τ_B (ε = {EPS_MAIN:g}, a = {A_MAIN:g})")
    f = A.save(fig, "tau_local_phi.png")
    local = {p.phi for fn in (TAU_CR, TAU_B) for p in per[fn]}
    for phi in sorted(local):
        # each time from the largest N that measured it; a size other than the row's is named
        at = [(label.split(" ")[0], fn, next((p for p in per[fn] if p.phi == phi), None)) for label, fn, _, _ in MEASURES]
        at = [(name, fn, p) for name, fn, p in at if p is not None]
        n_row = at[0][2].N
        cells = [f"{name} {fmt(*p.mean(fn)[:2])}" + (f" (N {p.N})" if p.N != n_row else "") for name, fn, p in at]
        A.row(f"relaxation times at φ = {phi:g} (N {n_row})", "not in the paper", "not measured",
              ", ".join(cells), "—", f, list({id(p): p for _, _, p in at}.values()))


def local_n_results(A):
    """tau_alpha, tau_alpha^CR and tau_B against N at each density run at
    several N: does the cage-relative tau_alpha still depend on N?"""
    multi = points_by_phi_n(A, lambda p: measured(p, TAU_CR))
    if not multi:
        say("    no density with tau_alpha^CR at several N: no rows")
        return
    fig, axes = plt.subplots(1, len(multi), figsize=(5.5 * len(multi), 4.4), squeeze=False)
    for (phi, d), ax in zip(multi.items(), axes[0]):
        ns = sorted(d)
        used = [d[n] for n in ns]
        for label, fn, col, m in MEASURES:
            ms = [d[n].mean(fn) for n in ns]
            ok = [i for i, v in enumerate(ms) if v[3]]
            errorbar(ax, [ns[i] for i in ok], [ms[i][0] for i in ok], [point_error(ms[i]) for i in ok], fmt=m + "-",
                        color=col, label=label)
            if len(ok) < 2:
                continue
            # each N: the mean over seeds, the error the runs quote and the seeds' own spread
            cells = ", ".join(f"N {ns[i]}: {fmt(ms[i][0], measured_error(ms[i]))} (seeds {ms[i][3]}"
                              + (f" of {len(d[ns[i]].runs)}" if ms[i][3] < len(d[ns[i]].runs) else "")
                              + (f", spread ± {ms[i][2]:.2g})" if ms[i][3] > 1 else ")") for i in ok)
            # the finite-size table's rule and inputs: measured errors only, sizes where every seed has a
            # value, and not a size whose tau_alpha(t0) (of the same measure) moves over its production
            from .steady import unsteady   # (tau_B: the standard tau_alpha(t0))
            steady = {i: not unsteady(d[ns[i]], fn is TAU_CR) for i in ok}
            verdict = size_verdict([ns[i] for i in ok], [ms[i][0] for i in ok],
                                   [measured_error(ms[i]) if ms[i][3] == len(d[ns[i]].runs) and steady[i] else math.nan
                                    for i in ok])[0]
            cells += "".join(f"; N {ns[i]} not steady (out of the verdict)" for i in ok if not steady[i])
            A.row(f"{label.split(' ')[0]} against N at φ = {phi:g}", "not in the paper",
                  "not measured", cells, verdict, "", used)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("N")
        ax.set_ylabel("relaxation time")
        ax.set_title(f"φ = {phi:g}, ε = 0.9, a = 0.6")
        ax.legend(fontsize=8)
    A.save(fig, "tau_local_N.png")
