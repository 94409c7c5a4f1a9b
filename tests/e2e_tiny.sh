#!/usr/bin/env bash
# The tiny scene end to end over LCM (sim_node, overlap_node, clusters_node, s4_node, recorder,
# each in a private network namespace), recorded with lcm-logger; the HDF5
# file is checked against brute-force results from its own frames and
# against H5MD's rules (tests/check_h5md.py, with the author given by
# --author); then the log is replayed twice through file:// (the author from
# DYNHET_AUTHOR, the second replay's file checked against H5MD's rules too)
# and the Q(t) of the replays must equal the live one bit for bit (when no
# frame was lost live) and each other.
set -euo pipefail
root=$1 build=$2
tmp=$(mktemp -d)
trap 'rc=$?; ((rc)) && { echo "e2e: lcm-logger said:"; cat "$tmp/live/lcm-logger.log"; }; rm -rf "$tmp"' EXIT
export BUILD_DIR=$build

# lcm-logger drops messages beyond its subscription queue (30 messages,
# not settable from its command line) when the machine starves it: under
# the full test suite on 2 cores it sometimes misses a frame chunk of the
# tiny scene's bursts. A log that misses frames cannot replay bit for bit,
# so then the live run and its recording are repeated (at most 3 times);
# what the live run lost, if anything, still fails the checks.
for attempt in 1 2 3; do
  rm -rf "$tmp/live" "$tmp/replay1" "$tmp/run.lcmlog" # (a recording is never written over: each attempt its own)
  bash "$root/launch_scripts/run_scene.sh" "$root/scenes/tiny.toml" --out "$tmp/live" \
    --url 'udpm://239.255.76.67:7681?ttl=0' --record "$tmp/run.lcmlog" --no-build --author "E2E Tester"
  /usr/bin/python3 "$root/tests/check_run.py" "$tmp/live/run.h5" "$root/scenes/tiny.toml"
  /usr/bin/python3 "$root/tests/check_h5md.py" "$tmp/live/run.h5" --author "E2E Tester"
  [[ -s $tmp/live/overlap.png && -s $tmp/live/chi4.png && -s $tmp/live/msd.png && -s $tmp/live/displacement.png &&
     -s $tmp/live/clusters.png && -s $tmp/live/s4.png ]] || { echo "FAIL: no plot"; exit 1; }
  if DYNHET_AUTHOR="E2E Replay" bash "$root/launch_scripts/replay.sh" "$tmp/run.lcmlog" --out "$tmp/replay1" --no-build \
    --key-file "$tmp/live/bus.key"; then
    break
  fi
  grep -q "lost by the recorder" "$tmp/replay1/recorder.log" 2>/dev/null ||
    { echo "FAIL: replay failed, and not for a short log"; exit 1; }
  ((attempt < 3)) || { echo "FAIL: lcm-logger missed frames in 3 recordings"; exit 1; }
  echo "e2e: lcm-logger missed frames (attempt $attempt):"; grep "lost" "$tmp/replay1/recorder.log"
done

DYNHET_AUTHOR="E2E Replay" bash "$root/launch_scripts/replay.sh" "$tmp/run.lcmlog" --out "$tmp/replay2" --no-build \
  --key-file "$tmp/live/bus.key"
/usr/bin/python3 "$root/tests/check_h5md.py" "$tmp/replay2/run.h5" --author "E2E Replay"
/usr/bin/python3 "$root/tests/compare_runs.py" "$tmp/live/run.h5" "$tmp/replay1/run.h5" "$tmp/replay2/run.h5"
echo PASS
