"""The rows of the finite-size report (finite_size.py): each quantity's
per-run function (standard and cage-relative), the points its rows take
(tau_B's may come from another study), and what a cell without a value says
(tau_B beyond the lags, as a bound; xi and chi0 not resolved, and why)."""
import math

import numpy as np

from .config import A_MAIN, EPS_MAIN
from .quantities import (MIN_SHELLS, PER_RUN, XI_MIN, chi0_at_tau, kappa_of, n_star, shells_below, whole_box_s4,
                         xi_of_cut)
from .runs import blocks_span
from ..fits import interp_ln_t, slope_with_error

# chi4^P (the peak of chi4(t)) per sub-box size: a run's grid counts for a
# size when its <N_r> is within a factor 1.6 of it and is not the whole box.
SUBBOX_SIZES = (32, 128, 512, 2048, 8192, 32768)




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


def chi4p_grid(size, cr=False):
    """chi4^P of the run's grid of exactly `size` particles per sub-box
    (rounded; the whole box too), as a per-run function for Point.mean
    (the cage-relative one with cr): the points of fig. chi4P(a); NaN where
    the run has no such grid or its peak is not interior."""
    def fn(r):
        c = cutx(r, cr)
        for n, peak, err, inside in zip(c["chi4_N"], c["chi4_peak"], c["chi4_peak_err"], c["tau4_interior"]):
            if round(float(n)) == size:
                return (peak, err) if inside else (math.nan, math.nan)
        return math.nan, math.nan
    return fn


def xi_shells(r, cr=False):
    """(xi, error, shells): the whole box's OZ xi at tau_alpha (the
    reproduction's xi: quantities.xi_of_cut) and how many q shells lie below
    q xi = 1; xi is NaN with fewer than MIN_SHELLS shells (not resolved at
    this N), below XI_MIN, beyond the box or outside the lags."""
    c = cutx(r, cr)
    return xi_of_cut(c, c["tau_alpha"])


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


def production_change(r, cr=False):
    """How far tau_alpha(t0) moves over the run's production, in per cent of
    tau_alpha: the line through tau_alpha(t0)/tau_alpha against t0/tau_alpha
    (fits.slope_with_error, the origins' scatter about it) from the first
    origin to the last; 0 within its error in a steady state (a run that
    still relaxes after its equilibration moves; docs/analysis.md, "The
    longest waves", for what the box-scale flows do and do not do)."""
    c = cutx(r, cr)
    t0, tt, tm = np.asarray(c["t0"], float), np.asarray(c["tau_t0"], float), float(c["tau_alpha"])
    m = np.isfinite(tt)
    if m.sum() < 3 or not tm > 0:
        return math.nan, math.nan
    b, e, _ = slope_with_error(t0[m] / tm, tt[m] / tm)
    span = (t0[m].max() - t0[m].min()) / tm
    return 100.0 * b * span, 100.0 * e * span


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
    """Per density, where C_B is compared across N: the longest lag that
    every run of it (at every N) reached and at which every run's origin
    blocks span it (blocks_span), so that every size, one seed too, has an
    error there; the longest lag every run reached where no lag
    has that."""
    out = []
    for phi, d in multi.items():
        runs = [r for p in d.values() for r in p.runs if len(r.get("c_b_lag", ()))]
        if not runs:
            continue
        reach = min(float(r["c_b_lag"][-1]) for r in runs)
        lags = sorted({float(t) for r in runs for t in r["c_b_lag"] if float(t) <= reach}, reverse=True)
        t = next((t for t in lags if all(blocks_span(t, r.get("schedule")) for r in runs)), reach)
        out.append((round(float(phi), 6), t))
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
              True, False),
             ("τ_α(t0): change over the production, % (0 when steady)", "tau_t0_change", production_change, True,
              False),
             # D grows with L in two dimensions (the long-wavelength motion): the
             # fits of D against tau_alpha over several box sizes carry it
             ("D (the MSD's long-time slope / 4)", "diffusion", lambda r, cr=False: (r["D_cr"], r["D_cr_err"]) if cr
              else (r["D"], r["D_err"]), True, True)]


QUANTITIES = TAU_ROWS + CHI4P_ROWS + REST_ROWS


def quantities(multi, multi_cr=None):
    """Every row of the report: QUANTITIES and C_B at each density's common
    last lag (bond breaking measured where tau_B lies beyond the lags); kappa
    over each density's common window of cluster sizes (kappa_windows; the
    cage-relative window from multi_cr, the cage-relative rows' points)."""
    cb = [("C_B at the longest common lag with an error (bond breaking)", "c_b", c_b_at(c_b_times(multi)), False, False)]
    kw = kappa_windows(multi, multi_cr)
    rest = [(name, slug, kappa_common(kw), c, lg) if slug == "kappa" else (name, slug, fn, c, lg)
            for name, slug, fn, c, lg in REST_ROWS]
    return TAU_ROWS + cb + CHI4P_ROWS + rest


def kappa_windows(multi, multi_cr=None):
    """{(phi, cr): N*_min}: per density and measure the smallest cutoff size
    N* = <N_c^2>/<N_c> over every run at every N (the cage-relative one over
    multi_cr's runs, where given), the common upper end of the kappa fits
    (3 <= N_c <= N*_min), so that every N fits the same cluster sizes: each
    run's own N* grows with the box where the box cuts the largest clusters
    off, and so would the window. A run whose own window holds fewer than 3
    bins with data (it could fit no kappa itself) does not narrow the
    others'."""
    out = {}
    for cr, src in ((False, multi), (True, multi if multi_cr is None else multi_cr)):
        for phi, d in src.items():
            vals = []
            for p in d.values():
                for r in p.runs:
                    try:
                        c = cutx(r, cr)
                        v = n_star(dict(r, cut=r["cut_cr"]) if cr else r)[0]
                        n, pp, pe = (np.asarray(c[k], float) for k in ("cl_size", "cl_p_slow", "cl_p_slow_err"))
                    except (KeyError, TypeError, ValueError):
                        continue
                    bins = np.isfinite(pp) & (pp > 0) & np.isfinite(pe) & (pe > 0) & (n >= 3) & (n <= v)
                    if np.isfinite(v) and bins.sum() >= 3:
                        vals.append(v)
            if vals:
                out[(round(float(phi), 6), cr)] = min(vals)
    return out


def kappa_common(windows):
    """kappa_of over the density's common window (kappa_windows); NaN where it has none."""
    def fn(r, cr=False):
        hi = windows.get((round(float(r["packing_fraction"]), 6), cr))
        if hi is None:
            return math.nan, math.nan
        return kappa_of(dict(r, cut=r["cut_cr"]) if cr else r, hi=hi)
    return fn


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
    reached", "τ_α beyond the S4 lags", "no OZ fit" (the S4 node refused
    its fit at a lag around tau_alpha: xi beyond the box, below the q range,
    or its jackknife error not below xi), "ξ < 0.3" (not determined), "ξ
    beyond the box", "not resolved" (fewer than MIN_SHELLS q shells below
    q xi = 1); None where it has one, or no S4. The xi judged is the one
    the cell would show (quantities.xi_of_cut)."""
    try:
        c = cutx(r, cr)
        if not len(c.get("xi_t", ())):
            return None
        t = c["tau_alpha"]
        if not np.isfinite(t):
            return "τ_α not reached"
        lag = np.asarray(c["s4_lag"], float)
        if not lag[0] <= t <= lag[-1]:
            return "τ_α beyond the S4 lags"
        g = whole_box_s4(c)
        raw, _ = interp_ln_t(lag, c["xi_t"][:, g], t)   # the node's xi, before XI_MIN and the box
        if not np.isfinite(raw):
            return "no OZ fit"
        xi, _, _ = xi_of_cut(c, t)
        resolved = shells_below(c, g, raw) >= MIN_SHELLS
        if slug == "chi0":   # the q -> 0 extrapolation of the same fit: as resolved as its xi
            return None if resolved or raw < XI_MIN else "not resolved"
        if np.isfinite(xi):
            return None
        if raw < XI_MIN:
            return f"ξ < {XI_MIN:g}"
        off = int(np.sum(c["s4_nshells"][:g]))
        q = np.asarray(c["s4_q"][off:off + int(c["s4_nshells"][g])])
        if raw > 2 * math.pi / q[q > 0].min():
            return "ξ beyond the box"
        return "not resolved" if not resolved else "ξ < 0.3 or beyond the box at a lag around τ_α"
    except (KeyError, TypeError, IndexError, ValueError):
        return None


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
    from .size import held_sizes   # the rule of every finite-size row: no size whose runs did not all finish
    held = held_sizes(A)
    out = {}
    for phi, d in multi.items():
        dd = dict(d)
        for p in list(A.points.values()) + list(A.extra.values()):
            if p.phi != phi or p.pairs != "neighbours" or abs(p.eps - EPS_MAIN) > 1e-9 or not c_b_reach(p):
                continue
            if held(p):
                continue
            q = dd.get(p.N)
            if q is None or (c_b_reach(p), len(p.runs)) > (c_b_reach(q), len(q.runs)):
                dd[p.N] = p
        out[phi] = dd
    return out


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
