#!/usr/bin/python3
"""Checks a dynhet run file: the H5MD layout, the scene, the frames, no
loss, and the recorded Q(t) and tau_alpha, chi4, the MSD (with the
instantaneous fastest and slowest subsets), P(dx, t) with its fits, the
clusters and S4(q,t) against brute-force recomputations from the recorded
frames.

Usage: check_run.py RUN.h5 SCENE.toml
"""
import math
import sys
import tomllib
from collections import deque

import h5py
import numpy as np

failures = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        failures.append(what)


def crossing_time(t, q, level):
    """Same definition as the node: first downward crossing, linear in ln t."""
    prev = None
    for j in range(len(q)):
        if math.isnan(q[j]):
            continue
        if q[j] < level:
            if prev is None:
                return math.nan
            f = (q[prev] - level) / (q[prev] - q[j])
            return math.exp(math.log(t[prev]) + f * (math.log(t[j]) - math.log(t[prev])))
        prev = j
    return math.nan


def bracket(t, tau):
    """The node's bracket (lag_interpolation.hpp): adjacent lags lo, hi = lo + 1 with
    t[lo] <= tau <= t[hi], w = ln(tau/t_lo)/ln(t_hi/t_lo), and the third lag (the
    neighbour on tau's side, else the other); None outside the lags."""
    n = len(t)
    if not (math.isfinite(tau) and t[0] <= tau <= t[-1]) or n < 2:
        return None
    lo = 0
    while lo + 2 < n and t[lo + 1] <= tau:
        lo += 1
    hi = lo + 1
    w = math.log(tau / t[lo]) / math.log(t[hi] / t[lo])
    below, above = (lo - 1 if lo > 0 else None), (hi + 1 if hi + 1 < n else None)
    third = (below if below is not None else above) if w < 0.5 else (above if above is not None else below)
    return lo, hi, w, third


def quad_minus_lin(t, tau, lo, hi, third, v_lo, v_hi, v_3):
    """The quadratic in ln t through the three lags minus the linear interpolation, at tau."""
    x = np.log([t[lo], t[hi], t[third], tau])
    c = np.polyfit(x[:3], np.array([v_lo, v_hi, v_3], dtype=float), 2)
    return np.polyval(c, x[3]) - (v_lo + (x[3] - x[0]) / (x[1] - x[0]) * (v_hi - v_lo))


def origin_mean(x):
    """Mean over origins (axis 0) and its standard error, as the node's BlockAverage."""
    return x.mean(axis=0), x.std(axis=0, ddof=1) / math.sqrt(x.shape[0])


def check_msd_extremes(g, d2, species, scene):
    """The instantaneous fastest and slowest subsets: at every (origin, lag) the particles of the set
    sorted by their own |dr|^2 over that lag, the top and bottom k = round(fraction * set size)."""
    fractions = {"all": 0.1, "small": 0.2} | {k[9:]: v for k, v in scene.get("msd", {}).items()}
    check(float(g.attrs["fraction_all"]) == fractions["all"] and float(g.attrs["fraction_small"]) == fractions["small"],
          f"msd: fractions {fractions}")
    for name, sel in (("all", slice(None)), ("small", species == 0)):
        v = np.sort(d2[:, :, sel], axis=2)  # origin, lag, particle
        m = v.shape[2]
        k = min(m, max(1, math.floor(fractions[name] * m + 0.5)))
        mid = v.mean(axis=2).mean(axis=0)
        for kind, x in (("fast", v[:, :, m - k:]), ("slow", v[:, :, :k])):
            mean, err = origin_mean(x.mean(axis=2))
            rec, rec_err = g[f"msd_{kind}_{name}"]["value"][-1], g[f"msd_{kind}_{name}_err"]["value"][-1]
            d = np.max(np.abs(rec - mean) / mean)
            # 1e-12: the same sums in another order; the error from Welford against two passes: 1e-9
            check(d < 1e-12, f"msd: {kind}est {fractions[name]:.0%} of {name} ({k} of {m}) equals brute force "
                  f"(max rel diff {d:.2g})")
            check(np.allclose(rec_err, err, rtol=1e-9, atol=1e-15 * mean.max()), f"msd: its error over origins")
            check(np.all(rec > mid) if kind == "fast" else np.all(rec < mid), f"msd: {kind} subset on the "
                  f"{'far' if kind == 'fast' else 'near'} side of the {name}-particle MSD at every lag")


def golden_min(fn, a, b, iters=200):
    """Minimum of a unimodal fn on [a, b] by golden-section search."""
    r = (math.sqrt(5) - 1) / 2
    c, d = b - r * (b - a), a + r * (b - a)
    for _ in range(iters):
        if fn(c) < fn(d):
            b, d = d, c
            c = b - r * (b - a)
        else:
            a, c = c, d
            d = a + r * (b - a)
    return (a + b) / 2


def fit_distribution(x, count, samples, w, t, tail_sigmas, min_count):
    """The node's fits redone: Gaussian ln P_g with D free, weighted by counts, over bins with at least
    min_count; exponential tail over those with |x| >= tail_sigmas sqrt(<x^2>) (straight line in ln P)."""
    p = count / (samples * w)
    use = count >= min_count
    d = x_min = x0 = math.nan
    if use.sum() >= 3:
        xu, cu, lpu = x[use], count[use], np.log(p[use])

        def sse(u):
            fourdt = 4 * math.exp(u) * t
            return np.sum(cu * (lpu + xu ** 2 / fourdt + 0.5 * math.log(math.pi * fourdt)) ** 2)
        u0 = math.log(np.sum(cu * xu ** 2) / cu.sum() / (2 * t))
        d = math.exp(golden_min(sse, u0 - 3, u0 + 3))
    if count.sum() > 0:
        x_min = tail_sigmas * math.sqrt(np.sum(count * x ** 2) / count.sum())
        tail = use & (np.abs(x) >= x_min)
        if tail.sum() >= 3:
            ax, wt = np.abs(x[tail]), count[tail].astype(float)
            slope = np.polyfit(ax, np.log(p[tail]), 1, w=np.sqrt(wt))[0]
            slope_err = math.sqrt(wt.sum() / (wt.sum() * np.sum(wt * ax ** 2) - np.sum(wt * ax) ** 2))
            if slope < -slope_err:  # decays by more than one (Poisson) standard error, else no tail
                x0 = -1 / slope
    return d, x_min, x0


def jackknife(v):
    v = np.asarray(v)
    return math.sqrt((len(v) - 1) / len(v) * np.sum((v - v.mean()) ** 2))


def check_displacement(f, unwrapped, origin_frame, pair_frame, lag, scene):
    """P(dx, t) of all and small particles at the lags nearest the scene's targets: counts, density and
    its jackknife error over blocks of origins against numpy histograms of the recorded frames; the
    Gaussian and exponential-tail fits (and their jackknife errors) redone in numpy."""
    g = f["observables/displacement"]
    sp = scene.get("displacement", {})
    species = f["particles/all/species"][()]
    x, w = g["x"][()], float(g.attrs["bin_width"])
    nb, lo = len(x), x[0] - w / 2
    tail_sigmas, min_count = float(g.attrs["tail_sigmas"]), int(g.attrs["min_bin_count"])
    check(tail_sigmas == sp.get("tail_sigmas", 2.0) and min_count == sp.get("min_bin_count", 5)
          and abs(w - sp.get("bin_width", 0.05)) < 1e-15 and nb == round(2 * sp.get("x_max", 10.0) / w),
          f"displacement: {nb} bins of {w}, tail beyond {tail_sigmas} sigma, bins with >= {min_count}")
    a0 = f["observables/schedule/cutoff_a"][0]
    tau = float(g["tau_alpha"]["value"][-1])
    tau_q = float(f[f"observables/overlap/a{a0:g}/tau_alpha/value"][-1])
    check(tau == tau_q, f"displacement: tau_alpha {tau:.5g} is the overlap node's for a = {a0:g}")
    mult = sp.get("lags_tau_alpha", [0.01, 1.0, 8.5])
    want = np.array([m * tau for m in mult] + list(sp.get("lags", [])), dtype=float)
    targets = g["target_time"]["value"][-1]
    lag_index = g["lag_index"]["value"][-1]
    check(np.allclose(targets, want, rtol=1e-15), f"displacement: targets {np.round(targets, 4)}")
    nearest = np.array([np.argmin(np.abs(np.log(lag / t))) for t in want])
    check(np.array_equal(lag_index, nearest), f"displacement: lags {lag[nearest]} nearest the targets in ln t")
    n_origins = len(origin_frame)
    blocks = min(int(g.attrs["n_blocks"]), n_origins)
    check(blocks == min(sp.get("error_blocks", 20), n_origins), f"displacement: {blocks} blocks of origins")
    block_of = np.arange(n_origins) * blocks // n_origins
    rec = {k: g[k]["value"][-1] for k in ("count", "p", "p_err", "gauss_d", "gauss_d_err", "tail_x0",
                                           "tail_x0_err", "tail_x_min", "samples", "fraction_outside")}
    n_fits = 0
    for s, sel in enumerate((np.ones(len(species), bool), species == 0)):
        for l_, j in enumerate(lag_index):
            t = lag[j]
            dx = [unwrapped[pair_frame[k][j]][sel, 0] - unwrapped[of][sel, 0] for k, of in enumerate(origin_frame)]
            # The kernel's slot: floor((dx - lo) / w) + 1 clamped to 0 .. nb + 1 (0 and nb + 1: outside).
            slot = [np.clip(np.floor((d - lo) * (1.0 / w) + 1.0), 0, nb + 1).astype(int) for d in dx]
            per_block = np.zeros((blocks, nb + 2), dtype=np.int64)
            samples = np.zeros(blocks, dtype=np.int64)
            for k in range(n_origins):
                per_block[block_of[k]] += np.bincount(slot[k], minlength=nb + 2)
                samples[block_of[k]] += len(dx[k])
            count = per_block.sum(axis=0)[1:nb + 1]
            i = sl = (s, l_)  # per series [set][target], per bin [set][target][bin]
            what = f"displacement {('all', 'small')[s]} t = {t:.3g}"
            check(np.array_equal(rec["count"][sl], count) and rec["samples"][i] == samples.sum(),
                  f"{what}: counts equal numpy's ({count.sum()} of {samples.sum()} inside)")
            out_bf = 1 - count.sum() / samples.sum()
            check(abs(rec["fraction_outside"][i] - out_bf) < 1e-15, f"{what}: fraction outside {out_bf:.3g}")
            p = count / (samples.sum() * w)
            loo = [(per_block.sum(axis=0) - per_block[b])[1:nb + 1] for b in range(blocks)]
            loo_n = [samples.sum() - samples[b] for b in range(blocks)]
            p_err = np.array([jackknife([c[b] / (n_ * w) for c, n_ in zip(loo, loo_n)]) for b in range(nb)])
            check(np.allclose(rec["p"][sl], p, rtol=1e-12, atol=0)
                  and np.allclose(rec["p_err"][sl], p_err, rtol=1e-9, atol=1e-12 * p.max()),
                  f"{what}: P(dx) and its jackknife error equal numpy's")
            d, x_min, x0 = fit_distribution(x, count, samples.sum(), w, t, tail_sigmas, min_count)
            # D: the node's Levenberg-Marquardt stops when chi2 changes by < 1e-12 relative, which leaves
            # D good to ~1e-6; x0 and x_min are closed forms (1e-9: sums in another order).
            for name, mine, tol in (("gauss_d", d, 1e-5), ("tail_x_min", x_min, 1e-12), ("tail_x0", x0, 1e-9)):
                r = float(rec[name][i])
                ok = (math.isnan(mine) and math.isnan(r)) or abs(r - mine) <= tol * abs(mine)
                check(ok, f"{what}: {name} = {r:.6g} (numpy {mine:.6g})")
            if math.isfinite(x0) and math.isfinite(d):
                n_fits += 1
                fits = [fit_distribution(x, c, n_, w, t, tail_sigmas, min_count) for c, n_ in zip(loo, loo_n)]
                d_err, x0_err = jackknife([q[0] for q in fits]), jackknife([q[2] for q in fits])
                # NaN if some block's leave-one-out fit has no decaying tail, in both.
                x0_same = (math.isnan(x0_err) and math.isnan(rec["tail_x0_err"][i])) or \
                    abs(rec["tail_x0_err"][i] - x0_err) <= 1e-6 * x0_err + 1e-12 * x0
                check(abs(rec["gauss_d_err"][i] - d_err) <= 1e-3 * d_err + 1e-5 * d and x0_same,
                      f"{what}: jackknife errors D +- {d_err:.2g}, x0 +- {x0_err:.2g} equal numpy's")
    check(n_fits > 0, f"displacement: {n_fits} series with both fits")


def check_msd(f, unwrapped, origin_frame, pair_frame, lag, scene):
    """Delta(t) = <|r(t0+t) - r(t0)|^2> over particles (all, small), then over origins; D by brute force."""
    species = f["particles/all/species"][()]
    g = f["observables/msd"]
    d2 = np.array([[np.sum((unwrapped[pf] - unwrapped[of]) ** 2, axis=1) for pf in pair_frame[k]]
                   for k, of in enumerate(origin_frame)])  # origin, lag, particle
    for name, sel in (("msd_all", slice(None)), ("msd_small", species == 0)):
        bf = d2[:, :, sel].mean(axis=2).mean(axis=0)
        rec = g[name]["value"][-1]
        err = np.max(np.abs(rec - bf) / bf)
        check(err < 1e-12, f"msd: {name} equals brute force (max rel diff {err:.2g})")
    D, t_min, t_max = (float(g[k]["value"][-1]) for k in ("diffusion", "fit_t_min", "fit_t_max"))
    if math.isfinite(D):
        bf = d2.mean(axis=2).mean(axis=0)
        sel = (lag >= t_min) & (lag <= t_max)
        slope = np.polyfit(lag[sel], bf[sel], 1)[0]
        check(abs(D - slope / 4) <= 1e-9 * abs(D), f"msd: D = {D:.5g} is the slope/4 over [{t_min:.3g}, {t_max:.3g}]")
    else:
        check(False, "msd: no diffusion coefficient")
    check_msd_extremes(g, d2, species, scene)


def check_chi4(f, unwrapped, L, origin_frame, pair_frame):
    """chi4(t) by brute force: the pooled estimator, N_r times the variance
    (n - 1 divisor) of Q_r over every sub-box of every origin, with a block
    jackknife over origins; and the paper's eq. (14), the mean over origins
    of N [<Q_r^2> - <Q_r>^2], as chi4_per_origin. For the whole box both are
    N_tot times the variance of Q over origins."""
    n = unwrapped.shape[1]
    ko = len(origin_frame)
    spacing = float(f["parameters/schedule"].attrs["origin_spacing"])

    def block_of(t):  # origin_block (fits.cpp), then at most half the origins
        b = min(max(math.ceil(t / spacing - 1e-9), 1), max(1, ko // 4))
        return min(max(b, 1), max(1, ko // 2))

    def jackknife(reps):
        reps = np.asarray(reps)
        k = len(reps)
        return np.sqrt((k - 1) / k * ((reps - reps.mean(axis=0)) ** 2).sum(axis=0))

    for name, g in f["observables/chi4"].items():
        a = float(g.attrs["cutoff_a"])
        sides = g["subbox_per_side"][()]
        lag = g["lag_time"][()]
        n_lags = len(lag)
        rec = g["chi4"]["value"][-1]  # [grid][lag]
        check(rec.shape == (len(sides), n_lags), f"chi4 {name}: the last record is [grid][lag] {rec.shape}")
        check(str(g.attrs.get("estimator", b"")).find("pooled") >= 0, f"chi4 {name}: the estimator is named")
        for gi, m in enumerate(sides):
            N = n / (m * m)
            qr = []  # origin, lag, box
            for k, of in enumerate(origin_frame):
                x0 = unwrapped[of] % L
                box = (np.minimum((x0[:, 1] // (L / m)).astype(int), m - 1) * m
                       + np.minimum((x0[:, 0] // (L / m)).astype(int), m - 1))
                qr.append([np.bincount(box, weights=np.hypot(*(unwrapped[pf] - unwrapped[of]).T) < a,
                                       minlength=m * m) / N for pf in pair_frame[k]])
            qr = np.array(qr)

            def curve(keep):
                v = qr[keep].transpose(1, 0, 2).reshape(n_lags, -1)
                return N * v.var(axis=1, ddof=1)
            chi = curve(list(range(ko)))
            err = np.max(np.abs(chi - rec[gi]) / np.maximum(np.abs(chi), 1e-12))
            check(err < 1e-9, f"chi4 {name} m={m}: the pooled estimator equals brute force (max rel diff {err:.2g})")
            eq14 = (N * qr.var(axis=2)).mean(axis=0)
            if "chi4_per_origin" in g:  # eq. (14); one box has no variance within an origin
                rec14 = g["chi4_per_origin"]["value"][-1][gi]
                d = np.max(np.abs(eq14 - rec14) / np.maximum(np.abs(eq14), 1e-12)) if m > 1 else np.max(np.abs(rec14))
                check(d < 1e-9, f"chi4 {name} m={m}: chi4_per_origin equals eq. (14) by brute force (max diff {d:.2g})")
            # Per lag: a jackknife over blocks of origins spanning the lag.
            got_err = g["chi4_err"]["value"][-1][gi]
            want_err = np.full(n_lags, np.nan)
            for j in range(n_lags):
                b = block_of(lag[j])
                nb_ = -(-ko // b)
                if nb_ >= 3:
                    want_err[j] = jackknife([curve([i for i in range(ko) if i // b != blk])[j] for blk in range(nb_)])
            ok = np.isnan(want_err) == np.isnan(got_err)
            fin = ~np.isnan(want_err)
            d = np.max(np.abs(want_err[fin] - got_err[fin]) / np.maximum(want_err[fin], 1e-9 * np.max(want_err[fin]) + 1e-12)) \
                if fin.any() else 0.0
            check(ok.all() and d < 1e-6, f"chi4 {name} m={m}: its block jackknife error equals brute force "
                  f"(max rel diff {d:.2g})")
            # chi4^P, tau4: the vertex of the parabola in ln t fitted to the
            # peak above half its maximum, weights (y/y_max - 1/2)/(1/2), kept
            # within those lags; fewer than three: the parabola through the
            # largest point and its neighbours. Their errors: a jackknife over
            # blocks of origins spanning the last lag the fit reads (at most
            # a quarter of the origins; the whole box needs 3 blocks).
            def peak(y):
                b = int(np.nanargmax(y))
                lo = hi = b
                while lo > 0 and y[lo - 1] > y[b] / 2:
                    lo -= 1
                while hi < len(y) - 1 and y[hi + 1] > y[b] / 2:
                    hi += 1
                if y[b] > 0 and hi - lo >= 2:
                    u = np.log(lag[lo:hi + 1]) - math.log(lag[b])
                    w = (y[lo:hi + 1] / y[b] - 0.5) / 0.5
                    c2, c1, c0 = np.polyfit(u, y[lo:hi + 1], 2, w=np.sqrt(w))
                    fit = lambda v: c0 + c1 * v + c2 * v * v
                    v = min(max(-c1 / (2 * c2), u[0]), u[-1]) if c2 < 0 else (u[0] if fit(u[0]) >= fit(u[-1]) else u[-1])
                    return fit(v), lag[b] * math.exp(v), hi
                if b == 0 or b == len(y) - 1:
                    return y[b], lag[b], b
                x = np.log(lag[b - 1:b + 2])
                c2, c1, c0 = np.polyfit(x, y[b - 1:b + 2], 2)
                if not c2 < 0:
                    return y[b], lag[b], b + 1
                xv = -c1 / (2 * c2)
                return c0 + c1 * xv + c2 * xv * xv, math.exp(xv), b + 1
            pk = peak(chi)
            rp = (g["chi4_peak"]["value"][-1][gi], g["tau4"]["value"][-1][gi])
            check(all(abs(u - v) <= 1e-8 * abs(v) for u, v in zip(rp, pk[:2])),
                  f"chi4 {name} m={m}: peak {rp[0]:.5g} at tau4 {rp[1]:.4g} equals brute force")
            bsz = block_of(lag[pk[2]])
            nb_ = -(-ko // bsz)
            if nb_ >= 3:
                reps = np.array([peak(curve([i for i in range(ko) if i // bsz != blk]))[:2] for blk in range(nb_)])
                errs = np.sqrt((nb_ - 1) / nb_ * ((reps - reps.mean(axis=0)) ** 2).sum(axis=0))
                re = (g["chi4_peak_err"]["value"][-1][gi], g["tau4_err"]["value"][-1][gi])
                check(all(abs(u - v) <= 1e-6 * abs(v) + 1e-12 for u, v in zip(re, errs)),
                      f"chi4 {name} m={m}: peak errors +- {re[0]:.3g}, +- {re[1]:.3g} equal a brute-force "
                      f"jackknife over {nb_} blocks of {bsz} origins")


def s4_shells_brute(x0, w, L, m, q_max, n_total):
    """S4 per |q| shell (paper eqs. 15-16) for one origin and lag by the exact
    sum, as the node defines it: half-plane lattice vectors of the sub-box
    with |q| <= q_max, shells round(|n|); also, per shell, the largest error
    the grid may make given the kernel's bound on each sum_i w_i e^{iq.r_i}
    (bound_rel times sum_i |w_i| of the sub-box)."""
    ell = L / m
    dq = 2 * math.pi / ell
    nm = int(math.floor(q_max / dq + 1e-12))
    modes = [(nx, ny) for ny in range(nm + 1) for nx in range(0 if ny == 0 else -nm, nm + 1)
             if (nx * nx + ny * ny) * dq * dq <= q_max * q_max * (1 + 1e-12)]
    box = (np.minimum((x0[:, 1] // ell).astype(int), m - 1) * m + np.minimum((x0[:, 0] // ell).astype(int), m - 1))
    N = n_total / (m * m)
    nvec = np.array(modes, dtype=float)
    phase = np.exp(1j * dq * (x0 @ nvec.T))  # particle, mode
    A = np.array([np.sum((w * (box == r))[:, None] * phase, axis=0) for r in range(m * m)])  # box, mode
    wsum = np.array([np.sum(w * (box == r)) for r in range(m * m)])
    W = A / N
    if m > 1:
        v = N * (np.mean(np.abs(W) ** 2, axis=0) - np.abs(W.mean(axis=0)) ** 2)
    else:
        v = N * np.abs(W[0]) ** 2
    shell = np.rint(np.hypot(nvec[:, 0], nvec[:, 1])).astype(int)
    qn = np.hypot(nvec[:, 0], nvec[:, 1]) * dq
    if m == 1:
        v = np.where(shell == 0, np.nan, v)
    out_q, out_v, out_d = [], [], []
    for s in sorted(set(shell)):
        sel = shell == s
        out_q.append(qn[sel].mean())
        out_v.append(v[sel].mean())
        out_d.append((sel, np.abs(W[:, sel]), wsum / N))
    return np.array(out_q), np.array(out_v), out_d


def check_s4(f, name, g, unwrapped, L, origin_frame, pair_frame, sched_lag, dr_of=None, overlap="overlap",
             need_fit=True):
    """S4(q,t) of one cutoff (group g = observables/s4/<name>), every grid at
    every computed lag, against the exact direct sum from the recorded frames
    with that cutoff's weights, within the error the NUFFT grid may make (the
    kernel's stated bound, a worst case); chi4 at t_s4 against the
    brute-force chi4; the OZ fit at t_s4 a least-squares minimum. dr_of(k, j)
    gives the displacements of origin k at lag j (default: unwrapped; the
    cage-relative ones for s4_cr; then overlap = "overlap_cr", and need_fit
    False: a whole-box OZ fit that does not converge is not a failure)."""
    if dr_of is None:
        def dr_of(k, j):
            return unwrapped[pair_frame[k][j]] - unwrapped[origin_frame[k]]
    a = float(g.attrs["cutoff_a"])
    check(name == f"a{a:g}", f"s4 {name}: the group is named after its cutoff a = {a:g}")
    q_max = float(g.attrs["q_max"])
    n = unwrapped.shape[1]
    sides, n_shells = g["subbox_per_side"][()], g["n_shells"][()]
    h, q_rec = g["grid_spacing"][()], g["q"][()]
    lags = g["lag_time"][()]
    s4_lag = g["s4_lag"]["value"][-1]  # [lag][value]
    check(s4_lag.shape == (len(lags), len(q_rec)), f"s4 {name}: s4_lag's last record is [lag][value] {s4_lag.shape}")
    hw = 4  # the Gaussian half-width: the scene's [s4] half_width, default 4
    if "s4" in f["parameters"] and "half_width" in f["parameters/s4"].attrs:
        hw = int(f["parameters/s4"].attrs["half_width"])
    start = np.concatenate([[0], np.cumsum(n_shells)])
    worst = 0.0
    for li, t in enumerate(lags):
        j = int(np.argmin(np.abs(np.log(sched_lag / t))))
        for gi, m in enumerate(sides):
            R = math.pi / (h[gi] * q_max)
            bound_rel = math.exp(-math.pi * hw * (R - 1) / (R - 0.5))  # S4Grid::error_bound()
            N = n / (m * m)
            vals, tols = [], []
            for k, of in enumerate(origin_frame):
                x0 = unwrapped[of] % L
                w = (np.hypot(*dr_of(k, j).T) < a).astype(float)
                qb, vb, d = s4_shells_brute(x0, w, L, m, q_max, n)
                tol = []
                for sel, absw, wN in d:  # per mode: N [<2|W_r| d_r + d_r^2> + 2|<W>| <d> + <d>^2], d_r = bound sum|w|/N
                    dr = bound_rel * wN[:, None]
                    e = N * (np.mean(2 * absw * dr + dr ** 2, axis=0)
                             + (2 * np.abs(absw.mean(axis=0)) * dr.mean() + dr.mean() ** 2 if m > 1 else 0))
                    tol.append(e.mean())
                vals.append(vb)
                tols.append(tol)
            bf, tol = np.mean(vals, axis=0), np.mean(tols, axis=0) + 1e-12 * np.nanmax(np.abs(np.mean(vals, axis=0)))
            rec = s4_lag[li, start[gi]:start[gi + 1]]
            same_q = np.allclose(q_rec[start[gi]:start[gi + 1]], qb, rtol=1e-12)
            ok = same_q and np.all((np.abs(rec - bf) <= tol) | (np.isnan(rec) & np.isnan(bf)))
            if not ok:
                check(False, f"s4 {name} m={m} t={t:.3g}: S4 {rec} vs direct sum {bf} (tolerance {tol})")
                return
            fin = np.isfinite(bf) & (bf > 0)
            worst = max(worst, np.max(np.abs(rec[fin] - bf[fin]) / bf[fin]))
    check(True, f"s4 {name}: every grid and lag within the grid's error bound of the direct sum (max rel diff {worst:.2g})")
    # The lag of the fits: nearest the node's tau_alpha, which is the overlap node's for this cutoff.
    tau = float(g["tau_alpha"]["value"][-1])
    tau_ov = float(f[f"observables/{overlap}/a{a:g}/tau_alpha"]["value"][-1])
    check(abs(tau - tau_ov) <= 1e-9 * tau_ov, f"s4 {name}: tau_alpha {tau:.6g} is the overlap node's")
    # At tau_alpha: S4 interpolated in ln t between the computed lags that bracket it.
    t_s4 = float(g["t_s4"]["value"][-1])
    br = bracket(lags, tau)
    check(br is not None, f"s4 {name}: tau_alpha {tau:.4g} lies within the computed lags")
    lo, hi, w, third = br
    rec = tuple(int(g[k]["value"][-1]) for k in ("lag_lo", "lag_hi", "lag_third"))
    check(rec == (lo, hi, third if third is not None else -1), f"s4 {name}: bracketing lags {rec} (and the third)")
    check(abs(t_s4 - tau) <= 1e-12 * tau, f"s4 {name}: t_s4 {t_s4:.15g} is tau_alpha {tau:.15g}")
    check(abs(float(g["lag_weight"]["value"][-1]) - w) <= 1e-12, f"s4 {name}: weight w = {w:.6f}")
    li = int(g["lag_index"]["value"][-1])
    check(li == int(np.argmin(np.abs(np.log(lags / tau)))), f"s4 {name}: lag_index is the lag nearest tau_alpha")
    s4_rec, s4_err = g["s4"]["value"][-1], g["s4_err"]["value"][-1]
    s4_lin = (1 - w) * s4_lag[lo] + w * s4_lag[hi]
    check(np.allclose(s4_rec, s4_lin, rtol=1e-12, atol=1e-14, equal_nan=True),
          f"s4 {name}: S4 at t_s4 is (1 - w) S4(t_lo) + w S4(t_hi)")
    if third is not None:
        d = np.abs(quad_minus_lin(lags, tau, lo, hi, third, s4_lag[lo], s4_lag[hi], s4_lag[third]))
        ok = np.isfinite(d)
        check(np.all(s4_err[ok] >= d[ok] * (1 - 1e-9)),
              f"s4 {name}: every S4 error holds the interpolation error (largest {np.max(d[ok] / s4_rec[ok]):.2g} of S4)")
    # chi4 at t_s4: S4 at q = 0 for sub-boxes, N var(Q) interpolated for the whole box.
    chi4 = g["chi4"]["value"][-1]
    for gi, m in enumerate(sides):
        if m == 1:
            bf = []
            for l_ in (lo, hi):
                j = int(np.argmin(np.abs(np.log(sched_lag / lags[l_]))))
                q = [np.mean(np.hypot(*dr_of(k, j).T) < a) for k, of in enumerate(origin_frame)]
                bf.append(n * np.var(q, ddof=1))
            bf_t = (1 - w) * bf[0] + w * bf[1]
            check(abs(chi4[gi] - bf_t) <= 1e-9 * bf_t,
                  f"s4 {name}: whole-box chi4 {chi4[gi]:.5g} = N var(Q) interpolated ({bf[0]:.5g} .. {bf[1]:.5g})")
        else:
            check(chi4[gi] == s4_rec[start[gi]], f"s4 {name} m={m}: chi4 at t_s4 is S4 at q = 0")
    # OZ fit of the whole box: a least-squares minimum of the relative residuals over its range.
    gi = len(sides) - 1
    q, s4 = q_rec[start[gi]:start[gi + 1]], s4_rec[start[gi]:start[gi + 1]]
    chi0, xi, qf = (float(g[k]["value"][-1][gi]) for k in ("oz_chi0", "oz_xi", "oz_q_fit_max"))
    if math.isfinite(xi):
        sel = (q > 0) & (q <= qf * (1 + 1e-12)) & np.isfinite(s4)
        def sse(c, x):
            return np.sum(((s4[sel] - c / (1 + (q[sel] * x) ** 2)) / s4[sel]) ** 2)
        best = sse(chi0, xi)
        nudged = min(sse(chi0 * f1, xi * f2) for f1 in (0.999, 1, 1.001) for f2 in (0.999, 1, 1.001) if (f1, f2) != (1, 1))
        check(best <= nudged * (1 + 1e-9), f"s4 {name}: OZ fit xi={xi:.4g} chi0={chi0:.4g} over q <= {qf:.3g} is a least-squares minimum")
        check(float(g["xi"]["value"][-1]) == xi, f"s4 {name}: the xi summary is the whole box's")
        # Between the bracketing lags' fits (xi_lag, chi0_lag: the same fit at each lag), within the error.
        for k_, v, e in (("xi_lag", xi, float(g["oz_xi_err"]["value"][-1][gi])),
                         ("chi0_lag", chi0, float(g["oz_chi0_err"]["value"][-1][gi]))):
            at = g[k_]["value"][-1][[lo, hi], gi]
            if not np.all(np.isfinite(at)):  # a lag's fit gave no xi by the rule (xi_lag_rule)
                continue
            check(min(at) - e <= v <= max(at) + e,
                  f"s4 {name}: whole-box {k_[:-4]} {v:.4g} +- {e:.2g} at t_s4 lies between its values at the lags {at}")
    else:
        check(not need_fit, f"s4 {name}: no OZ fit of the whole box")


def pair_counts(x, species, L, nb, dr):
    """Pairs i < j per species pair (11, 12, 22) and bin [k dr, (k+1) dr), k < nb, minimum image."""
    d = x[None, :, :] - x[:, None, :]
    d -= L * np.floor(d / L + 0.5)
    r = np.hypot(d[..., 0], d[..., 1])
    i, j = np.triu_indices(len(x), 1)
    r, sp = r[i, j], species[i] + species[j]
    keep = r < nb * dr
    counts = np.zeros((3, nb))
    np.add.at(counts, (sp[keep], np.minimum(nb - 1, (r[keep] / dr).astype(int))), 1)
    return counts


def first_minimum(r, g, width):
    """The kernel's recipe: Gaussian smoothing (renormalised at the ends), first peak above 1,
    then the first minimum, refined by a parabola through the three bins around it."""
    dr = r[1] - r[0]
    half = int(math.ceil(3 * width / dr))
    s = np.array([sum(math.exp(-0.5 * ((l - k) * dr / width) ** 2) * g[l] for l in range(max(0, k - half), min(len(g), k + half + 1)))
                  / sum(math.exp(-0.5 * ((l - k) * dr / width) ** 2) for l in range(max(0, k - half), min(len(g), k + half + 1)))
                  for k in range(len(g))])
    k = 1
    while k < len(s) - 1 and not (s[k] > 1 and s[k] >= s[k - 1] and s[k] >= s[k + 1]):
        k += 1
    while k < len(s) - 1 and not (s[k] <= s[k - 1] and s[k] < s[k + 1]):
        k += 1
    if k >= len(s) - 1:
        return math.nan
    den = s[k - 1] - 2 * s[k] + s[k + 1]
    return r[k] + (0.5 * (s[k - 1] - s[k + 1]) / den if den > 0 else 0.0) * dr


def clusters_bf(x0, xt, neighbours, selected, L):
    """Clusters of the selected particles over the t0 neighbour lists, by breadth-first search:
    (size, R_g at t or NaN if the cluster winds around the box) for each."""
    label = -np.ones(len(x0), dtype=int)
    out = []
    for root in np.flatnonzero(selected):
        if label[root] >= 0:
            continue
        label[root] = len(out)
        u = {root: np.zeros(2)}
        queue, spans = deque([root]), False
        while queue:
            a = queue.popleft()
            for b in neighbours[a]:
                if not selected[b]:
                    continue
                bond = x0[b] - x0[a]
                ub = u[a] + bond - L * np.floor(bond / L + 0.5)
                if label[b] < 0:
                    label[b] = label[root]
                    u[b] = ub
                    queue.append(b)
                elif np.any(np.abs(u[b] - ub) > L / 2):
                    spans = True
        members = np.array(list(u))
        pos_t = np.array([u[i] for i in members]) + xt[members] - x0[members]
        rg = math.nan if spans else math.sqrt(max(0.0, np.mean(np.sum((pos_t - pos_t.mean(axis=0)) ** 2, axis=1))))
        out.append((len(members), rg))
    return out


def check_clusters(f, unwrapped, L, origin_frame, pair_frame, lag, scene, group="clusters", dr_of=None):
    """The cluster node's results against a brute-force recomputation from the frames: g_ab and
    the neighbour cutoffs, tau_alpha and the lag chosen, the sizes at every lag, and at the chosen
    lag the P(N_c) counts, the R_g bins and d_f. group "clusters_cr" with dr_of(k, j) the
    cage-relative displacements: slow and fast chosen by those (R_g still at t0 + t)."""
    if dr_of is None:
        def dr_of(k, j):
            return unwrapped[pair_frame[k][j]] - unwrapped[origin_frame[k]]
    spec = scene.get("clusters", {})
    species = f["particles/all/species"][()].astype(int)
    n = unwrapped.shape[1]
    n_min = spec.get("fractal_min_size", 10)
    for name, g in f["observables/" + group].items():
        name = name if group == "clusters" else f"{group}/{name}"
        a = float(g.attrs["cutoff_a"])
        r = g["r"][()]
        dr, nb = r[1] - r[0], len(r)
        na = np.bincount(species, minlength=2).astype(float)
        ideal = np.outer([na[0] * (na[0] - 1) / 2, na[0] * na[1], na[1] * (na[1] - 1) / 2],
                         np.pi * dr * dr * ((np.arange(nb) + 1) ** 2 - np.arange(nb) ** 2) / L ** 2)
        gs = [pair_counts(unwrapped[of] % L, species, L, nb, dr) / ideal for of in origin_frame]
        g_rec = np.array([g[k]["value"][-1] for k in ("g11", "g12", "g22")])
        err = np.max(np.abs(np.mean(gs, axis=0) - g_rec))
        check(err < 1e-9, f"clusters {name}: g_ab over {len(gs)} origin frames equals brute force (max diff {err:.2g})")
        frames = spec.get("cutoff_frames", 1)
        g_fix = np.mean(gs[:frames], axis=0)
        cut_bf = np.array([first_minimum(r, g_fix[p], spec.get("gr_smoothing", 0.1)) for p in range(3)])
        cut = g["neighbour_cutoff"]["value"][-1]
        check(np.allclose(cut, cut_bf, rtol=1e-9, atol=0), f"clusters {name}: neighbour cutoffs {cut} are the first minima of g_ab")

        # tau_alpha from Q(t) = fraction of slow particles; the lag nearest it in ln t.
        disp = np.array([[dr_of(k, jj) for jj in range(len(pair_frame[k]))] for k in range(len(origin_frame))])
        d2 = np.sum(disp ** 2, axis=3)  # origin, lag, particle
        q_bf = np.mean(d2 < a * a, axis=2).mean(axis=0)
        tau, tau_bf = float(g["tau_alpha"]["value"][-1]), crossing_time(lag, q_bf, math.exp(-1))
        check(abs(tau - tau_bf) <= 1e-9 * tau_bf, f"clusters {name}: tau_alpha {tau:.6g} (brute force {tau_bf:.6g})")
        j = int(g["lag_index"]["value"][-1])
        check(j == int(np.argmin(np.abs(np.log(lag / tau_bf)))), f"clusters {name}: lag {lag[j]:.4g} is the one nearest tau_alpha")

        # Neighbours at t0, clusters at every lag.
        neighbours = []
        for of in origin_frame:
            x = unwrapped[of]
            d = x[None, :, :] - x[:, None, :]
            d -= L * np.floor(d / L + 0.5)
            close = np.hypot(d[..., 0], d[..., 1]) < cut[species[:, None] + species[None, :]]
            np.fill_diagonal(close, False)
            neighbours.append([np.flatnonzero(row) for row in close])
        # tau_alpha lies between two scheduled lags: the results there are interpolated in ln t.
        br = bracket(lag, tau_bf)
        check(br is not None and int(g["lag_lo"]["value"][-1]) == br[0] and int(g["lag_hi"]["value"][-1]) == br[1],
              f"clusters {name}: interpolated between the lags that bracket tau_alpha")
        lo_, hi_, w, _ = br
        # The clusters node adds no interpolation error from a third lag (its
        # fits' noise swamped the curvature; docs/analysis.md).
        third = None
        check(int(g["lag_third"]["value"][-1]) == -1, f"clusters {name}: no third lag")
        check(abs(float(g["lag"]["value"][-1]) - tau) <= 1e-12 * tau, f"clusters {name}: the results are at t = tau_alpha")
        check(abs(float(g["lag_weight"]["value"][-1]) - w) <= 1e-12, f"clusters {name}: weight w = {w:.6f}")

        def at_t(v_lo, v_hi, v_3, err=None):
            """(value, smallest admissible error): the interpolated value, and the interpolation error."""
            v = (1 - w) * v_lo + w * v_hi
            d = np.abs(quad_minus_lin(lag, tau, lo_, hi_, third, v_lo, v_hi, v_3)) if third is not None else 0 * v
            return v, np.where(np.isfinite(d), d, 0)

        mean_size = {"slow": [], "fast": []}
        clusters_at = {"slow": {}, "fast": {}}
        for jj in range(len(lag)):
            for kind, sel in (("slow", d2[:, jj] < a * a), ("fast", d2[:, jj] > 9 * a * a)):
                cl = [c for k, of in enumerate(origin_frame)
                      for c in clusters_bf(unwrapped[of], unwrapped[pair_frame[k][jj]], neighbours[k], sel[k], L)]
                mean_size[kind].append(sum(c[0] for c in cl) / len(cl) if cl else math.nan)
                if jj in (j, lo_, hi_, third):
                    clusters_at[kind][jj] = cl
        lo, hi = g["size_lo"][()], g["size_hi"][()]

        def results(cl):
            """P(N_c), R_g per bin and d_f of one lag's clusters (brute force)."""
            sizes = np.array([c[0] for c in cl])
            count = np.array([np.sum((sizes >= l) & (sizes <= h)) for l, h in zip(lo, hi)])
            used = [(c[0], c[1]) for c in cl if c[0] >= n_min and c[1] > 0]
            ln_n, ln_rg = [], []
            for l, h in zip(lo, hi):
                inbin = [(math.log(s), math.log(rg)) for s, rg in used if l <= s <= h]
                ln_n.append(np.mean([v[0] for v in inbin]) if inbin else math.nan)
                ln_rg.append(np.mean([v[1] for v in inbin]) if inbin else math.nan)
            ok = np.isfinite(ln_n)
            d_f = 1 / np.polyfit(np.array(ln_n)[ok], np.array(ln_rg)[ok], 1)[0] if ok.sum() >= 3 else math.nan  # 3 bins (clusters.hpp)
            return {"count": count, "p": count / (len(sizes) * (hi - lo + 1)), "rg": np.exp(ln_rg), "d_f": d_f}

        for kind in ("slow", "fast"):
            rec = g[f"mean_size_{kind}"]["value"][-1]
            same = np.allclose(rec, mean_size[kind], rtol=1e-12, atol=0, equal_nan=True)
            check(same, f"clusters {name}: mean {kind} cluster size at every lag equals brute force")
            n_sel = g[f"n_{kind}"]["value"][-1]
            sel_bf = np.mean(d2 < a * a if kind == "slow" else d2 > 9 * a * a, axis=2).mean(axis=0) * n
            check(np.allclose(n_sel, sel_bf, rtol=1e-12), f"clusters {name}: {kind} particles per origin at every lag")
            # <N_c> at tau_alpha: interpolated, its error (1 - w) e_lo + w e_hi with the interpolation's in quadrature.
            e_lag = g[f"mean_size_{kind}_err"]["value"][-1]
            v, d = at_t(rec[lo_], rec[hi_], rec[third] if third is not None else math.nan)
            e = math.hypot((1 - w) * e_lag[lo_] + w * e_lag[hi_], d)
            got, got_e = float(g[f"{kind}_mean_size"]["value"][-1]), float(g[f"{kind}_mean_size_err"]["value"][-1])
            check(abs(got - v) <= 1e-12 * v and abs(got_e - e) <= 1e-9 * e,
                  f"clusters {name}: {kind} <N_c> at tau_alpha {got:.4g} +- {got_e:.2g} (interpolation error {d:.2g})")
            # The nearest lag: the size histogram's counts and the spanning clusters.
            r = {jj: results(cl) for jj, cl in clusters_at[kind].items()}
            check(np.array_equal(g[f"count_{kind}"]["value"][-1], r[j]["count"]),
                  f"clusters {name}: {kind} P(N_c) counts at the nearest lag equal brute force")
            spans = sum(math.isnan(c[1]) for c in clusters_at[kind][j])
            check(int(g[f"{kind}_spanning"]["value"][-1]) == spans, f"clusters {name}: {spans} spanning {kind} clusters")
            # Interpolated: P(N_c), R_g per bin, d_f; each error at least the interpolation error.
            for key, tol, label in (("p", 1e-12, "P(N_c)"), ("rg", 1e-9, "R_g per N_c bin (R_g at t0 + t, periodic)"),
                                    ("d_f", 1e-9, "d_f")):
                rec_v = np.atleast_1d(g[f"{kind}_d_f" if key == "d_f" else f"{key}_{kind}"]["value"][-1])
                rec_e = np.atleast_1d(g[f"{kind}_d_f_err" if key == "d_f" else f"{key}_{kind}_err"]["value"][-1])
                v3 = r[third][key] if third is not None else np.nan * np.asarray(r[lo_][key])
                v, d = at_t(np.asarray(r[lo_][key]), np.asarray(r[hi_][key]), np.asarray(v3))
                v = np.atleast_1d(v)
                same = np.allclose(rec_v, v, rtol=tol, atol=0, equal_nan=True)
                check(same, f"clusters {name}: {kind} {label} at tau_alpha equals brute force interpolated")
                fin = np.isfinite(rec_e)
                check(np.all(rec_e[fin] >= np.atleast_1d(d)[fin] * (1 - 1e-9)),
                      f"clusters {name}: {kind} {label} errors hold the interpolation error")


def main(path, scene_path):
    f = h5py.File(path, "r")
    check(list(f["h5md"].attrs["version"]) == [1, 1], "h5md version 1.1")
    check("name" in f["h5md/creator"].attrs, "h5md creator")
    text = f["parameters/scene_toml"][()]
    text = text.decode() if isinstance(text, bytes) else str(text)
    check(text == open(scene_path).read(), "parameters/scene_toml is the scene file")
    check(int(f.attrs.get("complete", 0)) == 1, "file marked complete")
    for obs in tomllib.loads(text).get("observables", {}).get("compute", []):
        check(f"observables/{obs}" in f, f"observables/{obs} recorded (the scene asks for it)")

    box = f["particles/all/box"]
    check(int(box.attrs["dimension"]) == 2, "box is 2D")
    L = float(box["edges"][0])
    pos = f["particles/all/position/value"][()]
    img = f["particles/all/image/value"][()]
    unwrapped = pos + img * L
    sched = f["observables/schedule"]
    frame_time = sched["frame_time"][()]
    origin_frame = sched["origin_frame"][()]
    pair_frame = sched["pair_frame"][()]
    lag = sched["lag_time"][()]
    n_frames, n, _ = pos.shape
    check(n_frames == len(frame_time), f"all {len(frame_time)} frames recorded")
    check(np.allclose(f["particles/all/position/time"][()], frame_time, rtol=0, atol=1e-9), "frame times")
    check(np.all((pos >= 0) & (pos < L)), "positions folded into the box")

    nodes = f["observables/nodes/overlap"]
    check(int(nodes["frames_lost"]["value"][-1]) == 0, "overlap node lost no frame")
    check(int(nodes["frames_whole"]["value"][-1]) == n_frames, "overlap node got every frame whole")

    check(pair_frame.shape == (len(origin_frame), len(lag)), f"schedule: pair_frame is [origin][lag] {pair_frame.shape}")
    for name, g in f["observables/overlap"].items():
        a = float(g.attrs["cutoff_a"])
        q_rec = g["q"]["value"][-1]
        # Brute force: Q(t;t0) = <Q_r> = fraction of particles that moved less than a.
        q_k = np.array([[np.mean(np.hypot(*(unwrapped[pf] - unwrapped[of]).T) < a)
                         for pf in pair_frame[k]] for k, of in enumerate(origin_frame)])
        q_bf = q_k.mean(axis=0)
        err = np.max(np.abs(q_bf - q_rec))
        check(err < 1e-12, f"{name}: Q(t) equals brute force (max diff {err:.2g})")
        tau = float(g["tau_alpha"]["value"][-1])
        tau_bf = crossing_time(lag, q_bf, math.exp(-1))
        check(math.isfinite(tau) and abs(tau - tau_bf) <= 1e-9 * tau_bf,
              f"{name}: tau_alpha {tau:.6g} (brute force {tau_bf:.6g})")
        check(np.all(np.diff(q_bf) <= 0.05), f"{name}: Q(t) decays")
        tau_t0 = g["tau_alpha_t0"]["value"][-1]
        tau_t0_bf = np.array([crossing_time(lag, q_k[k], math.exp(-1)) for k in range(len(origin_frame))])
        same = np.allclose(tau_t0, tau_t0_bf, rtol=1e-9, atol=0, equal_nan=True)
        check(same, f"{name}: tau_alpha(t0) per origin equals brute force")
        beta, tau0 = float(g["beta"]["value"][-1]), float(g["tau0"]["value"][-1])
        # The fit is a least-squares minimum of the node's objective: nudging
        # either parameter by 0.1% does not lower the residual. The node fits
        # the lags with 0.1 <= Q <= 0.7, unweighted (fits.hpp, overlap_fit_lags).
        use = np.isfinite(q_rec) & (lag > 0) & (q_rec >= 0.1) & (q_rec <= 0.7)
        e = np.ones(int(use.sum()))

        def sse(b_, t_):
            return np.sum(((q_rec[use] - 1 / ((lag[use] / t_) ** b_ + 1)) / e) ** 2)
        best = sse(beta, tau0)
        nudged = min(sse(beta * f1, tau0 * f2) for f1 in (0.999, 1, 1.001) for f2 in (0.999, 1, 1.001)
                     if (f1, f2) != (1, 1))
        check(best <= nudged * (1 + 1e-9), f"{name}: fit beta={beta:.4g} tau0={tau0:.4g} is a least-squares minimum")
    if "observables/chi4" in f:
        check_chi4(f, unwrapped, L, origin_frame, pair_frame)
    scene = tomllib.loads(text)
    if "observables/msd" in f:
        check_msd(f, unwrapped, origin_frame, pair_frame, lag, scene)
    if "observables/displacement" in f:
        check_displacement(f, unwrapped, origin_frame, pair_frame, lag, scene)
    if "observables/s4" in f:  # one group per cutoff, each against the direct sum with its own weights
        cutoffs = sorted(f"a{a:g}" for a in f["observables/schedule/cutoff_a"][()])
        check(sorted(f["observables/s4"].keys()) == cutoffs, f"s4: one group per cutoff {cutoffs}")
        for name, g in f["observables/s4"].items():
            check_s4(f, name, g, unwrapped, L, origin_frame, pair_frame, lag)
    if "observables/clusters" in f:
        nodes = f["observables/nodes/clusters"]
        check(int(nodes["frames_lost"]["value"][-1]) == 0, "clusters node lost no frame")
        check_clusters(f, unwrapped, L, origin_frame, pair_frame, lag, scene)
        for name, g in f["observables/clusters"].items():
            if "observables/overlap/" + name in f:
                t1, t2 = float(g["tau_alpha"]["value"][-1]), float(f["observables/overlap/" + name]["tau_alpha"]["value"][-1])
                check(abs(t1 - t2) <= 1e-9 * t2, f"clusters {name}: tau_alpha is the overlap node's")
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
