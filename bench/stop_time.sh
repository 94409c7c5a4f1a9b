#!/usr/bin/env bash
# How long a SIGTERM takes to stop a run with a whole checkpoint cut
# (docs/checkpoints.md, "A stop in seconds"): each scene is started afresh
# with run_scene.sh, sent SIGTERM to its process group DELAY seconds after
# its first frame, and timed until run_scene.sh has exited (75: interrupted,
# resumable). Prints a table: N, where the sim stopped, its part's size and
# write time, and the time from the signal to the exit. WORK/<scene>.timeline
# has every log line of the run from the first frame on, stamped with the
# seconds from the signal at which it appeared (where the stop's time goes).
#
# usage: bench/stop_time.sh WORK SCENE...   (env DELAY, default 20; BUILD_DIR)
#   e.g. bench/stop_time.sh /tmp/stop scenes_at_1e6.toml scenes_at_4e6.toml
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
work=$1; shift
delay=${DELAY:-20}
export BUILD_DIR=${BUILD_DIR:-$root/build}
mkdir -p "$work"
now() { date +%s.%N; }
printf '| N | stopped at | sim part MB | written in | SIGTERM to exit |\n|---|---|---|---|---|\n'
for scene in "$@"; do
  name=$(basename "$scene" .toml)
  out=$work/$name
  set -m
  bash "$root/launch_scripts/run_scene.sh" "$scene" --out "$out" --no-build --no-plots --fresh >"$out.log" 2>&1 &
  pid=$!
  set +m
  for _ in $(seq 360000); do grep -q "frames [1-9]" "$out/sim_node.log" 2>/dev/null && break; sleep 0.1; done
  # (tail -F: a log written later is followed from its start)
  tail -n 0 -F "$out"/{sim,overlap,clusters,s4}_node.log "$out/recorder.log" "$out.log" 2>/dev/null \
    > >(perl -MTime::HiRes=time -ne 'BEGIN { $| = 1 } printf "%.3f %s", time, $_' >"$out.stamped") &
  stamp=$!
  sleep "$delay"
  t0=$(now)
  kill -TERM -- -$pid 2>/dev/null || true
  set +e; wait $pid; rc=$?; set -e
  stop=$(echo "$(now) - $t0" | bc)
  sleep 0.2
  kill "$stamp" 2>/dev/null || true
  wait "$stamp" 2>/dev/null || true
  sleep 0.1 # (perl ends at the end of its input)
  awk -v t0="$t0" '$2 != "==>" && NF > 1 { $1 = sprintf("%+8.3f", $1 - t0); print }' "$out.stamped" >"$out.timeline"
  rm -f "$out.stamped"
  n=$(grep -m1 -o 'N=[0-9]*' "$out/sim_node.log" | cut -d= -f2)
  at=$(grep -o 'a checkpoint cut at t=[0-9.]*, [a-z ]*' "$out/sim_node.log" | tail -1 | sed 's/a checkpoint cut at //')
  part=$(grep -o 'sim part [0-9.]* MB in [0-9.]* s' "$out/sim_node.log" | tail -1)
  mb=$(echo "$part" | awk '{print $3}'); s=$(echo "$part" | awk '{print $6}')
  printf '| %s | %s | %s | %s s | %.1f s (exit %s) |\n' "$n" "${at:-?}" "${mb:-?}" "${s:-?}" "$stop" "$rc"
done
