"""What a run will cost before it runs: kick rate, the engine's speed, CPU time and memory."""
import math

from ..scene import resolved


def kick_rate(sc):
    """Kicks per particle per unit time of scene sc: the rate the engine is
    given (the Enskog frequency of model.hpp with the scene's G_c, or the
    scene's own number), from sim_node --resolved."""
    return resolved(sc)["model"]["kick_rate"]


def events_per_second(n):
    """Driven collisions + kicks per CPU second with neighbour pairs
    (docs/engine.md, bench_engine): about 2e6 up to 10^4, 1.5e6 at 10^5,
    1.2e6 at 10^6, log-linear between."""
    x = math.log10(max(n, 1e4))
    return 2.0e6 - 0.5e6 * min(x - 4, 1) - 0.3e6 * max(0.0, x - 5)


def estimate(sc, n_nodes):
    """(CPU seconds, bytes) of one run from the engine's measured speed: its
    simulated time and collision frequency as sim_node resolves the scene."""
    r = resolved(sc)
    n, phi = r["system"]["n_particles"], r["system"]["packing_fraction"]
    origins, spacing = r["schedule"]["origins"], r["schedule"]["origin_spacing"]
    lag_max = r["schedule"]["lag_max"]
    w = r["model"]["collision_frequency"]
    events = n * w * r["model"]["sim_time"]  # collisions ~ N w / 2 and kicks N w / 2 per unit time
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
