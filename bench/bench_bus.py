#!/usr/bin/python3
"""The bus at scale: frames of N = 10^5 to 4 x 10^6 particles, live.

For each N, a scene at the paper's state point (phi = 0.78, eps = 0.9,
neighbour kick pairs) with a short schedule (2 origins 1 apart, lags 0.1
to 2, 4 per decade; S4 at one lag; clusters at lag 2) runs twice from the
same prepared state, so both runs have the same trajectory:

  alone  sim_node by itself (no --pace-nodes, nobody listening), in a
         private network namespace;
  live   run_scene.sh: sim, overlap, clusters and s4 nodes and the
         recorder, paced, in a private network namespace.

It prints one table: frame size, frames, the bus throughput (frame bytes
published per second of production, and while publishing), frames lost
(whole and lost per node from run.h5), whether the file is complete, the
sim's speed (time units per wall second in production) alone and live and
their ratio, and the peak resident memory (VmHWM) of every process, read
from /proc while it runs.

Usage: bench/bench_bus.py [--n 100000,1000000,4000000] [--work DIR]
                          [--build DIR] [--equilibration T] [--port P]

Prepared states are cached in the work directory (compressing 4 x 10^6
disks takes about 15-20 minutes on one core; 10^6 about 4).
"""
import argparse
import os
import re
import subprocess
import sys
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PROCS = ["sim_node", "overlap_node", "clusters_node", "s4_node", "recorder"]


def scene_text(n, state, equilibration):
    chi4 = [s for s in (64, 1024, 16384, 262144) if s < n] + [n]
    return f"""# bench/bench_bus.py: N = {n} at phi 0.78, a short schedule (a test of scale, not a measurement)
[system]
n_particles = {n}
packing_fraction = 0.78
restitution = 0.9
seed = 1
initial_state = "{state}"

[run]
equilibration_time = {equilibration}

[schedule]
origins = 2
origin_spacing = 1.0
lag_min = 0.1
lag_max = 2.0
lags_per_decade = 4

[observables]
compute = ["overlap", "chi4", "msd", "displacement", "clusters", "s4"]
cutoff_a = [0.6]

[overlap]
subbox_particles = 64

[chi4]
subbox_particles = {chi4}

[clusters]
lag = 2.0

[s4]
lags = [1.0]
subbox_particles = [1024]

[transport]
chunk_particles = 65000
"""


def children_of(pid):
    """Every descendant of pid (by /proc/*/stat's parent)."""
    parent = {}
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            with open(f"/proc/{d}/stat") as f:
                st = f.read()
            parent[int(d)] = int(st[st.rindex(")") + 2:].split()[1])
        except (OSError, ValueError):
            pass
    out, todo = set(), [pid]
    while todo:
        p = todo.pop()
        for c, pp in parent.items():
            if pp == p and c not in out:
                out.add(c)
                todo.append(c)
    return out


class PeakMemory(threading.Thread):
    """Samples VmHWM (the kernel's own peak RSS) of the named processes
    under a pid until stopped; the last reading before exit is the peak."""

    def __init__(self, pid):
        super().__init__(daemon=True)
        self.pid, self.peak, self.stop = pid, {}, threading.Event()

    def run(self):
        while not self.stop.is_set():
            for c in children_of(self.pid) | {self.pid}:
                try:
                    with open(f"/proc/{c}/comm") as f:
                        name = f.read().strip()
                    if name not in PROCS:
                        continue
                    with open(f"/proc/{c}/status") as f:
                        m = re.search(r"VmHWM:\s+(\d+) kB", f.read())
                    if m:
                        self.peak[name] = max(self.peak.get(name, 0), int(m.group(1)) / 1024.0)
                except OSError:
                    pass
            self.stop.wait(0.5)


def run_watched(cmd, log):
    with open(log, "w") as out:
        p = subprocess.Popen(cmd, stdout=out, stderr=subprocess.STDOUT)
        mem = PeakMemory(p.pid)
        mem.start()
        rc = p.wait()
        mem.stop.set()
        mem.join()
    return rc, mem.peak


PROD = re.compile(r"production wall time ([\d.]+) s for ([\d.e+-]+) time units: ([\d.]+) s waiting for paced nodes, "
                  r"([\d.]+) s publishing ([\d.]+) MB")


def production(log):
    m = None
    with open(log, errors="replace") as f:
        for line in f:
            m = PROD.search(line) or m
    if not m:
        sys.exit(f"bench_bus: no production line in {log}")
    wall, t, wait, pub, mb = (float(g) for g in m.groups())
    return dict(wall=wall, t=t, wait=wait, publish=pub, mb=mb)


def losses(h5):
    import h5py
    with h5py.File(h5, "r") as f:
        complete = int(f.attrs.get("complete", 0))
        nodes = {}
        for name, g in f["observables/nodes"].items():
            nodes[name] = (int(g["frames_whole/value"][-1]), int(g["frames_lost/value"][-1]))
    return complete, nodes


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], epilog=__doc__.split("\n\n", 1)[1],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", default="100000,1000000,4000000", help="particle numbers, comma-separated")
    ap.add_argument("--work", default="/tmp/dynhet-bench-bus", help="prepared states, scenes, runs")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--equilibration", type=float, default=1.0, help="equilibration time from the prepared state")
    ap.add_argument("--port", type=int, default=7791, help="LCM port of both runs (each in its own namespace)")
    a = ap.parse_args()
    bin_ = os.path.join(a.build, "bin")
    os.environ["BUILD_DIR"] = os.path.abspath(a.build)  # run_scene.sh's binaries are --build's too
    os.makedirs(a.work, exist_ok=True)
    rows = []
    for n in [int(float(x)) for x in a.n.split(",")]:
        state = os.path.join(a.work, f"state_{n}.h5")
        if not os.path.exists(state):
            prep = os.path.join(a.work, f"prep_{n}.toml")
            with open(prep, "w") as f:
                f.write(f"[system]\nn_particles = {n}\npacking_fraction = 0.78\nrestitution = 0.9\nseed = 1\n")
            print(f"bench_bus: N = {n}: compressing to phi 0.78 (once; cached in {state})", file=sys.stderr)
            subprocess.run([os.path.join(bin_, "sim_node"), prep, "--prepare-only", state + ".part"], check=True)
            os.replace(state + ".part", state)
        scene = os.path.join(a.work, f"scene_{n}.toml")
        with open(scene, "w") as f:
            f.write(scene_text(n, state, a.equilibration))
        url = f"udpm://239.255.76.67:{a.port}?ttl=0"

        print(f"bench_bus: N = {n}: the sim alone", file=sys.stderr)
        alone_log = os.path.join(a.work, f"alone_{n}.log")
        key = os.path.join(a.work, "bench.key")  # the sim alone tags its frames as the live one does
        if not os.path.exists(key):
            fd = os.open(key, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
            os.write(fd, os.urandom(32))
            os.close(fd)
        rc, mem_alone = run_watched([os.path.join(ROOT, "launch_scripts/netns.sh"), os.path.join(bin_, "sim_node"),
                                     scene, "--lcm-url", url, "--key-file", key], alone_log)
        if rc != 0:
            sys.exit(f"bench_bus: sim alone failed (exit {rc}), see {alone_log}")
        alone = production(alone_log)

        print(f"bench_bus: N = {n}: live, with the nodes and the recorder", file=sys.stderr)
        out = os.path.join(a.work, f"live_{n}")
        live_log = os.path.join(a.work, f"live_{n}.log")
        rc, mem = run_watched(["bash", os.path.join(ROOT, "launch_scripts/run_scene.sh"), scene, "--out", out,
                               "--no-build", "--url", url], live_log)
        live = production(os.path.join(out, "sim_node.log"))
        complete, nodes = losses(os.path.join(out, "run.h5"))
        rows.append(dict(n=n, alone=alone, live=live, complete=complete, rc=rc, nodes=nodes, mem=mem,
                         mem_alone=mem_alone.get("sim_node", float("nan"))))
        print_table(rows)


def print_table(rows):
    print()
    print("| N | frame MB | frames | bus MB/s (production) | MB/s while publishing | frames lost (whole/lost per node) "
          "| complete | sim speed alone | sim speed live | live/alone | waiting for nodes |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        fr = 16e-6 * r["n"]
        frames = round(r["live"]["mb"] / fr)
        lost = ", ".join(f"{k} {w}/{l}" for k, (w, l) in sorted(r["nodes"].items()))
        sa = r["alone"]["t"] / r["alone"]["wall"]
        sl = r["live"]["t"] / r["live"]["wall"]
        print(f"| {r['n']:.0e} | {fr:.1f} | {frames} | {r['live']['mb'] / r['live']['wall']:.1f} "
              f"| {r['live']['mb'] / max(r['live']['publish'], 1e-9):.0f} | {lost} "
              f"| {'yes' if r['complete'] == 1 and r['rc'] == 0 else 'NO'} "
              f"| {sa:.4g} | {sl:.4g} | {sl / sa:.2f} | {r['live']['wait']:.1f} s of {r['live']['wall']:.1f} s |")
    print()
    print("Peak resident memory (VmHWM, MiB):")
    print()
    print("| N | sim alone | " + " | ".join(PROCS) + " |")
    print("|---|---|" + "---|" * len(PROCS))
    for r in rows:
        print(f"| {r['n']:.0e} | {r['mem_alone']:.0f} | " +
              " | ".join(f"{r['mem'].get(p, float('nan')):.0f}" for p in PROCS) + " |")
    sys.stdout.flush()


if __name__ == "__main__":
    main()
