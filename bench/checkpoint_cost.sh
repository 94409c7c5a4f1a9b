#!/usr/bin/env bash
# What checkpoint cuts cost (docs/checkpoints.md, "What it costs"): for each
# N, the same run (phi 0.78, eps 0.9, every observable, one cutoff, 2
# origins, lags 0.1 to 2 as scenes/n4e6.toml) with cuts at
# run.checkpoint_interval = INTERVAL and without (--no-checkpoints), from a
# prepared state made once per N (cached in WORK). Prints a table: each
# process's part size and write time (median over the run's cuts), the
# number of cuts, the wall time with and without, the overhead, and the time
# a SIGTERM to the group took to stop every process (a third run, stopped
# half-way through its production).
#
# Usage: bench/checkpoint_cost.sh WORK [N...]   (env INTERVAL, default 10;
#        PRODUCTION, time units between the two origins, default 10)
#   e.g. bench/checkpoint_cost.sh /tmp/ckcost 100000 1000000
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
work=$1; shift
ns=("${@:-100000}")
interval=${INTERVAL:-10}
production=${PRODUCTION:-10}
export BUILD_DIR=${BUILD_DIR:-$root/build}
bin=$BUILD_DIR/bin
mkdir -p "$work"
py=/usr/bin/python3
now() { date +%s.%N; }

scene_for() { # N -> a scene file
  local n=$1 f=$work/n$1.toml
  cat >"$f" <<TOML
[system]
n_particles = $n
packing_fraction = 0.78
restitution = 0.9
seed = 1
initial_state = "state_$n.h5"
[run]
equilibration_time = $interval
checkpoint_interval = $interval
[schedule]
origins = 2
origin_spacing = $production
lag_min = 0.1
lag_max = 2.0
lags_per_decade = 4
[observables]
compute = ["overlap", "chi4", "msd", "displacement", "clusters", "s4"]
cutoff_a = [0.6]
[overlap]
subbox_particles = 64
[chi4]
subbox_particles = [64, 1024, 16384]
[clusters]
lag = 2.0
[s4]
lags = [1.0]
subbox_particles = [1024]
[transport]
chunk_particles = 65000
TOML
  [[ -f $work/state_$n.h5 ]] || "$bin/sim_node" "$f" --prepare-only "$work/state_$n.h5" 2>"$work/prepare_$n.log"
  echo "$f"
}

printf '| N | process | part MB | write s | cuts | wall with | wall without | overhead | SIGTERM to exit |\n'
printf '|---|---|---|---|---|---|---|---|---|\n'
for n in "${ns[@]}"; do
  scene=$(scene_for "$n")
  t0=$(now)
  bash "$root/launch_scripts/run_scene.sh" "$scene" --out "$work/with_$n" --no-build --no-plots --fresh \
    >"$work/with_$n.log" 2>&1
  with=$(echo "$(now) - $t0" | bc)
  t0=$(now)
  bash "$root/launch_scripts/run_scene.sh" "$scene" --out "$work/without_$n" --no-build --no-plots --no-checkpoints \
    >"$work/without_$n.log" 2>&1
  without=$(echo "$(now) - $t0" | bc)
  # Stopped by SIGTERM half-way through the production.
  set -m
  bash "$root/launch_scripts/run_scene.sh" "$scene" --out "$work/term_$n" --no-build --no-plots --fresh \
    >"$work/term_$n.log" 2>&1 &
  pid=$!
  set +m
  for _ in $(seq 36000); do grep -q "frames [1-9]" "$work/term_$n/sim_node.log" 2>/dev/null && break; sleep 0.1; done
  sleep "$(echo "$without / 4" | bc)"
  t0=$(now)
  kill -TERM -- -$pid 2>/dev/null || true
  set +e; wait $pid; rc=$?; set -e
  stop=$(echo "$(now) - $t0" | bc)
  $py - "$work/with_$n" "$n" "$with" "$without" "$stop" "$rc" <<'PY'
import re, statistics, sys, glob
d, n, with_, without, stop, rc = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5]), sys.argv[6]
pat = re.compile(r"(\w+?)(?:_node)?: checkpoint: cut (\d+).*?\((?:sim part )?([\d.]+) MB in ([\d.]+) s[,)]")
rows = {}
for f in glob.glob(d + "/*.log"):
    for line in open(f, errors="replace"):
        m = pat.search(line)
        if m:
            rows.setdefault(m.group(1), []).append((float(m.group(3)), float(m.group(4))))
for f in glob.glob(d + "/recorder.log"):
    for line in open(f):
        m = re.search(r"recorder: checkpoint: cut (\d+) saved \(journal ([\d.]+) MB\)", line)
        if m:
            rows.setdefault("recorder", []).append((float(m.group(2)), float("nan")))
first = True
for proc in ("sim", "overlap", "clusters", "s4", "recorder"):
    if proc not in rows:
        continue
    mb = statistics.median(r[0] for r in rows[proc])
    s = statistics.median(r[1] for r in rows[proc])
    tail = (f"{len(rows[proc])} | {with_:.0f} s | {without:.0f} s | {100 * (with_ - without) / without:+.1f}% | "
            f"{stop:.1f} s (exit {rc})") if first else " | | | | "
    print(f"| {n:.0e} | {proc} | {mb:.1f} | {'journal' if s != s else f'{s:.2f}'} | {tail} |")
    first = False
PY
done
