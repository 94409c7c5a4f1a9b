#!/usr/bin/env bash
# Where frames are still lost, the node names the cause it observed, not a
# guess. In a private network namespace, a bare sim_node WITHOUT
# --pace-nodes (no flow control) at N = 20000 (320 KB frames), two nodes:
# - the s4 node slowed to 0.3 s a frame (--test-frame-delay) with a 1 MiB
#   queue (--max-queue-mib 1): its queue fills, it loses frames, and says
#   "queue full: the node fell more than 1 MiB behind", and that its socket
#   dropped nothing;
# - the overlap node stopped (SIGSTOP) from the run info until the sim has
#   ended (at least 4 s): its socket buffer overflows, it loses frames, and
#   says how many datagrams the kernel dropped at its socket while the
#   process took nothing for so many seconds.
set -euo pipefail
root=$1 build=$2
if [[ -z ${DYNHET_IN_NETNS:-} ]]; then exec "$root/launch_scripts/netns.sh" bash "$0" "$@"; fi
export LCM_DEFAULT_URL='udpm://239.255.76.67:7722?ttl=0&recv_buf_size=4194304'
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
lags = [0.5]
TOML
id=8201
t0=$SECONDS
# (--sim-timeout: the sim may end while the node is stopped, its "done"
# lost with the frames; the node then gives up after 8 s of silence.)
start "$tmp/overlap_node.log" "$bin/overlap_node" --run-id $id --sim-timeout 8
overlap=${pids[-1]}
start "$tmp/s4_node.log" "$bin/s4_node" --run-id $id --test-frame-delay 0.3 --max-queue-mib 1
"$bin/sim_node" "$tmp/s.toml" --run-id $id 2>"$tmp/sim_node.log" &
sim=$!
pids+=($sim)
# The overlap node stopped as soon as it has the run info, and held until
# the sim has ended and 4 s have passed: every frame (23 MB) meets a
# stopped node, whatever the machine's speed.
for _ in $(seq 300); do grep -qs "run $id" "$tmp/overlap_node.log" && break; sleep 0.02; done
kill -STOP "$overlap"
stopped=$SECONDS
for _ in $(seq 1200); do ! kill -0 "$sim" 2>/dev/null && ((SECONDS - stopped >= 5)) && break; sleep 0.05; done
kill -CONT "$overlap"
wait "$sim" && rc=0 || rc=$?
check '[[ $rc == 0 ]]' "the sim ran to the end (exit $rc)"
for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
pids=()
echo "   $((SECONDS - t0)) s"
grep -h "frames lost\|done:\|failed:" "$tmp/s4_node.log" "$tmp/overlap_node.log" | sed 's/^/   /'
check 'grep -qE "(done|failed): [0-9]+ frames whole, [1-9][0-9]* lost" "$tmp/s4_node.log"' "the slow s4 node lost frames"
check 'grep -q "queue full: the node fell more than 1 MiB behind ([1-9][0-9]* messages dropped" "$tmp/s4_node.log"' \
  "the s4 node names the cause: queue full"
check '! grep -q "socket buffer overflow" "$tmp/s4_node.log"' "... and not its socket (the receive thread kept up)"
check 'grep -qE "(done|failed): [0-9]+ frames whole, [1-9][0-9]* lost" "$tmp/overlap_node.log"' "the stopped overlap node lost frames"
check 'grep -qE "socket buffer overflow: the kernel dropped [1-9][0-9]* datagrams at this node.s socket, while the process took nothing for ([3-9]|[1-9][0-9])[.0-9]* s" "$tmp/overlap_node.log"' \
  "the overlap node names the cause: socket buffer overflow while stopped"
check '! grep -q "queue full" "$tmp/overlap_node.log"' "... and not its queue"
exit $fail
