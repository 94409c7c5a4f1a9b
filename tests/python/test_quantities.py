"""dynhet.analysis.quantities: per-run values at tau_alpha carry the error
the run quotes at that lag (interpolated like the value), not the
interpolation's own error."""
import math

import numpy as np

from dynhet.analysis.quantities import chi4_at_tau


def run_with_chi4(err):
    lags = np.geomspace(0.1, 100.0, 25)
    chi4 = 3.0 + np.log(lags)                     # a line in ln t: no interpolation error
    grid_n = np.array([64.0, 256.0, 1024.0])      # sub-box particles; the proper sub-box is 256 (not the whole box)
    c = {"tau_alpha": 7.3, "tau_alpha_err": 0.1, "chi4_lag": lags, "chi4_N": grid_n,
         "chi4": np.tile(chi4, (3, 1)), "chi4_err": np.tile(err(lags), (3, 1))}
    return {"N": 1024, "cut": {0.6: c}}


def test_chi4_at_tau_alpha_takes_the_error_at_that_lag():
    v, e = chi4_at_tau(run_with_chi4(lambda t: np.full_like(t, 0.5)))
    assert math.isclose(v, 3.0 + math.log(7.3)) and math.isclose(e, 0.5)
    # an error growing as a line in ln t: its value at tau_alpha
    v, e = chi4_at_tau(run_with_chi4(lambda t: 0.1 + 0.05 * np.log(t)))
    assert math.isclose(e, 0.1 + 0.05 * math.log(7.3), rel_tol=1e-9)
