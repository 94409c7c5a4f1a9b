#!/usr/bin/env bash
# tcpq, LCM's TCP hub (lcm.lcm.TCPService): the tiny scene 5 times, each run
# complete with 0 frames lost and its results equal to a udpm run's bit for
# bit. Two runs use run_scene.sh --bus tcpq (a hub of its own each); three
# share one hub started here (--url tcpq://), which also carries a foreign
# publisher's junk on DYNHET_SIM_STATUS every 2 ms, so that every process
# has unread bytes when it exits: the case where a plain close resets the
# connection and drops the last messages still in the process's send
# buffer (dynhet/lcm_exit.hpp). Every process must close its connection
# cleanly: the namespace's TCP counter of closes aborted on unread data
# (TcpExt TCPAbortOnClose) stays 0. All in a private network namespace.
set -euo pipefail
root=$1 build=$2
[[ ${DYNHET_IN_NETNS:-} == 1 ]] || exec "$root/launch_scripts/netns.sh" bash "$0" "$@"
export BUILD_DIR=$build
source "$root/tests/processes.sh"
run=(bash "$root/launch_scripts/run_scene.sh" "$root/scenes/tiny.toml" --no-build --no-plots --run-id 4242)
aborted_closes() { awk '/^TcpExt:/ { if (!h) { for (i = 1; i <= NF; i++) if ($i == "TCPAbortOnClose") c = i; h = 1 } else print $c }' /proc/net/netstat; }
complete_no_loss() { # run.h5: complete, and frames_lost 0 for every node and the recorder
  $py -c "
import h5py, sys
f = h5py.File(sys.argv[1], 'r')
lost = {k: int(v) for k, v in f.attrs.items() if k.startswith('frames_lost')}
print('   ', sys.argv[1].split('/')[-2], 'complete', int(f.attrs['complete']), lost)
sys.exit(0 if int(f.attrs['complete']) == 1 and lost and not any(lost.values()) else 1)" "$1"
}
same_as_udpm() {
  PYTHONPATH="$root/tests" $py -c "
import sys
from compare_runs import final_results, same
(a, _), (b, _) = final_results(sys.argv[1]), final_results(sys.argv[2])
sys.exit(0 if same(a, b) else 1)" "$tmp/udpm/run.h5" "$1"
}

"${run[@]}" --url 'udpm://239.255.76.67:7723?ttl=0' --out "$tmp/udpm" >"$tmp/udpm.log" 2>&1 ||
  { echo "FAIL the udpm reference run"; tail -5 "$tmp/udpm.log"; exit 1; }
before=$(aborted_closes)

for i in 1 2; do
  "${run[@]}" --bus tcpq --out "$tmp/own$i" >"$tmp/own$i.log" 2>&1 && rc=0 || rc=$?
  check '[[ $rc == 0 ]] && grep -q "reading tcpq://127.0.0.1:" "$tmp/own$i/overlap_node.log"' \
    "run_scene.sh --bus tcpq, run $i: on its own hub, exit $rc"
done

port=7724
java -cp /usr/share/java/lcm.jar lcm.lcm.TCPService $port >"$tmp/hub.log" 2>&1 &
pids+=($!)
for _ in $(seq 150); do (exec 3<>/dev/tcp/127.0.0.1/$port && head -c 8 <&3 >/dev/null) 2>/dev/null && break; sleep 0.1; done
start "$tmp/junk.log" $py "$root/tests/tcpq_junk.py" $port DYNHET_SIM_STATUS 0.002
for i in 1 2 3; do
  "${run[@]}" --url tcpq://127.0.0.1:$port --out "$tmp/shared$i" >"$tmp/shared$i.log" 2>&1 && rc=0 || rc=$?
  check '[[ $rc == 0 ]] && grep -q "dropped a message on DYNHET_SIM_STATUS" "$tmp/shared$i/recorder.log"' \
    "one hub with junk on it, run $i: exit $rc (the junk reached the recorder and was dropped)"
done

for d in own1 own2 shared1 shared2 shared3; do
  [[ -f $tmp/$d/run.h5 ]] || { echo "FAIL $d: no run.h5"; tail -5 "$tmp/$d.log"; fail=1; continue; }
  check 'complete_no_loss "$tmp/$d/run.h5"' "$d: complete, 0 frames lost"
  check 'same_as_udpm "$tmp/$d/run.h5"' "$d: results equal the udpm run's bit for bit"
done
after=$(aborted_closes)
check '[[ $after == "$before" ]]' "every tcpq connection closed cleanly (TCPAbortOnClose $before -> $after)"
((fail == 0)) || for d in own1 shared1; do tail -n 3 "$tmp/$d"/*.log; done
exit $fail
