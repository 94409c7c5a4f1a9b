"""Whether a run was in a steady state over its production: the change of
tau_alpha(t0) from the first origin to the last (size_rows.production_change)
against 0, with the dof of its error (finite_size's tables and verdicts, the
reproduction's header, local_measures' rows)."""
import numpy as np

from .points import measured_error
from .size_rows import cutx, production_change
from .verdicts import fmt


Z_STEADY = 3.0   # a size is "not steady" beyond 3 errors: some 30 cells judged at 2 would flag one or two by chance
P_STEADY = 0.0027   # the same as a two-sided probability (3 sigma of a normal error)


def steady_limit(dof):
    """How many errors from 0 make a change "not steady": Z_STEADY for an
    error of known size; with the slopes' residual dof, the Student t
    quantile of the same probability (one run of 8 origins, 6 dof: 4.9; of
    4 origins, 2 dof: 19; three runs of 8, 18 dof: 3.5), since an error from the
    scatter of a few origins about a line is itself uncertain."""
    if dof is None or not dof > 0:
        return Z_STEADY
    from scipy.stats import t
    return float(t.ppf(1 - P_STEADY / 2, dof))


def change_dof(p, cr):
    """The dof of the error Point.mean gives a point's change over the
    production (production_change): where every run quotes one (its
    origins' scatter about the line, n - 2 dof), Welch-Satterthwaite over
    the runs, (sum e^2)^2 / sum (e^4 / (n - 2)), which is the sum for equal
    errors and less otherwise; where some run quotes none (fewer than 4
    origins, or origins closer than one tau_alpha), the seeds' spread:
    seeds - 1; None where neither."""
    errs, dofs = [], []
    for r in p.runs:
        try:
            v, e = production_change(r, cr)
            k = int(np.isfinite(np.asarray(cutx(r, cr)["tau_t0"], float)).sum()) - 2
        except (KeyError, TypeError, ValueError):
            continue
        if np.isfinite(v):
            errs.append(e)
            dofs.append(k)
    if not errs:
        return None
    if all(np.isfinite(e) and e > 0 for e in errs) and all(k > 0 for k in dofs):
        return sum(e * e for e in errs) ** 2 / sum(e ** 4 / k for e, k in zip(errs, dofs))
    return (len(errs) - 1) or None


MIN_DOF = 2   # below it the limit is no check: one dof puts it at 236 errors (two dof: 19, one run of 4 origins)


def unjudged_reason(m, whole, dof=None):
    """Why steady_off cannot judge a size (m, Point.mean's), or None where it
    can: no error (no value, no error, or not every seed has one), or an
    error of fewer than MIN_DOF dof (the spread of two seeds, where some
    run quotes none)."""
    if not (whole and np.isfinite(m[0]) and np.isfinite(measured_error(m))):
        return "no error"
    if dof is not None and dof < MIN_DOF:
        return f"{dof:.3g} dof: 3σ's probability would allow {steady_limit(dof):.0f} errors"
    return None


def steady_off(m, whole, dof=None):
    """Whether a size's change over the production (m, Point.mean's) lies
    beyond steady_limit(dof) errors from 0; None where it cannot be judged
    (unjudged_reason)."""
    if unjudged_reason(m, whole, dof) is not None:
        return None
    return abs(m[0]) > steady_limit(dof) * measured_error(m)


def unsteady(p, cr):
    """Whether point p's tau_alpha(t0) (cage-relative with cr) moves over the
    production beyond steady_limit (steady_off; False where it cannot be
    judged)."""
    m = p.mean(lambda r: production_change(r, cr))
    return bool(steady_off(m, m[3] == len(p.runs), change_dof(p, cr)))


def steady_verdict(ns, ms, whole, dofs=None):
    """tau_alpha(t0)'s change over the production against 0 at each size
    (every seed's value with an error): the sizes where it lies beyond
    steady_limit (3 sigma's probability, Student t with the slopes' dof)
    from 0 are "not steady"."""
    off, ok, unjudged = [], [], {}
    for n, m, w, k in zip(ns, ms, whole, dofs or [None] * len(ns)):
        if not np.isfinite(m[0]):
            continue
        why = unjudged_reason(m, w, k)
        if why is not None:
            unjudged.setdefault(why, []).append(n)
            continue
        (off if steady_off(m, w, k) else ok).append((n, m[0], measured_error(m)))
    tail = "".join(f"; not judged ({why}) at N = {', '.join(str(n) for n in sizes)}" for why, sizes in unjudged.items())
    if not off and not ok:
        return ("no verdict: " + tail[2:]) if tail else "no verdict: no size with every seed's value and an error"
    if not off:
        return ("steady: 0 within 3σ's probability at "
                + ("every N" if not unjudged else "N = " + ", ".join(str(n) for n, _, _ in ok)) + tail)
    return ("not steady at " + ", ".join(f"N = {n} ({fmt(v, e)} %)" for n, v, e in off)
            + ("; 0 within 3σ's probability at N = " + ", ".join(str(n) for n, _, _ in ok) if ok else "") + tail)
