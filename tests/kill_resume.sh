#!/usr/bin/env bash
# Runs that outlive their processes (docs/checkpoints.md). In a private
# network and mount namespace, a scene with a checkpoint cut every 0.5 time
# units and slow nodes (0.1 s a frame), so that the run lasts seconds:
#  1. the uninterrupted run: the reference;
#  2. SIGKILL of a randomly chosen process (sim, each node, the recorder, or
#     the whole process group) at seeded random times in production, four
#     times in one run, each followed by the same command, which resumes;
#  3. SIGKILL of a process while it writes its part of a cut (a pause
#     between the bytes and the rename, DYNHET_TEST_PART_WRITE_DELAY);
#  4. SIGTERM of the whole process group at random times, twice: every
#     process saves its part of one last cut and exits; run_scene.sh exits
#     75 within a bound; run.h5 says incomplete, interrupted;
#  4a. the same with no synchronised time left in the run: the sim cuts
#     from its whole engine between synchronised times, and the resumed run
#     equals the uninterrupted one with that interval;
#  4b. SIGTERM while the processes start (the nodes up and the sim not; a
#     process launched and not yet ready): exit 75, nothing left running;
#  5. the newest whole cut corrupted (one byte of a node's part): refused
#     with the file named, the cut before it used;
#  6. the disk of the checkpoints fills during the run (a 4 MB tmpfs):
#     cuts fail, the previous whole one survives, and the run resumes
#     from it once there is room;
#  7. a run recorded with --record across a SIGTERM: one log per segment,
#     and replay.sh of the segments in order gives the uninterrupted
#     run's results.
# Every resumed run's run.h5 must equal the reference in every dataset and
# attribute but the wall-clock ones (tests/compare_h5.py).
# Usage: kill_resume.sh ROOT BUILD [SEED]
set -euo pipefail
[[ -z ${TRACE:-} ]] || set -x
root=$1 build=$2 seed=${3:-2026}
if [[ -z ${DYNHET_IN_MOUNTNS:-} ]]; then exec env DYNHET_IN_MOUNTNS=1 unshare -m bash "$0" "$@"; fi
if [[ -z ${DYNHET_IN_NETNS:-} ]]; then exec "$root/launch_scripts/netns.sh" bash "$0" "$@"; fi
export BUILD_DIR=$build
export LCM_DEFAULT_URL='udpm://239.255.76.67:7699?ttl=0'
tmp=$(mktemp -d)
trap 'umount "$tmp/ckdisk" 2>/dev/null || true; [[ -n ${KEEP_TMP:-} ]] && echo "kept $tmp" || rm -rf "$tmp"' EXIT
py=/usr/bin/python3
RANDOM=$seed
fail=0
check() { if eval "$1"; then echo "ok   $2"; else echo "FAIL $2"; fail=1; fi; }
sed 's/^equilibration_time = 5.0/equilibration_time = 5.0\ncheckpoint_interval = 0.5/' "$root/scenes/tiny.toml" >"$tmp/scene.toml"
grep -q "checkpoint_interval = 0.5" "$tmp/scene.toml"
run_id=4711
same() { # DIR [REFERENCE]: DIR's run.h5 equals the reference's (default the uninterrupted run)
  $py "$root/tests/compare_h5.py" "${2:-$tmp/ref}/run.h5" "$1/run.h5" >"$1.cmp" 2>&1 || { cat "$1.cmp"; return 1; }
}
complete() { $py -c "import h5py, sys; sys.exit(0 if int(h5py.File(sys.argv[1], 'r').attrs['complete']) == 1 else 1)" "$1"; }

# Starts the run in DIR in the background, in a process group of its own
# (pid in $run_pid, the group's id too).
start_run() { # DIR [SCENE]
  set -m
  bash "$root/launch_scripts/run_scene.sh" "${2:-$tmp/scene.toml}" --out "$1" --run-id $run_id --no-build --no-plots \
    --test-node-delay 0.1 >>"$1.log" 2>&1 &
  run_pid=$!
  set +m
}
finish_run() { # DIR [SCENE]: the same command until it completes (at most 4 more times)
  for _ in 1 2 3 4; do
    bash "$root/launch_scripts/run_scene.sh" "${2:-$tmp/scene.toml}" --out "$1" --run-id $run_id --no-build --no-plots \
      --test-node-delay 0.1 >>"$1.log" 2>&1 && return 0
  done
  return 1
}
pid_of() { # a process of this run: sim_node, overlap_node, s4_node, clusters_node or recorder
  case $1 in
  recorder) pgrep -f "bin/recorder --out $2/run.h5" | head -1 || true ;;
  *) pgrep -f "bin/$1 .*--run-id $run_id" | head -1 || true ;;
  esac
}

# 1. The reference.
bash "$root/launch_scripts/run_scene.sh" "$tmp/scene.toml" --out "$tmp/ref" --run-id $run_id --no-build --no-plots \
  --test-node-delay 0.1 >"$tmp/ref.log" 2>&1 || { tail -20 "$tmp/ref.log"; exit 1; }
check 'complete "$tmp/ref/run.h5"' "reference run complete"

# 2. SIGKILL of random processes at random times, four times.
victims=(sim_node overlap_node s4_node clusters_node recorder all)
out=$tmp/killed
killed=0 # rounds whose run was killed (not ended before the kill)
for round in 1 2 3 4; do
  touch "$tmp/round$round.start"
  start_run "$out"
  t=$(( RANDOM % 1500 )) # ms after this segment's first whole cut: within the production (it lasts seconds)
  v=${victims[RANDOM % ${#victims[@]}]}
  # The kill waits until this segment is in production (the processes'
  # parts at its frame boundaries in checkpoints/frames/), its victim
  # running and a whole cut of its own written (a cut to resume from,
  # whatever the load does to the start); at most 90 s, or until the run
  # has ended.
  ready=0
  for _ in $(seq 1800); do
    if [[ -n $(find "$out/checkpoints" -path "*/cut-*/WHOLE" -newer "$tmp/round$round.start" 2>/dev/null | head -1) &&
      -n $(find "$out/checkpoints/frames" -name "*.part" -newer "$tmp/round$round.start" 2>/dev/null | head -1) &&
      -n $(pid_of "${v/all/sim_node}" "$out") ]]; then
      ready=1
      break
    fi
    kill -0 "$run_pid" 2>/dev/null || { ready=ended; break; }
    sleep 0.05
  done
  if [[ $ready == 0 ]]; then
    echo "FAIL round $round: no whole cut of this segment with $v running within 90 s of its start"
    fail=1
  fi
  sleep "$(printf '%d.%03d' $((t / 1000)) $((t % 1000)))"
  if [[ $v == all ]]; then
    kill -KILL -- -$run_pid 2>/dev/null || true
  else
    p=$(pid_of "$v" "$out")
    if [[ -n $p ]]; then kill -KILL "$p"; fi
  fi
  set +e; wait $run_pid; rc=$?; set -e
  ((rc == 0)) || killed=$((killed + 1))
  # (no whole cut: the run ended before the kill, or its cuts were off; the checks below then say so)
  cut=$(ls -d "$out"/checkpoints/cut-*/WHOLE 2>/dev/null | tail -1 | sed 's/.*cut-0*\([0-9]*\)\/WHOLE/\1/' || true)
  echo "     round $round: SIGKILL of $v $t ms after the segment's first whole cut$([[ $ready != ended ]] || echo ' (the run had ended before it)'): run_scene exit $rc, newest whole cut ${cut:-none}"
done
finish_run "$out" || true
# Most rounds must have killed a running run (one may find it ended on a
# starved machine), or the checks below would say little.
check '((killed >= 3))' "at least 3 of the 4 rounds killed the run before it ended ($killed did)"
check 'complete "$out/run.h5"' "killed $killed times: the run completes"
check 'same "$out"' "killed $killed times and resumed: run.h5 equals the uninterrupted run's"
check '[[ $(grep -h "resumed from cut" "$out"/*_node.log "$out"/recorder.log | wc -l) -ge 4 ]]' "the nodes and the recorder resumed from cuts"

# 3. SIGKILL while a part is written.
out=$tmp/midwrite
export DYNHET_TEST_PART_WRITE_DELAY=0.3
start_run "$out"
victim="" tmpfile=""
for _ in $(seq 200); do ls "$out"/checkpoints/cut-*/WHOLE >/dev/null 2>&1 && break; sleep 0.05; done
whole=$(ls -d "$out"/checkpoints/cut-*/WHOLE 2>/dev/null | tail -1)
for _ in $(seq 200); do
  tmpfile=$(ls -t "$out"/checkpoints/cut-*/*.part.tmp "$out"/checkpoints/frames/*.part.tmp 2>/dev/null | head -1 || true)
  [[ -n $tmpfile ]] && break
  sleep 0.05
done
unset DYNHET_TEST_PART_WRITE_DELAY
if [[ -n $tmpfile ]]; then
  victim=$(basename "$tmpfile" .part.tmp)
  victim=${victim%-*} # frames/overlap-18.part: the part of overlap
  case $victim in sim) proc=sim_node ;; recorder) proc=recorder ;; *) proc=${victim}_node ;; esac
  p=$(pid_of "$proc" "$out")
  if [[ -n $p ]]; then kill -KILL "$p"; fi
fi
set +e; wait $run_pid; set -e
check '[[ -n $victim && -n $whole ]]' "a process was killed while writing its part ($tmpfile), after a whole cut"
finish_run "$out" || true
check 'complete "$out/run.h5" && same "$out"' "killed mid-write ($victim) and resumed: run.h5 equals the uninterrupted run's"

# 4. SIGTERM of the whole group, three times.
out=$tmp/term
# Round 3 signals a resumed run while its processes start (before the sim
# speaks): the recorder, resumed from its journal, must not wait for a cut
# that no sim will take.
for round in 1 2 3; do
  start_run "$out"
  t=$(( 1500 + RANDOM % 3000 ))
  ((round < 3)) || t=$(( 200 + RANDOM % 600 ))
  sleep "$(printf '%d.%03d' $((t / 1000)) $((t % 1000)))"
  kill -TERM -- -$run_pid 2>/dev/null || true
  s0=$(date +%s%N)
  set +e; wait $run_pid; rc=$?; set -e
  ms=$(( ($(date +%s%N) - s0) / 1000000 ))
  echo "     SIGTERM at $t ms: exit $rc after $ms ms"
  if [[ -f $out/run.h5 ]] && ! complete "$out/run.h5"; then
    check '[[ $rc == 75 ]]' "SIGTERM $round: run_scene.sh exits 75, interrupted and resumable (got $rc)"
    check '[[ $ms -lt 20000 ]]' "SIGTERM $round: every process has stopped within 20 s ($ms ms)"
    check '$py -c "import h5py, sys; m = h5py.File(sys.argv[1], \"r\").attrs[\"missing\"]; m = m.decode() if isinstance(m, bytes) else str(m); sys.exit(0 if \"interrupted\" in m else 1)" "$out/run.h5"' \
      "SIGTERM $round: run.h5 says incomplete and interrupted"
  fi
done
finish_run "$out" || true
check 'complete "$out/run.h5" && same "$out"' "stopped three times by SIGTERM and resumed: run.h5 equals the uninterrupted run's"
# 4a. SIGTERM with no synchronised time left in the run (checkpoint_interval
# 1000): the sim cuts between synchronised times, from its whole engine, and
# the resumed run equals the uninterrupted one with the same interval.
sed 's/^checkpoint_interval = 0.5/checkpoint_interval = 1000/' "$tmp/scene.toml" >"$tmp/far.toml"
bash "$root/launch_scripts/run_scene.sh" "$tmp/far.toml" --out "$tmp/ref_far" --run-id $run_id --no-build --no-plots \
  --test-node-delay 0.1 >"$tmp/ref_far.log" 2>&1
# The sim sleeps 0.1 s a frame (DYNHET_TEST_SIM_DELAY), so that the signal
# finds it in its production, not done and waiting for the nodes.
out=$tmp/term_far
for round in 1 2; do
  DYNHET_TEST_SIM_DELAY=0.1 start_run "$out" "$tmp/far.toml"
  t=$(( 1500 + RANDOM % 3000 ))
  sleep "$(printf '%d.%03d' $((t / 1000)) $((t % 1000)))"
  kill -TERM -- -$run_pid 2>/dev/null || true
  s0=$(date +%s%N)
  set +e; wait $run_pid; rc=$?; set -e
  ms=$(( ($(date +%s%N) - s0) / 1000000 ))
  echo "     SIGTERM at $t ms (no synchronised time ahead): exit $rc after $ms ms"
  if [[ -f $out/run.h5 ]] && ! complete "$out/run.h5"; then
    check '[[ $rc == 75 && $ms -lt 20000 ]]' "SIGTERM $round between synchronised times: exit 75 within 20 s (got $rc, $ms ms)"
    check 'grep -q "a checkpoint cut at t=.*\(between synchronised times\|before frame\)" "$out/sim_node.log"' \
      "SIGTERM $round: the sim cut between synchronised times"
  fi
done
finish_run "$out" "$tmp/far.toml" || true
check 'complete "$out/run.h5" && same "$out" "$tmp/ref_far"' \
  "stopped twice between synchronised times and resumed: run.h5 equals the uninterrupted run's"
# 4b. SIGTERM while the processes start: (a) the nodes up, the sim not yet;
# (b) a process launched and not yet seen ready (the script in a sleep: a
# group signal ends the sleep too, which under errexit had ended the script
# 143 before it looked at the signal). All stop, exit 75, nothing left
# running; the same command then runs it.
for pause in START READY; do
  out=$tmp/early_$pause
  export DYNHET_TEST_${pause}_PAUSE=4
  start_run "$out"
  if [[ $pause == START ]]; then
    for _ in $(seq 100); do grep -qs ready "$out/s4_node.log" && break; sleep 0.05; done
  else
    for _ in $(seq 100); do [[ -e $out/recorder.log ]] && break; sleep 0.05; done
  fi
  sleep 0.5
  kill -TERM -- -$run_pid 2>/dev/null || true
  s0=$(date +%s%N)
  set +e; wait $run_pid; rc=$?; set -e
  ms=$(( ($(date +%s%N) - s0) / 1000000 ))
  unset DYNHET_TEST_${pause}_PAUSE
  sleep 0.5
  left=$( (pgrep -f -- "$out/" || true) | wc -l)
  check '[[ $rc == 75 && $ms -lt 10000 && $left == 0 ]]' \
    "SIGTERM while the processes start ($pause pause): exit 75 (got $rc) after $ms ms, $left processes left"
  check 'grep -q "interrupted (SIGTERM) while the run.s processes started" "$out.log"' "... and says so"
  finish_run "$out" || true
  check 'complete "$out/run.h5" && same "$out"' "... and the same command then runs it: run.h5 equals the uninterrupted run's"
done

# 5. The newest whole cut corrupted: the one before is used.
out=$tmp/corrupt
start_run "$out"
sleep 3.5
kill -TERM -- -$run_pid 2>/dev/null || true
set +e; wait $run_pid; set -e
cuts=($(ls -d "$out"/checkpoints/cut-*/WHOLE 2>/dev/null | sed 's/\/WHOLE//'))
if ((${#cuts[@]} >= 2)); then
  frame=$(sed -n 's/^frame //p' "${cuts[-1]}/WHOLE")
  part=$out/checkpoints/frames/overlap-$((frame + 1)).part
  size=$(stat -c %s "$part")
  printf '\xff' | dd of="$part" bs=1 seek=$((size - 9)) conv=notrunc status=none
  finish_run "$out" || true
  check 'grep -q "refused: $part: corrupt" "$out.log"' "a corrupted part is refused, its file named"
  newest=$((10#${cuts[-1]##*cut-}))
  used=$(grep -o "resuming run $run_id from checkpoint cut [0-9]*" "$out.log" | tail -1 | awk '{print $NF}' || true)
  check '[[ -n $used && $used -lt $newest ]]' "an older whole cut is used (cut ${used:-none}, not $newest)"
  check 'complete "$out/run.h5" && same "$out"' "resumed from the older cut: run.h5 equals the uninterrupted run's"
else
  check false "two whole cuts before the corruption (got ${#cuts[@]})"
fi

# 6. The checkpoints' disk fills during the run.
out=$tmp/full
mkdir -p "$out/checkpoints" "$tmp/ckdisk"
mount -t tmpfs -o size=4m tmpfs "$tmp/ckdisk"
rmdir "$out/checkpoints"
ln -s "$tmp/ckdisk" "$out/checkpoints"
start_run "$out"
for _ in $(seq 100); do ls "$out"/checkpoints/cut-*/WHOLE >/dev/null 2>&1 && break; sleep 0.05; done
sleep 0.5
head -c 8m /dev/zero >"$tmp/ckdisk/filler" 2>/dev/null || true
sleep 1.5
kill -KILL -- -$run_pid 2>/dev/null || true
set +e; wait $run_pid; set -e
check 'grep -qh "NOT saved\|not taken" "$out"/*.log' "a cut on the full disk fails and says so"
rm -f "$tmp/ckdisk/filler"
finish_run "$out" || true
check 'complete "$out/run.h5" && same "$out"' "resumed from the cut before the disk filled: run.h5 equals the uninterrupted run's"
# 7. Recorded across an interruption: one log per segment; replay.sh plays
# the segments in order and gives the uninterrupted run's results. On a bus
# of its own: the log holds whatever its port carries, and a process of an
# earlier section still talking there (under load one did: 127 messages of
# another run's key) makes replay.sh refuse the log, as it must.
export LCM_DEFAULT_URL='udpm://239.255.76.67:7698?ttl=0'
out=$tmp/recorded
set -m
bash "$root/launch_scripts/run_scene.sh" "$tmp/scene.toml" --out "$out" --run-id $run_id --no-build --no-plots \
  --test-node-delay 0.1 --record "$tmp/seg.lcmlog" >>"$out.log" 2>&1 &
run_pid=$!
set +m
sleep 3
kill -TERM -- -$run_pid 2>/dev/null || true
set +e; wait $run_pid; set -e
bash "$root/launch_scripts/run_scene.sh" "$tmp/scene.toml" --out "$out" --run-id $run_id --no-build --no-plots \
  --test-node-delay 0.1 --record "$tmp/seg.lcmlog" >>"$out.log" 2>&1 || true
check '[[ -s $tmp/seg.lcmlog && -s $tmp/seg.lcmlog.2 ]]' "each segment has its log (seg.lcmlog, seg.lcmlog.2)"
bash "$root/launch_scripts/replay.sh" "$tmp/seg.lcmlog" "$tmp/seg.lcmlog.2" --out "$tmp/replayed" --no-build \
  --key-file "$out/bus.key" \
  >"$tmp/replayed.log" 2>&1 || true
check 'PYTHONPATH="$root/tests" $py -c "
import sys
from compare_runs import final_results, same
(a, la), (b, lb) = final_results(sys.argv[1]), final_results(sys.argv[2])
sys.exit(0 if same(a, b) and la == lb == 0 else 1)" "$tmp/ref/run.h5" "$tmp/replayed/run.h5"' \
  "the two segments replayed in order give the uninterrupted run's results bit for bit"

((fail == 0)) || { for f in "$tmp"/*.log; do echo "== $f"; tail -15 "$f"; done; }
exit $fail
