#!/usr/bin/env bash
# Flow control: a node stopped (SIGSTOP) for seconds in a run whose frames
# (N = 20000, 320 KB each) would overflow its socket buffer many times over
# in that time loses nothing: the sim holds its frames until the node
# catches up (sim_node --pace-nodes, which run_scene.sh sets), and the run
# ends complete. In a private network namespace.
set -euo pipefail
root=$1 build=$2
if [[ -z ${DYNHET_IN_NETNS:-} ]]; then exec "$root/launch_scripts/netns.sh" bash "$0" "$@"; fi
export BUILD_DIR=$build
export LCM_DEFAULT_URL='udpm://239.255.76.67:7698?ttl=0'
tmp=$(mktemp -d)
trap 'pkill -CONT -f "overlap_node --run-id 7001" 2>/dev/null || true; rm -rf "$tmp"' EXIT
fail=0
check() { if eval "$1"; then echo "ok   $2"; else echo "FAIL $2"; fail=1; fi; }
cat >"$tmp/s.toml" <<TOML
[system]
n_particles = 20000
packing_fraction = 0.6
restitution = 0.9
seed = 3
[run]
equilibration_time = 2.0
[schedule]
origins = 6
origin_spacing = 1.0
lag_min = 0.05
lag_max = 6.0
lags_per_decade = 8
[observables]
compute = ["overlap"]
cutoff_a = [0.6]
TOML
bash "$root/launch_scripts/run_scene.sh" "$tmp/s.toml" --out "$tmp/out" --no-build --run-id 7001 >"$tmp/run.log" 2>&1 &
rp=$!
# Stopped as soon as it has the run info, and held until 3 s into
# production (the sim's progress line): whatever the machine's speed, the
# sim reaches its frames while the node is stopped (unpaced, the 108 frames
# would go out in about a second and overflow its socket buffer).
for _ in $(seq 300); do grep -qs "run 7001" "$tmp/out/overlap_node.log" && break; sleep 0.02; done
pkill -STOP -f "overlap_node --run-id 7001"
for _ in $(seq 1200); do grep -qs "production" "$tmp/out/sim_node.log" && break; sleep 0.05; done
sleep 3
pkill -CONT -f "overlap_node --run-id 7001"
wait $rp && rc=0 || rc=$?
check '[[ $rc == 0 ]]' "run_scene.sh exits 0 (got $rc)"
check 'grep -q "waiting for slow nodes.*: overlap at frame" "$tmp/out/sim_node.log"' "the sim waited for the stopped node"
check 'grep -q "done: [0-9]* frames whole, 0 lost" "$tmp/out/overlap_node.log"' \
  "the stopped node lost no frame ($(grep -o "done: .*" "$tmp/out/overlap_node.log"))"
check '/usr/bin/python3 -c "import h5py, sys; sys.exit(0 if int(h5py.File(sys.argv[1], \"r\").attrs[\"complete\"]) == 1 else 1)" "$tmp/out/run.h5"' \
  "the run is complete"
((fail == 0)) || tail -20 "$tmp/run.log"
exit $fail
