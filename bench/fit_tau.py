#!/usr/bin/python3
"""Fits of tau_alpha(phi) from bench/tau_scan.py results: the paper's inverse
power law tau = A (phi_c - phi)^-gamma and its exponential (VFT) form
tau = tau_inf exp[B / (phi_0 - phi)], each fitted to ln tau_alpha with the
runs' jackknife errors. The divergence point is profiled on a fine grid
(the other two parameters are then a linear weighted least-squares fit);
its error is where chi^2 rises by max(1, chi^2/dof) (the errors scaled up
when the fit is worse than the error bars say), and the other parameters'
errors are their linear errors, so scaled, widened by their spread over that
interval. The better fit is the one with the smaller chi^2 (both have
three parameters).

Usage: bench/fit_tau.py DIR [--plot tau.png] [--phi-min 0.0]
DIR holds <pairs>_eps<eps>/phi*/result.toml; prints a markdown table per
restitution and the fits.
"""
import argparse
import glob
import math
import os
import sys

import numpy as np

from tau_scan import read_result


def load(d):
    sets = {}
    for path in sorted(glob.glob(os.path.join(d, "*_eps*/phi*/result.toml"))):
        r = read_result(path)
        if r.get("accepted") != "true":
            continue
        key = (r["pairs"], float(r["eps"]))
        sets.setdefault(key, []).append(
            (float(r["phi"]), float(r["tau_alpha"]), float(r["tau_alpha_err"]), float(r["temperature"]),
             float(r["guess"])))
    return {k: np.array(sorted(v)) for k, v in sets.items()}


def profile_fit(phi, tau, err, kind):
    """Returns dict with the divergence point, exponent/B, amplitude, errors, chi2, dof."""
    y = np.log(tau)
    s = np.maximum(err / tau, 1e-4)  # error of ln tau
    w = 1 / s**2
    top = phi.max()
    grid = top + np.concatenate([np.geomspace(1e-4, 0.5, 4000)])
    best = None
    rows = []
    for pc in grid:
        x = -np.log(pc - phi) if kind == "power" else 1 / (pc - phi)
        X = np.vstack([np.ones_like(x), x]).T
        A = X.T @ (w[:, None] * X)
        b = X.T @ (w * y)
        try:
            coef = np.linalg.solve(A, b)
        except np.linalg.LinAlgError:
            continue
        chi2 = float(np.sum(w * (y - X @ coef) ** 2))
        cov = np.linalg.inv(A)
        rows.append((pc, chi2, coef, cov))
        if best is None or chi2 < best[1]:
            best = rows[-1]
    pc, chi2, coef, cov = best
    dof = len(phi) - 3
    scale = max(1.0, chi2 / dof) if dof > 0 else 1.0
    inside = [r for r in rows if r[1] <= chi2 + scale]
    pcs = [r[0] for r in inside]
    slopes = [r[2][1] for r in inside]
    amps = [r[2][0] for r in inside]
    slope_err = math.hypot(math.sqrt(cov[1, 1] * scale), (max(slopes) - min(slopes)) / 2)
    amp_err = math.hypot(math.sqrt(cov[0, 0] * scale), (max(amps) - min(amps)) / 2)
    at_edge = pc >= grid[-2]
    return dict(pc=pc, pc_lo=min(pcs), pc_hi=max(pcs), slope=coef[1], slope_err=slope_err, amp=coef[0],
                amp_err=amp_err, chi2=chi2, dof=dof, at_edge=at_edge)


def model(kind, f, phi):
    x = -np.log(f["pc"] - phi) if kind == "power" else 1 / (f["pc"] - phi)
    return np.exp(f["amp"] + f["slope"] * x)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("dir")
    p.add_argument("--plot")
    p.add_argument("--phi-min", type=float, default=0.0, help="fit only points at phi >= this")
    a = p.parse_args()
    sets = load(a.dir)
    if not sets:
        print(f"fit_tau: no accepted results under {a.dir}", file=sys.stderr)
        return 1
    fits = {}
    for eps in sorted({k[1] for k in sets}, reverse=True):
        rules = sorted(k[0] for k in sets if k[1] == eps)
        phis = sorted({row[0] for r in rules for row in sets[(r, eps)]})
        print(f"\n### eps = {eps:g}\n")
        print("| phi | " + " | ".join(f"tau_alpha ({r}) | T ({r})" for r in rules) + " |")
        print("|---|" + "---|---|" * len(rules))
        for ph in phis:
            cells = []
            for r in rules:
                row = [x for x in sets[(r, eps)] if abs(x[0] - ph) < 1e-9]
                cells += [f"{row[0][1]:.4g} +- {row[0][2]:.2g}", f"{row[0][3]:.3f}"] if row else ["-", "-"]
            print(f"| {ph:g} | " + " | ".join(cells) + " |")
        print()
        for r in rules:
            d = sets[(r, eps)]
            d = d[d[:, 0] >= a.phi_min]
            if len(d) < 4:
                print(f"- {r}: {len(d)} points, too few to fit three parameters")
                continue
            for kind in ("power", "vft"):
                f = profile_fit(d[:, 0], d[:, 1], d[:, 2], kind)
                fits[(r, eps, kind)] = f
                edge = " (at the edge of the grid: no divergence found)" if f["at_edge"] else ""
                if kind == "power":
                    print(f"- {r}, power law: phi_c = {f['pc']:.4f} [{f['pc_lo']:.4f}, {f['pc_hi']:.4f}], "
                          f"gamma = {f['slope']:.3g} +- {f['slope_err']:.2g}, chi2/dof = {f['chi2']:.1f}/{f['dof']}"
                          f" over phi {d[0, 0]:g}-{d[-1, 0]:g}{edge}")
                else:
                    print(f"- {r}, VFT: phi_0 = {f['pc']:.4f} [{f['pc_lo']:.4f}, {f['pc_hi']:.4f}], "
                          f"B = {f['slope']:.3g} +- {f['slope_err']:.2g}, chi2/dof = {f['chi2']:.1f}/{f['dof']}"
                          f" over phi {d[0, 0]:g}-{d[-1, 0]:g}{edge}")
            pw, vf = fits[(r, eps, "power")], fits[(r, eps, "vft")]
            print(f"  better (smaller chi2, same number of parameters): {'VFT' if vf['chi2'] < pw['chi2'] else 'power law'}")
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        epss = sorted({k[1] for k in sets}, reverse=True)
        fig, axes = plt.subplots(1, len(epss), figsize=(5 * len(epss), 4.2), squeeze=False)
        for ax, eps in zip(axes[0], epss):
            for r, color in (("neighbours", "C0"), ("any", "C3")):
                if (r, eps) not in sets:
                    continue
                d = sets[(r, eps)]
                ax.errorbar(d[:, 0], d[:, 1], d[:, 2], fmt="o", color=color, ms=4, label=f"pairs: {r}")
                for kind, ls in (("power", "--"), ("vft", "-")):
                    if (r, eps, kind) in fits:
                        f = fits[(r, eps, kind)]
                        x = np.linspace(d[0, 0], min(d[-1, 0] + 0.005, f["pc"] - 1e-4), 200)
                        ax.plot(x, model(kind, f, x), ls, color=color, lw=1,
                                label=f"{'power' if kind == 'power' else 'VFT'}: "
                                      f"{'phi_c' if kind == 'power' else 'phi_0'}={f['pc']:.3f}")
            ax.set_yscale("log")
            ax.set_xlabel("packing fraction phi")
            ax.set_ylabel("tau_alpha (a = 0.6)")
            ax.set_title(f"eps = {eps:g}")
            ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(a.plot, dpi=110)
        print(f"\nfit_tau: wrote {a.plot}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
