#!/usr/bin/env bash
# tcpq: the hub dies mid-run (kill -9 while frames flow). LCM 1.3.1's tcpq
# provider then closes its socket and reports file number -1, on which
# lcm_handle_timeout's select aborted sim_node and the recorder ("bit out of
# range 0 - FD_SETSIZE on fd_set", exit 134). Now every process says the
# connection is gone and ends by itself, none by a signal; the recorder
# closes run.h5, marked incomplete with that reason. A hub started again on
# the same port changes nothing (no process waits for it). All in a private
# network namespace.
set -euo pipefail
root=$1 build=$2
[[ ${DYNHET_IN_NETNS:-} == 1 ]] || exec "$root/launch_scripts/netns.sh" bash "$0" "$@"
export BUILD_DIR=$build
source "$root/tests/processes.sh"
port=7735
hub() { java -cp /usr/share/java/lcm.jar lcm.lcm.TCPService $port >>"$tmp/hub.log" 2>&1 & hub_pid=$!; pids+=($hub_pid)
  for _ in $(seq 150); do (exec 3<>/dev/tcp/127.0.0.1/$port && head -c 8 <&3 >/dev/null) 2>/dev/null && return 0; sleep 0.1; done
  echo "FAIL the hub did not start"; exit 1; }
# The tiny scene with 300 origins: about 3600 frames, many seconds of frames.
sed 's/^origins = 4$/origins = 300/' "$root/scenes/tiny.toml" >"$tmp/long.toml"
grep -q '^origins = 300$' "$tmp/long.toml" || { echo "FAIL scenes/tiny.toml has no 'origins = 4' line"; exit 1; }
hub
bash "$root/launch_scripts/run_scene.sh" "$tmp/long.toml" --no-build --no-plots --url tcpq://127.0.0.1:$port \
  --out "$tmp/run" >"$tmp/run.log" 2>&1 & scene=$!
frames() { { grep -o "frames [0-9]*/" "$tmp/run/sim_node.log" 2>/dev/null || true; } | tail -1 | tr -dc 0-9; }
for _ in $(seq 300); do f=$(frames); [[ -n $f ]] && ((f >= 100)) && break; sleep 0.1; done
check '[[ -n $f ]] && ((f >= 100)) && kill -0 $scene' "frames flow through the hub (${f:-0} published) and the run goes on"
kill -9 $hub_pid
sleep 2
hub
wait $scene && rc=0 || rc=$?
check '[[ $rc != 0 ]]' "run_scene.sh says the run failed (exit $rc)"
check '! grep -E "Aborted|FD_SETSIZE|core dumped|exit 1[3-9][0-9]" "$tmp/run.log"' \
  "no process aborted or ended by a signal"
for p in sim_node recorder overlap_node clusters_node s4_node; do
  check 'grep -q "the LCM connection is gone" "$tmp/run/$p.log"' "$p: says the LCM connection is gone"
  check 'grep -q "run_scene: $p failed (exit 1)" "$tmp/run.log"' "$p: ended by itself with exit 1"
done
check '$py -c "
import h5py, sys
f = h5py.File(sys.argv[1], \"r\")
sys.exit(0 if int(f.attrs[\"complete\"]) == 0 and f[\"observables\"] else 1)" "$tmp/run/run.h5"' \
  "run.h5 is closed, readable, incomplete, with the results received before"
check 'grep -q "INCOMPLETE.*" "$tmp/run/recorder.log" && grep -A1 INCOMPLETE "$tmp/run/recorder.log" | grep -q "connection is gone"' \
  "the recorder names the reason"
((fail == 0)) || { tail -20 "$tmp/run.log"; exit 1; }
