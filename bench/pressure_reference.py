#!/usr/bin/python3
"""The pressure sim_node prints against high-precision published data.

Elastic, undriven, monodisperse hard disks in a square periodic box, N =
72, 224 and 870, phi = 0.65 to 0.70: sim_node runs each point (through
launch_scripts/netns.sh, so its frames stay in a private namespace) and
its own printed line "production: Z = ... +- ..." is compared with the
event-chain Monte Carlo pressures of B. Li, Y. Nishikawa, P. Hoellmer, L.
Carillo, A. C. Maggs and W. Krauth, "Hard-disk computer simulations - a
historic perspective", J. Chem. Phys. 157, 234111 (2022) (their data
synopsis, github.com/jellyfysh/HistoricDisks, DigitizedData/ThisWork.csv,
square boxes), given there as beta P (2 sigma)^2 with sigma the radius:
Z = beta P / rho = beta P (2 sigma)^2 pi / (4 phi).

Usage: bench/pressure_reference.py [--n 224,870] [--phi 0.67,0.68,0.69,0.70]
         [--time T] [--seeds K] [--build DIR] [--check SIGMAS]

--time is the production time per run (default 20000 time units, about
10-30 s per run at N = 224); --seeds runs K seeds per point and combines
them (the mean and its error from the quoted errors, and the seeds' own
spread); --check exits non-zero if any point differs from the reference by
more than SIGMAS combined standard errors (the test uses 3).
"""
import argparse
import math
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# beta P (2 sigma)^2 and its error, ECMC, square box (aspect ratio 1:1),
# periodic (Li et al. 2022, data synopsis).
REFERENCE = {
    72: {0.650: (6.901074, 0.000071), 0.660: (7.383221, 0.000087), 0.670: (7.85637, 0.00011),
         0.680: (8.23631, 0.00034), 0.690: (8.41814, 0.00038), 0.700: (8.55170, 0.00059)},
    224: {0.670: (7.979479, 0.000058), 0.680: (8.49105, 0.00019), 0.690: (8.83348, 0.00046),
          0.700: (8.6876, 0.0012)},
    870: {0.670: (7.986779, 0.000025), 0.680: (8.513249, 0.000037), 0.690: (8.969898, 0.000075),
          0.700: (9.12966, 0.00015)},
}


def reference_z(n, phi):
    bp, err = REFERENCE[n][round(phi, 3)]
    f = math.pi / (4 * phi)
    return bp * f, err * f


def scene(n, phi, seed, time):
    return f"""[system]
n_particles = {n}
packing_fraction = {phi}
restitution = 1.0
radius_ratio = 1.0
seed = {seed}
[driving]
enabled = false
[run]
equilibration_time = 200.0
production_time = {time}
[schedule]
origins = 1
lag_min = 1.0
lag_max = 10.0
lags_per_decade = 1
[observables]
compute = ["overlap"]
"""


Z_LINE = re.compile(r"production: Z = ([-\d.e+]+) \+- ([-\d.e+naif]+)")


def run_point(bin_, n, phi, seed, time, port):
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "p.toml")
        with open(path, "w") as f:
            f.write(scene(n, phi, seed, time))
        r = subprocess.run([os.path.join(ROOT, "launch_scripts/netns.sh"), os.path.join(bin_, "sim_node"), path,
                            "--lcm-url", f"udpm://239.255.76.67:{port}?ttl=0", "--unauthenticated"],
                           stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        m = Z_LINE.search(r.stderr)
        if r.returncode != 0 or not m:
            sys.exit(f"pressure_reference: sim_node failed at N={n} phi={phi} seed={seed}:\n{r.stderr[-2000:]}")
        return float(m.group(1)), float(m.group(2))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], epilog=__doc__.split("\n\n", 1)[1],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", default="224,870")
    ap.add_argument("--phi", default="0.67,0.68,0.69,0.70")
    ap.add_argument("--time", type=float, default=20000.0, help="production time per run")
    ap.add_argument("--seeds", type=int, default=1)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--port", type=int, default=7797)
    ap.add_argument("--check", type=float, default=0.0, help="fail beyond this many combined standard errors")
    a = ap.parse_args()
    bin_ = os.path.join(a.build, "bin")
    print("| N | phi | Z (sim_node) | +- (quoted) | seeds' spread / quoted | Z (Li et al. 2022) | +- "
          "| difference | in sigmas |")
    print("|---|---|---|---|---|---|---|---|---|")
    bad = []
    for n in [int(x) for x in a.n.split(",")]:
        for phi in [float(x) for x in a.phi.split(",")]:
            if round(phi, 3) not in REFERENCE.get(n, {}):
                sys.exit(f"pressure_reference: no reference value at N={n}, phi={phi}; there are: " +
                         ", ".join(f"N={k}: {sorted(v)}" for k, v in REFERENCE.items()))
            zs = [run_point(bin_, n, phi, s + 1, a.time, a.port) for s in range(a.seeds)]
            k = len(zs)
            z = sum(v for v, _ in zs) / k
            err = math.sqrt(sum(e * e for _, e in zs)) / k
            spread = "-"
            if k > 1:
                sd = math.sqrt(sum((v - z) ** 2 for v, _ in zs) / (k - 1))
                spread = f"{sd / (sum(e for _, e in zs) / k):.2f}"
            zr, er = reference_z(n, phi)
            sig = (z - zr) / math.hypot(err, er)
            print(f"| {n} | {phi:.3f} | {z:.5f} | {err:.5f} | {spread} | {zr:.5f} | {er:.5f} | {z - zr:+.5f} "
                  f"| {sig:+.2f} |", flush=True)
            if a.check > 0 and abs(sig) > a.check:
                bad.append(f"N={n} phi={phi}: Z = {z:.5f} +- {err:.5f}, reference {zr:.5f} +- {er:.5f} "
                           f"({sig:+.2f} sigma)")
    if bad:
        sys.exit("pressure_reference: beyond " + f"{a.check:g} sigma: " + "; ".join(bad))


if __name__ == "__main__":
    main()
