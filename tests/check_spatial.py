"""The spatial brute-force checks of a run file, for check_run.py and
check_cage_relative.py: S4(q, t) per |q| shell by exact sums, and the slow
and fast clusters (neighbours within the first minima of g_ab, clusters by
breadth-first search) from the recorded frames."""
import math
from collections import deque

import numpy as np

from check_common import bracket, check, crossing_time, quad_minus_lin, scene_of

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
    # the Gaussian half-width: the scene's [s4] half_width
    hw = int(f["parameters/s4"].attrs["half_width"]) if "s4" in f["parameters"] and "half_width" in \
        f["parameters/s4"].attrs else scene_of(f["parameters/scene_toml"][()])["s4"]["half_width"]
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
    # xi(t)'s errors: the jackknife over blocks of origins spanning the lag,
    # so none where xi is NaN or such blocks do not fit four times into the
    # origins measured at that lag; positive where given.
    if "xi_lag_err" in g:
        xi_lag, xi_err = g["xi_lag"]["value"][-1], g["xi_lag_err"]["value"][-1]
        frame_time = f["observables/schedule/frame_time"][()]
        spacing = float(np.median(np.diff(frame_time[origin_frame]))) if len(origin_frame) > 1 else 0.0
        bad = []
        for li, t in enumerate(lags):
            j = int(np.argmin(np.abs(np.log(sched_lag / t))))
            measured = int(np.sum(np.asarray(pair_frame)[:, j] >= 0))
            span = spacing <= 0 or math.ceil(t / spacing - 1e-9) <= max(1, measured // 4)
            for gi in range(len(sides)):
                e = xi_err[li, gi]
                if np.isfinite(e) and not (np.isfinite(xi_lag[li, gi]) and span and e > 0):
                    bad.append((t, gi, e))
        given = int(np.isfinite(xi_err).sum())
        check(not bad, f"s4 {name}: xi(t) errors only where xi is and blocks span the lag ({given} given)"
              + (f"; not so at {bad[:3]}" if bad else ""))
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
    spec = scene["clusters"]
    species = f["particles/all/species"][()].astype(int)
    n = unwrapped.shape[1]
    n_min = spec["fractal_min_size"]
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
        frames = spec["cutoff_frames"]
        g_fix = np.mean(gs[:frames], axis=0)
        cut_bf = np.array([first_minimum(r, g_fix[p], spec["gr_smoothing"]) for p in range(3)])
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
