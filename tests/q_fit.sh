#!/usr/bin/env bash
# The fit of Q(t) = 1/((t/tau0)^beta + 1) (paper eq. 8) follows the data: a
# real run (N = 2048, phi = 0.74, eps = 0.9, 12 origins, through
# run_scene.sh), then, on its recorded Q(t): the node's beta and tau0 equal
# an independent Gauss-Newton fit over the stated range (0.1 <= Q <= 0.7)
# to 1e-6; every residual in the range lies within 3 standard errors of
# Q (their rms within 2); the fit over the range shifted by one lag either
# way moves beta and tau0 by less than 8%: the range is a systematic error
# of its own (one lag earlier takes in more of Q's curvature and raises
# beta: by 0.9 to 4.4 jackknife errors, 1-5%, over seeds 1-6 of this scene
# with both the engine before and after its kick lists; "less than
# twice the errors" held for 7 of 12 of those runs, so it was no property);
# those errors exist and the tau_alpha and D errors too. Runs in a private
# network namespace (run_scene.sh).
set -euo pipefail
root=$1 build=$2
export BUILD_DIR=$build
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cat >"$tmp/q.toml" <<TOML
[system]
n_particles = 2048
packing_fraction = 0.74
restitution = 0.9
seed = 3
[run]
equilibration_time = 50.0
[schedule]
origins = 12
origin_spacing = 5.0
lag_min = 0.05
lag_max = 20.0
lags_per_decade = 8
[observables]
compute = ["overlap", "msd"]
cutoff_a = [0.6]
TOML
bash "$root/launch_scripts/run_scene.sh" "$tmp/q.toml" --out "$tmp/out" --no-build >"$tmp/run.log" 2>&1 ||
  { tail -20 "$tmp/run.log"; exit 1; }
/usr/bin/python3 - "$tmp/out/run.h5" <<'PY'
import sys
import h5py
import numpy as np

f = h5py.File(sys.argv[1], "r")
g = f["observables/overlap/a0.6"]
t, q, e = g["lag_time"][()], g["q/value"][-1], g["q_err/value"][-1]
beta, tau0 = g["beta/value"][-1], g["tau0/value"][-1]
beta_err, tau0_err = g["beta_err/value"][-1], g["tau0_err/value"][-1]
fail = 0


def check(ok, what):
    global fail
    print(("ok   " if ok else "FAIL ") + what)
    fail |= not ok


def fit(sel):
    """Least squares in Q of eq. (8) by Gauss-Newton from the linearised fit."""
    x, y = np.log(t[sel]), np.log(1 / q[sel] - 1)
    b, c = np.polyfit(x, y, 1)
    p = np.array([b, -c / b])
    for _ in range(100):
        u = (t[sel] / np.exp(p[1])) ** p[0]
        m = 1 / (u + 1)
        jac = np.stack([-m * m * u * np.log(t[sel] / np.exp(p[1])), m * m * u * p[0]], 1)
        p = p + np.linalg.lstsq(jac, q[sel] - m, rcond=None)[0]
    return p[0], np.exp(p[1])


idx = np.flatnonzero((q >= 0.1) & (q <= 0.7))
check(len(idx) >= 5, f"{len(idx)} lags in 0.1 <= Q <= 0.7")
sel = np.zeros(len(t), bool)
sel[idx] = True
b, t0 = fit(sel)
check(abs(b - beta) < 1e-6 * beta and abs(t0 - tau0) < 1e-6 * tau0,
      f"the node's fit (beta {beta:.6f}, tau0 {tau0:.6f}) equals an independent one ({b:.6f}, {t0:.6f})")
res = (q - 1 / ((t / tau0) ** beta + 1)) / e
r = res[sel]
check(np.all(np.abs(r) < 3) and np.sqrt(np.mean(r * r)) < 2,
      f"residuals over the range within the errors of Q: {np.round(r, 2).tolist()}")
check(np.isfinite(beta_err) and np.isfinite(tau0_err) and 0 < beta_err < 0.2 * beta and 0 < tau0_err < 0.2 * tau0,
      f"errors from the jackknife over origin blocks: beta {beta:.4f} +- {beta_err:.4f}, tau0 {tau0:.4f} +- {tau0_err:.4f}")
for shift in (-1, 1):
    if not (0 <= idx.min() + shift and idx.max() + shift < len(t)):
        print(f"note range shifted by {shift:+d} lag: beyond the lags, not tried")
        continue
    s = np.zeros(len(t), bool)
    s[idx + shift] = True
    b2, t2 = fit(s)
    check(abs(b2 - beta) < 0.08 * beta and abs(t2 - tau0) < 0.08 * tau0,
          f"range shifted by {shift:+d} lag: beta {b2:.4f} ({100 * (b2 - beta) / beta:+.1f}%, "
          f"{(b2 - beta) / beta_err:+.2f} err), tau0 {t2:.4f} ({100 * (t2 - tau0) / tau0:+.1f}%, "
          f"{(t2 - tau0) / tau0_err:+.2f} err)")
for name, path in (("tau_alpha", "observables/overlap/a0.6/tau_alpha"), ("D", "observables/msd/diffusion")):
    v, ve = f[path + "/value"][-1], f[path + "_err/value"][-1]
    check(np.isfinite(v) and np.isfinite(ve) and 0 < ve < 0.3 * abs(v), f"{name} = {v:.5g} +- {ve:.2g}")
sys.exit(fail)
PY
