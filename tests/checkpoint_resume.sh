#!/usr/bin/env bash
# sim_node stopped by SIGTERM in production writes a checkpoint and exits;
# --resume continues it, and the final state equals that of the
# uninterrupted run bit for bit (positions, velocities, images, counters,
# random generator). Runs in a private network namespace.
set -euo pipefail
root=$1 bin=$2
if [[ -z ${DYNHET_IN_NETNS:-} ]]; then exec "$root/launch_scripts/netns.sh" bash "$0" "$@"; fi
tmp=$(mktemp -d)
(umask 077 && head -c 32 /dev/urandom >"$tmp/bus.key") # the run's key (docs/bus.md)
export DYNHET_KEY_FILE=$tmp/bus.key
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
cat >scene.toml <<'TOML'
[system]
n_particles = 2000
packing_fraction = 0.72
restitution = 0.8
seed = 3
tc_time = 1e-6
[run]
equilibration_time = 20.0
checkpoint_interval = 3.0
[schedule]
origins = 12
origin_spacing = 10.0
lag_min = 0.1
lag_max = 20.0
TOML
url='udpm://239.255.76.67:7691?ttl=0'
py=/usr/bin/python3

"$bin/sim_node" scene.toml --lcm-url "$url" --checkpoint A.h5 2>a.log

"$bin/sim_node" scene.toml --lcm-url "$url" --checkpoint B.h5 2>b.log &
pid=$!
# Stop it once it is in production (a checkpoint past a published frame).
for _ in $(seq 600); do
  if [[ -f B.h5 ]] && $py -c "import h5py,sys; sys.exit(0 if h5py.File('B.h5','r').attrs['next_frame'][0] > 0 else 1)" 2>/dev/null; then break; fi
  sleep 0.05
done
kill -TERM $pid
set +e
wait $pid
rc=$?
set -e
cat b.log | grep -v '^\[' || true
[[ $rc -eq 143 ]] || { echo "FAIL: interrupted sim_node exited $rc, expected 143"; exit 1; }
stopped=$($py -c "import h5py; f=h5py.File('B.h5','r'); print(f.attrs['time'][0], f.attrs['next_frame'][0])")
echo "checkpoint at t, next frame: $stopped"

"$bin/sim_node" --resume B.h5 --lcm-url "$url" --checkpoint B.h5 2>b2.log
grep resumed b2.log

$py - <<'PY'
import sys
import h5py
import numpy as np
a, b = h5py.File("A.h5", "r"), h5py.File("B.h5", "r")
bad = [k for k in ("x", "y", "vx", "vy", "image_x", "image_y", "collision_count", "rng", "last_collision")
       if not np.array_equal(a[k][()], b[k][()])]
bad += [k for k in ("time", "collisions", "kicks", "tc", "virial") if a.attrs[k][0] != b.attrs[k][0]]
print("final time", a.attrs["time"][0], "collisions", a.attrs["collisions"][0])
if bad:
    print("FAIL: resumed run differs in", bad)
    sys.exit(1)
print("PASS: the resumed run ends bit for bit like the uninterrupted one")
PY
