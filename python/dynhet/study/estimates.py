"""What a run will cost before it runs: kick rate, the engine's speed, CPU time and memory."""
import math


def kick_rate(phi, ratio=1.43):
    """The Enskog frequency of common/include/dynhet/model.hpp (mixture G_c)."""
    s = (2.0, 2.0 * ratio)
    m = (1.0, ratio * ratio)
    m1, m2 = 0.5 * (s[0] + s[1]), 0.5 * (s[0] ** 2 + s[1] ** 2)
    num = den = 0.0
    for a in range(2):
        for b in range(2):
            sab = 0.5 * (s[a] + s[b])
            g = 1 / (1 - phi) + 9 / 16 * phi / (1 - phi) ** 2 * s[a] * s[b] / sab * m1 / m2
            w = 0.25 * sab * math.sqrt((m[a] + m[b]) / (m[a] * m[b]))
            num += w * g
            den += w
    return 2.59 * phi * (num / den) / math.sqrt(math.pi)


def events_per_second(n):
    """Driven collisions + kicks per CPU second with neighbour pairs
    (docs/engine.md, bench_engine): about 2e6 up to 10^4, 1.5e6 at 10^5,
    1.2e6 at 10^6, log-linear between."""
    x = math.log10(max(n, 1e4))
    return 2.0e6 - 0.5e6 * min(x - 4, 1) - 0.3e6 * max(0.0, x - 5)


def estimate(sc, n_nodes):
    """(CPU seconds, bytes) of one run from the engine's measured speed."""
    sy, rn, sch = sc.get("system", {}), sc.get("run", {}), sc.get("schedule", {})
    n, phi = int(sy.get("n_particles", 1000)), float(sy.get("packing_fraction", 0.7))
    eq = float(rn.get("equilibration_time", 100.0))
    origins, spacing = int(sch.get("origins", 10)), float(sch.get("origin_spacing", 10.0))
    lag_max = float(sch.get("lag_max", 100.0))
    t = eq + (origins - 1) * spacing + lag_max
    w = kick_rate(phi, float(sy.get("radius_ratio", 1.43)))
    events = n * w * t  # collisions ~ N w / 2 and kicks N w / 2 per unit time
    compress = 2.5e-4 * n * (1 + max(0.0, phi - 0.6) * 10)  # seconds, bench_engine's compression times
    cpu = events / events_per_second(n) + compress
    held = min(origins, lag_max / spacing + 2)
    mem = 60e6 + 230 * n + n_nodes * 16 * n * held
    return cpu, mem


def fmt_time(s):
    if not math.isfinite(s):
        return "?"
    s = int(round(s))
    return f"{s // 3600}:{s % 3600 // 60:02d}:{s % 60:02d}"
