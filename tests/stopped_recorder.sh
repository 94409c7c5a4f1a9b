#!/usr/bin/env bash
# Flow control for the kept frames: a recorder that keeps every frame
# (observables.keep_frames) and is stopped (SIGSTOP) for 5 s mid-run at
# N = 20000 (320 KB frames: 5 s of them overflow its socket buffer many
# times over) loses nothing: it publishes its own status (node "recorder")
# after every kept frame, the sim holds its frames until it catches up,
# and the run ends complete with every frame in run.h5. In a private
# network namespace, through run_scene.sh.
set -euo pipefail
root=$1 build=$2
if [[ -z ${DYNHET_IN_NETNS:-} ]]; then exec "$root/launch_scripts/netns.sh" bash "$0" "$@"; fi
export BUILD_DIR=$build
export LCM_DEFAULT_URL='udpm://239.255.76.67:7723?ttl=0'
py=/usr/bin/python3
tmp=$(mktemp -d)
rec=""
trap '[[ -n $rec ]] && kill -CONT "$rec" 2>/dev/null || true; [[ -n ${KEEP_TMP:-} ]] && echo "kept $tmp" || rm -rf "$tmp"' EXIT
fail=0
check() { if eval "$1"; then echo "ok   $2"; else echo "FAIL $2"; fail=1; fi; }
cat >"$tmp/s.toml" <<TOML
[system]
n_particles = 20000
packing_fraction = 0.6
restitution = 0.9
seed = 3
[run]
equilibration_time = 1.0
[schedule]
origins = 6
origin_spacing = 1.0
lag_min = 0.05
lag_max = 6.0
lags_per_decade = 8
[observables]
compute = ["overlap"]
cutoff_a = [0.6]
keep_frames = true
TOML
t0=$SECONDS
bash "$root/launch_scripts/run_scene.sh" "$tmp/s.toml" --out "$tmp/out" --no-build --run-id 8301 >"$tmp/run.log" 2>&1 &
rp=$!
# The recorder this run started (its own output file names it), stopped
# as production starts (the sim's progress line): the next 5 s would bring
# most of the run.
for _ in $(seq 200); do rec=$(pgrep -f "recorder --out $tmp/out/run.h5" || true); [[ -n $rec ]] && break; sleep 0.05; done
for _ in $(seq 1200); do grep -qs "production" "$tmp/out/sim_node.log" && break; sleep 0.05; done
check '[[ -n $rec ]]' "found the run's recorder (pid ${rec:-none})"
kill -STOP "$rec"
sleep 5
kill -CONT "$rec"
wait $rp && rc=0 || rc=$?
echo "   $((SECONDS - t0)) s"
check '[[ $rc == 0 ]]' "run_scene.sh exits 0 (got $rc)"
check 'grep -q "waiting for slow nodes.*: recorder at frame" "$tmp/out/sim_node.log"' \
  "the sim waited for the stopped recorder ($(grep -o "waiting for slow nodes.*recorder.*" "$tmp/out/sim_node.log" | head -1))"
check '$py - "$tmp/out/run.h5" <<PY
import h5py, numpy as np, sys
f = h5py.File(sys.argv[1], "r")
frames = len(f["observables/schedule/frame_time"])
pos, step = f["particles/all/position/value"], f["particles/all/position/step"][:]
print("    complete", int(f.attrs["complete"]), "frames_lost_recorder", int(f.attrs["frames_lost_recorder"]),
      "frames in the file", pos.shape[0], "of", frames, "missing:", f.attrs["missing"])
ok = (int(f.attrs["complete"]) == 1 and int(f.attrs["frames_lost_recorder"]) == 0 and pos.shape == (frames, 20000, 2)
      and np.array_equal(step, np.arange(frames)) and "recorder" not in f["observables/nodes"])
sys.exit(0 if ok else 1)
PY' "complete, 0 frames lost by the recorder, every frame in run.h5 (and no node named recorder)"
((fail == 0)) || tail -20 "$tmp/run.log"
exit $fail
