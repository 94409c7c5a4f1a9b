#!/usr/bin/env bash
# LCM's own player, unfiltered: a tiny run is recorded (run_scene.sh
# --record), then its FULL log (every channel, the old results and statuses
# too) is played with lcm-logplayer onto a bus where a recorder listens,
# (a) alone, (b) with the analysis nodes, which compute every result again
# while the logged ones arrive. Each file must be complete and hold one
# series per result: in every time series the steps strictly increase and
# are those of the live run, and every value equals the live run's, bit for
# bit (in (b) but the nodes' wall-clock times). In a private network
# namespace.
set -euo pipefail
root=$1 build=$2
[[ ${DYNHET_IN_NETNS:-} == 1 ]] || exec "$root/launch_scripts/netns.sh" bash "$0" "$@"
export BUILD_DIR=$build
source "$root/tests/processes.sh"
id=4343
# Whether every result message a recorder took from the bus (its log's
# 'messages received per channel') is also in an lcm log, or the other way
# round: lacks FROM TO prints what FROM has on a result channel that TO lacks.
result_counts() { # recorder.log | LOG.lcmlog: 'CHANNEL COUNT' lines of the result channels
  if [[ $1 == *.lcmlog ]]; then $py "$root/launch_scripts/lcmlog_runs.py" "$1" --channels
  else sed -n 's/^recorder: messages received per channel: //p' "$1" | tr ',' '\n' | sed 's/^ //'; fi |
    grep -E '^DYNHET_(OVERLAP|CHI4|MSD|DISPLACEMENT|CLUSTERS|S4)' || true
}
lacks() { # FROM TO
  join -a1 -e0 -o 0,1.2,2.2 <(result_counts "$1" | sort) <(result_counts "$2" | sort) | awk '$3 < $2 { printf "%s %d of %d; ", $1, $3, $2 }'
}
# lcm-logger drops what overflows its 30-message subscription queue when
# the machine starves it (tests/e2e_tiny.sh): a log that misses a frame or a
# result the live recorder took cannot replay complete, so the recording is
# repeated (at most 3 times).
for attempt in 1 2 3; do
  rm -rf "$tmp/live" "$tmp/run.lcmlog"
  bash "$root/launch_scripts/run_scene.sh" "$root/scenes/tiny.toml" --no-build --no-plots --run-id $id \
    --url 'udpm://239.255.76.67:7731?ttl=0' --out "$tmp/live" --record "$tmp/run.lcmlog" >"$tmp/live.log" 2>&1 ||
    { echo "FAIL the live run"; tail -5 "$tmp/live.log"; exit 1; }
  held=$($py "$root/launch_scripts/lcmlog_runs.py" "$tmp/run.lcmlog" --run-id $id)
  missed=$(lacks "$tmp/live/recorder.log" "$tmp/run.lcmlog")
  [[ $held =~ \ ([0-9]+)\ of\ ([0-9]+)\ frames ]] && [[ ${BASH_REMATCH[1]} == "${BASH_REMATCH[2]}" && -z $missed ]] && break
  ((attempt < 3)) || { echo "FAIL lcm-logger missed messages in 3 recordings: $held; results: ${missed:-none}"; exit 1; }
  echo "    lcm-logger missed messages (attempt $attempt): $held; results: ${missed:-none missed}"
done
[[ -n $(result_counts "$tmp/live/recorder.log") ]] || { echo "FAIL the recorder says no messages per channel"; exit 1; }
nodes=$("$bin/recorder" --list-nodes "$tmp/run.lcmlog")
# The recorded run's key: the played messages carry its tags, of the live
# run's launch (--bus-epoch any: a played log is not this launch's).
export DYNHET_KEY_FILE=$tmp/live/bus.key
export LCM_DEFAULT_URL='udpm://239.255.76.67:7732?ttl=0&recv_buf_size=4194304'

play() { # out dir, then the nodes to start: the recorder listens, the whole log is played
  local out=$1 rec rc; shift
  for attempt in 1 2 3; do
    rm -rf "$out" && mkdir -p "$out"
    start "$out/recorder.log" "$bin/recorder" --out "$out/run.h5" --run-id $id --bus-epoch any
    rec=${pids[-1]}
    for n in "$@"; do start "$out/$n.log" "$bin/$n" --run-id $id --bus-epoch any; done
    lcm-logplayer --lcm-url="$LCM_DEFAULT_URL" "$tmp/run.lcmlog" >"$out/player.log" 2>&1
    wait "$rec" && rc=0 || rc=$?
    # The bus may lose a played datagram on a starved machine too: the
    # test is of the recorder, given what the log holds.
    (($#)) || [[ -z $(lacks "$tmp/run.lcmlog" "$out/recorder.log") ]] && return $rc
    ((attempt < 3)) || { echo "    the recorder lacks played results 3 times: $(lacks "$tmp/run.lcmlog" "$out/recorder.log")"; return $rc; }
    echo "    the recorder lacks played results (attempt $attempt): $(lacks "$tmp/run.lcmlog" "$out/recorder.log")"
  done
}
# Every time series of the replayed file against the live one.
same_series() { # live.h5 replay.h5 [series to compare by steps only]
  $py - "$@" <<'PY'
import sys
import h5py
import numpy as np
live, rep, loose = h5py.File(sys.argv[1], "r"), h5py.File(sys.argv[2], "r"), sys.argv[3:]
names = []
rep.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Group) and "step" in o and "value" in o else None)
bad = []
for n in names:
    step = rep[n]["step"][()]
    if len(step) > 1 and not (np.diff(step) > 0).all():
        bad.append(f"{n}: steps do not strictly increase")
    elif n not in live or not np.array_equal(live[n]["step"][()], step):
        bad.append(f"{n}: {len(step)} records, steps unlike the live run's")
    elif not any(n.endswith(x) for x in loose):
        a, b = live[n]["value"][()], rep[n]["value"][()]
        if not np.array_equal(a, b, equal_nan=a.dtype.kind == "f"):
            bad.append(f"{n}: values differ from the live run's")
print(f"    {len(names)} time series, {len(bad)} wrong, complete {int(rep.attrs['complete'])}", *bad[:10], sep="\n    ")
sys.exit(0 if names and not bad and int(rep.attrs["complete"]) == 1 else 1)
PY
}

play "$tmp/alone" && rc=0 || rc=$?
check '[[ $rc == 0 ]] && same_series "$tmp/live/run.h5" "$tmp/alone/run.h5"' \
  "the full log into a recorder alone: complete, one series per result, equal to the live run (exit $rc)"
# shellcheck disable=SC2086
play "$tmp/nodes" $nodes && rc=0 || rc=$?
check '[[ $rc == 0 ]] && same_series "$tmp/live/run.h5" "$tmp/nodes/run.h5" /wall_time' \
  "the full log into a recorder and live nodes ($nodes): complete, one series per result, equal to the live run (exit $rc)"
((fail == 0)) || tail -n 5 "$tmp"/*/recorder.log
exit $fail
