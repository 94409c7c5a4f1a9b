#!/usr/bin/env bash
# Flow control for the kept frames: a recorder that keeps every frame
# (observables.keep_frames) and is stopped (SIGSTOP) for 5 s in the middle
# of production at N = 20000 (320 KB frames: 5 s of them overflow its
# socket buffer many times over) loses nothing: it publishes its own status
# (node "recorder") after every kept frame, the sim (--pace-nodes, as
# run_scene.sh starts it) holds its frames until it catches up, and the run
# ends complete with every frame in run.h5. In a private network namespace.
# The processes are started by hand, as run_scene.sh does, to slow the
# overlap node to 0.05 s a frame (--test-frame-delay): the sim, paced on it,
# then spends at least 5 s in production on any machine, and the stop comes
# in the middle of it.
set -euo pipefail
root=$1 build=$2
if [[ -z ${DYNHET_IN_NETNS:-} ]]; then exec "$root/launch_scripts/netns.sh" bash "$0" "$@"; fi
export LCM_DEFAULT_URL='udpm://239.255.76.67:7723?ttl=0&recv_buf_size=4194304'
. "$root/tests/processes.sh"
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
start "$tmp/recorder.log" "$bin/recorder" --out "$tmp/run.h5" --run-id 8301
rec=${pids[-1]}
start "$tmp/overlap_node.log" "$bin/overlap_node" --run-id 8301 --test-frame-delay 0.05
"$bin/sim_node" "$tmp/s.toml" --run-id 8301 --pace-nodes 2>"$tmp/sim_node.log" &
sim=$!
pids+=($sim)
# Stopped once production is under way (the sim's progress line, within a
# second of its start; production lasts at least 108 x 0.05 s).
for _ in $(seq 1200); do grep -qs "production" "$tmp/sim_node.log" && break; sleep 0.05; done
kill -STOP "$rec"
frames_at_stop=$(grep -o "frames [0-9]*/" "$tmp/sim_node.log" | tail -1)
sleep 5
frames_after=$(grep -o "frames [0-9]*/" "$tmp/sim_node.log" | tail -1)
kill -CONT "$rec"
wait "$sim" && rc=0 || rc=$?
check '[[ $rc == 0 ]]' "the sim ran to the end (exit $rc)"
wait "$rec" && rc=0 || rc=$?
check '[[ $rc == 0 ]]' "the recorder says complete (exit $rc)"
for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
pids=() rec=""
echo "   $((SECONDS - t0)) s; the sim's last progress line before the stop: ${frames_at_stop:-none}, after 5 s: ${frames_after:-none}"
# (On a loaded machine the stop can come before the recorder's first status:
# the sim then waits for "recorder at frame 0 (no status from it yet)".)
check 'grep -q "waiting for slow nodes.*: recorder at frame [0-9]*" "$tmp/sim_node.log"' \
  "the sim waited for the stopped recorder, behind ($(grep -o "waiting for slow nodes.*recorder.*" "$tmp/sim_node.log" | head -1))"
check '$py - "$tmp/run.h5" <<PY
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
((fail == 0)) || tail -5 "$tmp"/*.log
exit $fail
