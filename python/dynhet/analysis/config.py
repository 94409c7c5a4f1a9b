"""The study analysis' conventions: the paper's cutoff and restitution, the densities and ranges it names."""
import os

from ..scene import default

CONVENTIONS = """(docs/analysis.md, "Study analysis"):
- A point is (driving.pairs, restitution, packing fraction, N); its value is
  the mean over seeds, its error the standard error of that mean from the
  runs' own quoted errors, times the study's factor for that quantity
  (points.calibration: the seeds' spread over the quoted errors pooled over
  the study's points, where that ratio has at least 10 dof and lies more
  than 2 sigma above 1; a study with fewer dof takes the ratio pooled over
  every study analysed with it); where no run quotes an error, the seeds'
  standard error. The seeds' own spread is recorded beside it.
- Cross-run fits are weighted by those errors and quoted with the
  jackknife error over seeds (each seed left out of every point in turn);
  with fewer than 4 seeds at least the fit's own error, and where
  chi2/dof > 1 at least the fit's own error times sqrt(chi2/dof); their
  chi2/dof and range are recorded.
- "At tau_alpha" means at the run's own tau_alpha (a = 0.6, the overlap
  node's): chi4, S4, xi and chi0 are interpolated linearly in ln t between
  the two computed lags around it; the interpolation error (against a
  parabola through the three nearest lags) is recorded and added in
  quadrature. Clusters are the clusters node's at its own tau_alpha (the
  node interpolates between the lags around it, or takes the nearest lag
  where tau_alpha is not bracketed); P(dx) is taken at the lag nearest
  tau_alpha that the node used (the study schedules a lag at the pilot's
  tau_alpha); the ratio of the time used to tau_alpha is recorded.
- chi4(tau_alpha) is the largest proper sub-box's (the paper's chi4 comes
  from sub-boxes; the whole box of fixed N lacks the number fluctuations);
  xi is the whole box's OZ xi (the finest q).
"""

A_MAIN = default("observables", "cutoff_a")[0]  # the scene's, the paper's "unless stated otherwise"
EPS_MAIN = default("system", "restitution")  # the scene's, the paper's "unless stated otherwise"
XI_MIN_DF = 3.0      # d_f' (chi4 against xi) over xi >= 3 particle diameters
PHI_SNAP = (0.60, 0.78, 0.805)   # the paper's snapshot densities (nearest available are used)
PHI_AGE = (0.78, 0.805)          # the paper's ageing densities
PHI_PDX = (0.60, 0.72, 0.78)     # three densities for P(dx) (the paper's fig. 8a shows several)
PHI_INTERMEDIATE = (0.0, 0.77)   # D against tau_alpha: "not too close to dynamical arrest"
PHI_HIGH = (0.775, 1.0)          # ... "at the highest densities"
A_THREE = (0.6, 1.4, 3.0)        # the paper's fig. diff-a cutoffs


def say(*a):
    print(*a, flush=True)


def shown_path(d):
    """A study's directory as the documents name it: relative to the
    repository where it lies inside it (results/quick), so that a document's
    text does not depend on where it is written or which machine wrote it;
    else as given."""
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
    rel = os.path.relpath(os.path.abspath(d), root)
    return d if rel.startswith("..") else rel
