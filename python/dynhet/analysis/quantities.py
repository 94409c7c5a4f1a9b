"""Per-run quantities at tau_alpha: chi4, xi, chi0, S4, tau4, N*, kappa, and the OZ refit."""
import math

import numpy as np

from .. import fits as sf
from .config import A_MAIN


def cut(r, a=A_MAIN):
    return r["cut"][a]


def tau(r, a=A_MAIN):
    c = cut(r, a)
    return c["tau_alpha"], c["tau_alpha_err"]


# The sub-box of chi4(tau_alpha), tau4 and every fit across densities: one
# size at every N (the paper divides its box into sub-boxes of a chosen
# number of particles), 4096 / 9, the largest proper sub-box of the N = 4096
# box the reproduction was first made at. With --largest-n a series mixes
# N = 4096 with 65536 and 262144: "the largest grid below the whole box"
# would have been 455 particles at one density and 29127 at the next, and
# chi4 grows with the sub-box until it saturates (fig. chi4P).
CHI4_SUBBOX = 4096 / 9


def proper_subbox(c, N):
    """Index of the sub-box grid of chi4(tau_alpha): the one of about
    CHI4_SUBBOX particles (within a factor 1.6) where it is smaller than the
    whole box; else the largest grid smaller than the whole box (N < 4096:
    the size is not there), else the largest."""
    ns = np.asarray(c["chi4_N"], float)
    ok = np.where(ns < 0.999 * N)[0]
    if not len(ok):
        return int(np.argmax(ns))
    near = ok[np.argmin(np.abs(np.log(ns[ok] / CHI4_SUBBOX)))]
    if abs(math.log(ns[near] / CHI4_SUBBOX)) <= math.log(1.6):
        return int(near)
    return int(ok[np.argmax(ns[ok])])


def tau4_of(r, g):
    """tau4 of sub-box grid g with its error; NaN where the peak is not
    interior (the largest chi4 at the first or last lag: a bound, which
    scales with the lag window, not a peak)."""
    c = cut(r)
    if not c["tau4_interior"][g]:
        return math.nan, math.nan
    return c["tau4"][g], c["tau4_err"][g]


def interior_note(points, g_of):
    """How many points' runs have an interior tau4 peak (all of their seeds)."""
    ok = sum(all(cut(r)["tau4_interior"][g_of(r)] for r in p.runs) for p in points)
    return f"{ok} of {len(points)} points with an interior χ4 peak (the others left out)"


def whole_box_s4(c):
    return int(np.argmax(np.asarray(c["s4_N"], float)))


XI_MIN = 0.3   # below this OZ xi, S4 varies by less than 10% over q <= 1: not determined
MIN_SHELLS = 5  # an OZ xi (and its chi0) needs this many q shells below q xi = 1


def shells_below(c, g, xi):
    """How many q shells of S4 grid g lie below q xi = 1 (0 for xi not finite)."""
    if not np.isfinite(xi):
        return 0
    off = int(np.sum(c["s4_nshells"][:g]))
    q = np.asarray(c["s4_q"][off:off + int(c["s4_nshells"][g])])
    return int(np.sum((q > 0) & (q * xi <= 1.0)))


def oz_resolved(c, g, xi):
    """Whether the OZ fit of grid g with this xi rests on at least MIN_SHELLS
    q shells below q xi = 1: else neither its xi nor its chi0 (the q -> 0
    extrapolation of the same few shells) is taken ("not resolved at this N")."""
    return shells_below(c, g, xi) >= MIN_SHELLS


def chi4_at_tau(r, a=A_MAIN, g=None, own=False):
    """chi4 of cutoff a at tau_alpha of a = 0.6 (own: at cutoff a's own tau_alpha)."""
    c = cut(r, a)
    t = tau(r, a if own else A_MAIN)[0]
    if g is None:
        g = proper_subbox(c, r["N"])
    v, ie = sf.interp_ln_t(c["chi4_lag"], c["chi4"][g], t)
    e, _ = sf.interp_ln_t(c["chi4_lag"], c["chi4_err"][g], t)  # the error at t (not the error curve's own interpolation error)
    return v, math.hypot(e, ie if np.isfinite(ie) else 0.0)


def xi_at_tau(r, a=A_MAIN, own=False):
    """The whole box's OZ xi of cutoff a at tau_alpha (of a = 0.6, or own);
    NaN where it is below XI_MIN (S4 flat over the q range), longer than
    the box, or not resolved (fewer than MIN_SHELLS q shells below q xi = 1)."""
    return xi_of_cut(cut(r, a), tau(r, a if own else A_MAIN)[0])[:2]


def xi_of_cut(c, t):
    """(xi, error, shells) of a cut's whole-box S4 at time t (a tau_alpha):
    xi(t) interpolated in ln t between the lags around t (NaN outside the
    lags), its error the OZ fit's relative error at tau_alpha and the
    interpolation's in quadrature; NaN below XI_MIN or beyond the box, and
    with fewer than MIN_SHELLS shells below q xi = 1 (their count is
    returned either way: the finite-size table states it). The one xi of
    the reproduction's rows and of the finite-size table."""
    g = whole_box_s4(c)
    off = int(np.sum(c["s4_nshells"][:g]))
    q = c["s4_q"][off:off + int(c["s4_nshells"][g])]
    box = 2 * math.pi / q[q > 0].min()   # the box: no longer xi can be measured in it
    xi = c["xi_t"][:, g]
    xs = np.where((xi >= XI_MIN) & (xi <= box), xi, np.nan)
    v, ie = sf.interp_ln_t(c["s4_lag"], xs, t)
    shells = shells_below(c, g, v)
    if np.isfinite(v) and shells < MIN_SHELLS:
        return math.nan, math.nan, shells
    rel = c["s4_oz_xi_err"][g] / c["s4_oz_xi"][g] if np.isfinite(c["s4_oz_xi"][g]) and c["s4_oz_xi"][g] > 0 else math.nan
    return v, math.hypot(abs(v) * rel if np.isfinite(rel) else math.nan, ie if np.isfinite(ie) else 0.0), shells


def chi0_at_tau(r, a=A_MAIN, g=None):
    c = cut(r, a)
    t = tau(r)[0]
    if g is None:
        g = whole_box_s4(c)
    v, ie = sf.interp_ln_t(c["s4_lag"], c["chi0_t"][:, g], t)
    xi, _ = sf.interp_ln_t(c["s4_lag"], c["xi_t"][:, g], t)
    if np.isfinite(v) and np.isfinite(xi) and not oz_resolved(c, g, xi):
        return math.nan, math.nan
    rel = c["s4_oz_chi0_err"][g] / c["s4_oz_chi0"][g] if c["s4_oz_chi0"][g] > 0 else math.nan
    return v, math.hypot(abs(v) * rel if np.isfinite(rel) else math.nan, ie if np.isfinite(ie) else 0.0)


def s4_at_tau(r, a=A_MAIN, g=None):
    """(q, S4) of grid g (default the whole box) at tau_alpha, q = 0 left out."""
    c = cut(r, a)
    if g is None:
        g = whole_box_s4(c)
    off = int(np.sum(c["s4_nshells"][:g]))
    n = int(c["s4_nshells"][g])
    q = c["s4_q"][off:off + n]
    t = tau(r)[0]
    s = np.array([sf.interp_ln_t(c["s4_lag"], c["s4_t"][:, off + k], t)[0] for k in range(n)])
    m = q > 0
    return q[m], s[m]


def n_star(r, a=A_MAIN):
    """The slow-cluster cutoff size: <N_c^2>/<N_c> of P(N_c)."""
    c = cut(r, a)
    p, n, w = c["cl_p_slow"], c["cl_size"], c["cl_width"]
    m = np.isfinite(p)
    s1, s2 = np.sum((p * n * w)[m]), np.sum((p * n * n * w)[m])
    return (s2 / s1 if s1 > 0 else math.nan), math.nan


KAPPA_LO = (1.0, 3.0, 10.0)   # lower bounds of the kappa fit scanned (monomers in or out)


def kappa_of(r, lo=3.0, a=A_MAIN, hi=None):
    """kappa of slow clusters: P(N_c) ~ N_c^-kappa fitted to the bins with
    lo <= N_c <= N* (the run's cutoff size <N_c^2>/<N_c>: beyond it the
    scaling function cuts the power law off; hi in its place where given:
    the finite-size table's window common to every N of a density),
    weighted by the bins' errors;
    its error the fit's, times sqrt(chi2/dof) where the bins scatter more
    than their errors say (Fit.error: the Birge ratio); NaN with fewer than
    3 bins."""
    c = cut(r, a)
    if "cl_size" not in c:
        return math.nan, math.nan
    p, pe, n = c["cl_p_slow"], c["cl_p_slow_err"], c["cl_size"]
    ns = n_star(r, a)[0] if hi is None else hi
    m = np.isfinite(p) & (p > 0) & np.isfinite(pe) & (pe > 0) & (n >= lo) & (n <= ns)
    if m.sum() < 3:
        return math.nan, math.nan
    f = sf.power(n[m], p[m], pe[m])
    return (-f.p["s"], f.error("s")) if f.ok else (math.nan, math.nan)


def oz_fit(q, s, q_max):
    """S4 = chi0/(1 + (q xi)^2) over 0 < q <= q_max, relative residuals (as the node)."""
    from scipy.optimize import least_squares
    m = (q > 0) & (q <= q_max) & np.isfinite(s) & (s > 0)
    if m.sum() < 3:
        return math.nan, math.nan
    qq, ss = q[m], s[m]
    res = least_squares(lambda p: (p[0] / (1 + (qq * p[1]) ** 2) - ss) / ss, [ss[0] * 1.2, 2.0],
                        bounds=([0, 0], [np.inf, 1e4]))
    return float(res.x[0]), float(res.x[1])


# The per-run quantities by name, each run -> (value, error): what study.h5
# records per point and what Analysis.against_phi gives.
PER_RUN = {"tau_alpha": tau, "beta": lambda r: (cut(r)["beta"], cut(r)["beta_err"]),
           "tau0": lambda r: (cut(r)["tau0"], cut(r)["tau0_err"]), "diffusion": lambda r: (r["D"], r["D_err"]),
           "Z": lambda r: (r["Z"], r["Z_err"]), "chi4_tau_alpha": chi4_at_tau, "xi_tau_alpha": xi_at_tau,
           "chi0_tau_alpha": chi0_at_tau,
           "d_f_slow": lambda r: (cut(r)["cl_slow_d_f"], cut(r)["cl_slow_d_f_err"]),
           "d_f_fast": lambda r: (cut(r)["cl_fast_d_f"], cut(r)["cl_fast_d_f_err"]),
           "kappa_slow": kappa_of,
           "kappa_slow_node": lambda r: (cut(r)["cl_slow_kappa"], cut(r)["cl_slow_kappa_err"]),
           "n_star_slow": n_star,
           "cluster_lag_over_tau_alpha": lambda r: (cut(r)["cl_lag"] / cut(r)["tau_alpha"], math.nan),
           "s4_lag_over_tau_alpha": lambda r: (cut(r)["s4_t_s4"] / cut(r)["tau_alpha"], math.nan),
           "tau_alpha_cr": lambda r: (cut(r).get("tau_cr", math.nan), cut(r).get("tau_cr_err", math.nan)),
           "tau_b": lambda r: (r.get("tau_b", math.nan), r.get("tau_b_err", math.nan))}
