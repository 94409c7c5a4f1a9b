#!/usr/bin/env bash
# Flow control inside a node (analysis_nodes/inbox.hpp): a receive thread
# takes every message off the socket into a bounded queue while the compute
# thread works, and the sim paces its frames on the compute side's progress.
# In a private network namespace, a scene at N = 20000 (Q(t) and S4; 320 KB
# frames):
# 1. a reference run;
# 2. the same run with the s4 node slowed to 0.15 s a frame
#    (--test-frame-delay, a stand-in for S4 at large N) and the sim pacing
#    on it: complete, 0 frames lost by any node, the frames the computation
#    had not reached waited in the node's queue (not in its socket buffer),
#    and the results equal the reference's bit for bit.
# Processes are started by hand (as run_scene.sh does) to give the node the
# test flag.
set -euo pipefail
root=$1 build=$2
if [[ -z ${DYNHET_IN_NETNS:-} ]]; then exec "$root/launch_scripts/netns.sh" bash "$0" "$@"; fi
export LCM_DEFAULT_URL='udpm://239.255.76.67:7721?ttl=0&recv_buf_size=4194304'
. "$root/tests/processes.sh"
cat >"$tmp/s.toml" <<TOML
[system]
n_particles = 20000
packing_fraction = 0.6
restitution = 0.9
seed = 5
[run]
equilibration_time = 1.0
[schedule]
origins = 4
origin_spacing = 1.0
lag_min = 0.05
lag_max = 4.0
lags_per_decade = 8
[observables]
compute = ["overlap", "s4"]
cutoff_a = [0.6]
[s4]
lags = [0.5, 2.0]
TOML

run() { # out, run id, then the s4 node's extra flags; the sim paces on the nodes
  local out=$1 id=$2; shift 2
  mkdir -p "$out"
  pids=()
  start "$out/recorder.log" "$bin/recorder" --out "$out/run.h5" --run-id "$id" --timeout 30
  start "$out/overlap_node.log" "$bin/overlap_node" --run-id "$id"
  start "$out/s4_node.log" "$bin/s4_node" --run-id "$id" "$@"
  local t0=$SECONDS
  "$bin/sim_node" "$tmp/s.toml" --run-id "$id" --pace-nodes 2>"$out/sim_node.log" || echo "sim_node failed"
  for p in "${pids[@]}"; do wait "$p" || echo "a process of run $id exited $?"; done
  pids=()
  echo "run $id: $((SECONDS - t0)) s"
}
summary() { # run.h5: complete and every node's frames lost, one line
  $py -c "
import h5py, sys
f = h5py.File(sys.argv[1], 'r')
lost = {k: int(v) for k, v in f.attrs.items() if k.startswith('frames_lost')}
print(int(f.attrs['complete']), sum(lost.values()), len(lost))" "$1"
}

run "$tmp/ref" 8101
check '[[ $(summary "$tmp/ref/run.h5") == "1 0 2" ]]' "reference run: complete, 0 frames lost ($(summary "$tmp/ref/run.h5"))"

run "$tmp/slow" 8102 --test-frame-delay 0.15
read -r complete lost nodes <<<"$(summary "$tmp/slow/run.h5")"
check '[[ $complete == 1 ]]' "slow s4 node: the run is complete"
check '[[ $lost == 0 && $nodes == 2 ]]' "slow s4 node: 0 frames lost by the $nodes nodes"
check 'grep -q "done: [0-9]* frames whole, 0 lost" "$tmp/slow/s4_node.log"' \
  "slow s4 node: $(grep -o "done: .*" "$tmp/slow/s4_node.log")"
check 'grep -q "waiting for slow nodes.*: s4 at frame" "$tmp/slow/sim_node.log"' "the sim waited for the s4 node"
# The window the sim lets pile up (2 MiB of frames) waited in the queue.
peak=$(sed -n 's/.*queue (receive thread -> computation): peak \([0-9.]*\) MiB.*/\1/p' "$tmp/slow/s4_node.log")
check '$py -c "import sys; sys.exit(0 if float(sys.argv[1]) >= 1.0 else 1)" "${peak:-0}"' \
  "frames waited in the s4 node's queue, not its socket: peak ${peak:-?} MiB"
check 'grep -q "MiB, 0 messages dropped" "$tmp/slow/s4_node.log"' "the s4 node's queue dropped nothing"
check 'PYTHONPATH="$root/tests" $py -c "
import sys
from compare_runs import final_results, same
(a, la), (b, lb) = final_results(sys.argv[1]), final_results(sys.argv[2])
sys.exit(0 if same(a, b) and la == lb == 0 and any(k.startswith(\"s4/\") for k in a) else 1)" "$tmp/ref/run.h5" "$tmp/slow/run.h5"' \
  "slow s4 node: the results (Q(t), S4, xi, ...) equal the reference's bit for bit"

# 3. With checkpoint cuts, the sim waits after its last frame until the last
# cut is whole, i.e. until the slow node has caught up. Meanwhile it must go
# on saying it is alive: a node that is done waits for the sim's "done" and
# gives up on a sim silent for --sim-timeout (60 s by default; a node or
# recorder starved of CPU on a busy machine made a study's runs fail this
# way). Here the overlap node gives up after 3 s and the s4 node needs
# about 0.25 s a frame for N = 2000 frames (a window of most of the run).
sed -e 's/^n_particles = 20000/n_particles = 2000/' -e 's/^equilibration_time = 1.0/&\ncheckpoint_interval = 0.5\ncheckpoint_wall_interval = 0/' \
  "$tmp/s.toml" >"$tmp/cuts.toml"
out=$tmp/cuts id=8103
mkdir -p "$out"
start "$out/recorder.log" "$bin/recorder" --out "$out/run.h5" --run-id $id --timeout 30 --checkpoint-dir "$out/c"
start "$out/overlap_node.log" "$bin/overlap_node" --run-id $id --checkpoint-dir "$out/c" --sim-timeout 3
start "$out/s4_node.log" "$bin/s4_node" --run-id $id --checkpoint-dir "$out/c" --test-frame-delay 0.25
t0=$SECONDS
"$bin/sim_node" "$tmp/cuts.toml" --run-id $id --pace-nodes --checkpoint "$out/checkpoint.h5" --checkpoint-dir "$out/c" \
  2>"$out/sim_node.log" || echo "sim_node failed"
t_sim=$((SECONDS - t0))
for p in "${pids[@]}"; do wait "$p" || echo "a process of run $id exited $?"; done
pids=()
echo "run $id: $((SECONDS - t0)) s (the sim's production ended after $t_sim s)"
read -r complete lost nodes <<<"$(summary "$out/run.h5")"
check '[[ $complete == 1 && $lost == 0 ]]' "cuts and a slow node: complete ($complete), $lost frames lost"
check 'grep -q "done: [0-9]* frames whole, 0 lost" "$out/overlap_node.log"' \
  "the overlap node (--sim-timeout 3) waited out the sim's last cut: $(grep -o "done: .*\|failed: .*" "$out/overlap_node.log")"
# The sim asks again every second for a cut the slow node has not saved
# yet; the overlap node, past that boundary by then, answers "saved" again
# (it once answered "failed", and every such cut failed: the restart point
# stayed at the first cuts while the run went on).
boundaries() { grep -o "checkpoint: cut [0-9]* after frame -*[0-9]*" "$1" | awk '{print $NF}' | sort -u | wc -l; }
taken=$(grep -c "sim_node: checkpoint: cut [0-9]* after frame" "$out/sim_node.log")
saved_s4=$(boundaries "$out/s4_node.log")
check '! grep -q "could not save" "$out/sim_node.log"' \
  "no cut failed ($(grep -c "could not save" "$out/sim_node.log") answers of \"could not save\")"
check '[[ $taken -ge 10 && $saved_s4 == "$(boundaries "$out/sim_node.log")" && -f "$out/c/cut-$(printf %06d $((taken - 1)))/WHOLE" ]]' \
  "the slow node saved every boundary of the $taken cuts the sim took ($saved_s4), the last cut whole"

# 4. A node signalled before any run info stops at once (nothing to save,
# and no cut will come); it waited 300 s for a cut, talking on the bus.
start "$tmp/early.log" "$bin/overlap_node" --run-id 8104 --checkpoint-dir "$tmp/early"
early_pid=${pids[-1]}
t0=$(date +%s%N)
kill -TERM "$early_pid"
set +e; wait "$early_pid"; rc=$?; set -e
ms=$(( ($(date +%s%N) - t0) / 1000000 ))
pids=()
check '[[ $rc == 2 && $ms -lt 5000 ]]' "a node signalled before any run info exits 2 at once (exit $rc after $ms ms)"

((fail == 0)) || tail -n 5 "$tmp/slow/"*.log "$tmp/cuts/"*.log
exit $fail
