"""The two kick-pair rules side by side."""
import math

import matplotlib.pyplot as plt

from .. import fits as sf
from .config import EPS_MAIN, XI_MIN_DF
from .points import fit_series, series_arrays
from .quantities import chi4_at_tau, cut, tau, xi_at_tau
from .verdicts import fmt
from .overlap import better, tau_fits
from .plotting import errorbar


def driving_results(A):
    """The eps = 0.9 series under both kick-pair rules, side by side."""
    rules = [r for r in ("neighbours", "any") if A.series(pairs=r)]
    n_common = A.common_size([(r, EPS_MAIN) for r in rules])   # both rules at one box size
    out = {}
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for rule, col in zip(rules, ("C0", "C3")):
        pts = A.series(pairs=rule, N=n_common)
        fp, fv = tau_fits(A, pts, f"{rule}")
        x, y, e = series_arrays(pts, tau)
        errorbar(ax, x, y, e, fmt="o", color=col, label=f"pairs = {rule}")
        res = {"fp": fp, "fv": fv, "pts": pts}
        if all("s4_N" in cut(r) for p in pts for r in p.runs):
            res["fc"] = A.fit(f"chi4_phi_{rule}", fit_series(pts, chi4_at_tau, sf.critical))
            res["fx"] = A.fit(f"xi_phi_{rule}", fit_series(pts, xi_at_tau, sf.critical))
            res["fd"] = A.fit(f"chi4_xi_{rule}", fit_series(pts, chi4_at_tau, sf.power, xrun=xi_at_tau,
                                                             x_range=(XI_MIN_DF, math.inf)))
        dfs = lambda r: (cut(r)["cl_slow_d_f"], cut(r)["cl_slow_d_f_err"])
        res["df_lo"], res["df_hi"] = (pts[0].mean(dfs), pts[-1].mean(dfs)) if pts else (None, None)
        out[rule] = res
    ax.set_yscale("log")
    ax.set_xlabel("φ")
    ax.set_ylabel("τ_α (ε = 0.9)")
    ax.legend()
    ax.set_title("the driving rule: which kick pairs")
    f = A.save(fig, "driving_rules.png")
    A.driving = (out, f)
    A.driving_n = n_common


def param_cell(f_, k, digits=3):
    """A fit parameter's cell: a parameter whose error exceeds its value (or
    that has none) says nothing (docs/analysis.md) and is so marked."""
    v, e = f_.p[k], f_.error(k)
    if not math.isfinite(v):
        return "not determined"
    return fmt(v, e, digits) if abs(e) <= abs(v) else f"not determined ({fmt(v, e, digits)})"


def driving_rows(A):
    out, f = A.driving
    if len(out) < 2:
        A.row("both kick-pair rules side by side (ε = 0.9)", "2 (driving)", "—",
              f"only pairs = {', '.join(out) or 'none'} in this study", "not run", f, [])
        return
    param = param_cell
    def cell(res, what):
        if what == "phi_c":
            return param(res["fp"], "xc", 4)
        if what == "gamma":
            return param(res["fp"], "g")
        if what == "phi_0":
            return param(res["fv"], "x0", 4)
        if what == "B":
            return param(res["fv"], "B")
        if what == "better":
            return better(res["fp"], res["fv"]).split(" (")[0]
        if what in ("fc", "fx", "fd"):
            f_ = res.get(what)
            return param(f_, "s" if what == "fd" else "g") if f_ is not None else "not determined"
        if what == "tau_range":
            t = [p.mean(tau)[0] for p in res["pts"]]
            return f"{min(t):.3g} to {max(t):.3g} (φ {res['pts'][0].phi:g}-{res['pts'][-1].phi:g})" if t else "—"
        if what in ("df_lo", "df_hi"):
            m = res[what]
            return fmt(m[0], m[1]) if m else "—"
    A.driving_table = []
    for what, lab, paper in (("tau_range", "τ_α range", "grows ~100-fold to φ = 0.805 (fig. Q-t)"),
                             ("phi_c", "τ_α power law φ_c", "0.82"), ("gamma", "τ_α power law γ", "—"),
                             ("phi_0", "τ_α VFT φ_0", "0.83"), ("B", "τ_α VFT B", "—"), ("better", "better form", "VFT"),
                             ("fc", "γχ (χ4(τ_α), own φ_c)", "2.5"), ("fx", "γξ (ξ(τ_α), own φ_c)", "1.6"),
                             ("fd", f"d_f' (χ4 ∝ ξ^d_f', ξ ≥ {XI_MIN_DF:g})", "1.6"), ("df_lo", "d_f slow, lowest φ", "1.65 (0.60)"),
                             ("df_hi", "d_f slow, highest φ", "1.91 (0.805)")):
        A.driving_table.append((lab, paper, cell(out["neighbours"], what), cell(out["any"], what)))
