"""How a number is stated and judged against the paper's: formats, verdicts, fits that cannot be judged, range scans."""
import math

import numpy as np

from .. import fits as sf
from .points import fit_series


def fmt(v, e=math.nan, digits=3):
    if not np.isfinite(v):
        return "not determined"
    if not np.isfinite(e):
        return f"{v:.{digits}g}"
    return f"{v:.{digits}g} ± {e:.2g}"


def verdict(v, e, paper):
    """Agreement with the paper's number: within 2 of our standard errors."""
    if not (np.isfinite(v) and np.isfinite(e) and e > 0):
        return "no error: not judged" if np.isfinite(v) else "not determined"
    z = abs(v - paper) / e
    return f"{'agrees' if z <= 2 else 'differs'} ({z:.1f} σ)"


def fit_verdict(f, name, paper, transform=lambda v: v):
    """verdict() for a fit's parameter; a fit that did not resolve its singular
    point, whose chi2 is improbable, or whose singular point sits on the edge
    of the data (sf.cannot_judge) says so instead of a sigma."""
    if not f.ok:
        return "not determined"
    if not f.determined:
        return "not determined (no divergence resolved)"
    singular = {"critical": "xc", "critical_joint": "xc", "vft": "x0"}.get(f.form)
    if singular is not None and f.err.get(singular) == 0.0:
        singular = None  # held fixed
    why = sf.cannot_judge(f, singular)
    if why:
        return f"not judged: {why}"
    if f.dof <= 0:
        return f"not judged: {f.n} points for {f.n - f.dof} parameters (no degree of freedom left to test the form)"
    v, e = transform(f.p[name]), f.error(name)
    if np.isfinite(e) and np.isfinite(v) and e > abs(v):
        return f"not judged: its error exceeds its value (the points do not determine it)"
    if np.isfinite(e) and paper != 0 and e > abs(paper) and abs(v - paper) <= 2 * e:
        # within 2 errors of the paper then says nothing: the same error would "agree" with 0 or twice it
        # (a value beyond 2 such errors still differs)
        return "not judged: its error exceeds the paper's value (the comparison could not tell it from 0)"
    return verdict(v, e, paper)


def fixed_xc_row(A, key, item, sec, paper, fn, pts, joint, fig):
    """A critical fit y = A (phi_c - phi)^-g with phi_c held at the joint
    fit's (a free phi_c that sits on the edge of the
    data decides the exponent; the same exponent with the shared phi_c is
    the comparison that can be judged). phi_c's own error is not carried."""
    xc = joint.p["xc"] if joint is not None and joint.ok else math.nan
    fx = A.fit(key, fit_series(pts, fn, sf.critical_fixed, xc=xc))
    num = paper.lstrip("≈ ")
    judged = num[:1].isdigit()
    v = fit_verdict(fx, "g", float(num)) if judged else "—"
    # an exponent at a phi_c that the table itself does not trust is no judgement either
    # (the joint fit's own verdict on phi_c, as its row gives it: not judged, or not determined)
    jv = fit_verdict(joint, "xc", 0.82) if judged and joint is not None and joint.ok else ""
    if jv.startswith("not") and not v.startswith(("not judged", "not determined")):
        kind, _, why = jv.partition(": ")
        v = f"not judged: its φ_c is the joint fit's, which is {kind}" + (f" ({why})" if why else "")
    A.row(item + (f" (φ_c held at the joint fit's {xc:.4f})" if np.isfinite(xc) else " (φ_c of the joint fit: none)"),
          sec, paper, fmt(fx.p["g"], fx.error("g")), v, fig, pts, fx.note)
    return fx


def range_scan(fits, name, label):
    """How a fitted parameter moves with the range: `fits` {bound: Fit}.
    Returns (note, systematic error = half the spread of the determined
    values)."""
    vals = {b: f.p[name] for b, f in fits.items() if f.ok}
    if len(vals) < 2:
        return f"scan of {label}: fewer than 2 ranges fit", math.nan
    v = np.array(list(vals.values()))
    syst = float((v.max() - v.min()) / 2)
    return (f"scan of {label}: " + ", ".join(f"{b:g}: {x:.3g}" for b, x in vals.items())
            + f" (systematic ± {syst:.2g})"), syst
