#!/usr/bin/env bash
# Re-runs the analysis of a recorded run from its lcm-logger log, at full
# speed, through LCM's file:// provider, into a new HDF5 file. The nodes
# read frames, run info and sim status from the log and publish their
# results on a private bus, where the recorder picks them up (run info and
# status it reads from the log too).
#
# Usage: launch_scripts/replay.sh LOG [LOG2 ...] --out DIR [--run-id ID] [--key-file KEY]
#                                 [--only-verified] [--analysis FILE.toml] [--no-build]
#        several logs: the segments of one run interrupted and resumed
#        (run_scene.sh --record LOG writes LOG, LOG.2, ...), in order; they
#        are played as one (a frame the next segment publishes again, from
#        its checkpoint cut, is the same frame and is taken once)
#        launch_scripts/replay.sh LOG --list    the runs in the log, and how
#                                               many of each run's frames it holds
# A log holding several runs needs --run-id. Before it starts, the replay
# says how many of the run's frames the log lacks; a replay of an
# incomplete log is itself marked incomplete.
#   --key-file KEY   the recorded run's key (default: bus.key beside the
#                    first LOG, where run_scene.sh --record DIR/LOG leaves
#                    it). Every message of the log is checked against it
#                    first (docs/bus.md): a log with any message that does
#                    not verify (no tag, a wrong one, a replayed copy) is
#                    refused, and the processes check each one again
#   --only-verified  instead, play only the messages that verify, and say
#                    how many did not
#   --fresh          DIR holds results of something else (a live run's
#                    run.h5 and logs, another replay; refused without it):
#                    move them into DIR/old-<time>/ first (nothing is deleted).
#                    A replay of the same LOGs into the DIR it wrote before
#                    replays again without it
# Exit: 0 replayed; 1 a process failed; 2 bad arguments, a log refused or a
# refused DIR (nothing written); 130 interrupted (the same command replays
# again). The last line says where and the exit.
#   --analysis FILE  re-analyse the run with another analysis section: FILE
#                    is a TOML of analysis tables and keys only ([observables]
#                    compute, cutoff_a, cage_relative, cage; [overlap], [chi4],
#                    [s4], [clusters], [msd], [displacement], [bond_breaking])
#                    that replace the recorded scene's for the nodes and the
#                    recorder. What decided the recorded frames ([system],
#                    [driving], [run], [schedule], [transport],
#                    observables.keep_frames) is refused by name (exit 2)
#                    before anything runs. The new run.h5's parameters/ hold
#                    the changed scene, and parameters/reanalysis says whose
#                    re-analysis it is (of_run_id, the file and its text, the
#                    recorded scene). At the recorded settings the results
#                    equal the live run's bit for bit. Messages are checked
#                    against the run's key all the same
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$root/build}
bin=$build/bin

log="" out="" build_first=1 run_id="" list=0 segments=() key_file="" only_verified=0 checked=0 fresh=0 analysis=""
while (($#)); do
  case "$1" in
  --out) out=$2; shift 2 ;;
  --no-build) build_first=0; shift ;;
  --run-id) run_id=$2; shift 2 ;;
  --key-file) key_file=$2; shift 2 ;;
  --only-verified) only_verified=1; shift ;;
  --fresh) fresh=1; shift ;;
  --analysis) analysis=$2; shift 2 ;;
  --log-checked) checked=1; shift ;; # internal: the first pass checked LOG (the re-run in the namespace)
  --list) list=1; shift ;;
  -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;;
  -*) echo "replay: unknown option $1" >&2; exit 2 ;;
  *) segments+=("$1"); shift ;;
  esac
done
for s in "${segments[@]}"; do [[ -f $s ]] || { echo "replay: no log file $s" >&2; exit 2; }; done
# DIR may hold a replay of these same logs (its REPLAY file names them),
# which this one replaces; results of anything else are refused, or moved
# aside with --fresh. (The re-run inside the namespace comes after this.)
if [[ -n $out && $list == 0 && $checked == 0 ]]; then
  source "$root/launch_scripts/lib/out_dir.sh"
  mapfile -t there < <(held "$out" run.h5 checkpoint.h5 checkpoint_before_frames.h5 checkpoints scene.toml '*.log' '*.png' \
    segments.lcmlog verified.lcmlog)
  replay_of=$(for s in "${segments[@]}"; do realpath -m "$s"; done)
  if ((${#there[@]})) && ! { [[ -f $out/REPLAY ]] && [[ $(cat "$out/REPLAY") == "$replay_of" ]]; }; then
    if ((fresh)); then
      [[ ! -f $out/REPLAY ]] || there+=(REPLAY)
      to=$(move_aside "$out" "${there[@]}")
      echo "replay: --fresh: what $out held (${there[*]}) moved to $to" >&2
    else
      what="results that are not a replay of $(paste -sd' ' <<<"$replay_of")"
      [[ ! -f $out/scene.toml ]] || what="a run's results (scene.toml: a live run, not a replay)"
      echo "replay: refused: $out holds $what: ${there[*]}" >&2
      echo "replay: nothing was written; give another --out, or add --fresh to move them into $out/old-<time>/ (nothing is deleted)" >&2
      exit 2
    fi
  fi
  mkdir -p "$out"
  printf '%s\n' "$replay_of" >"$out/REPLAY"
fi
if ((${#segments[@]} == 1)); then
  log=${segments[0]}
elif ((${#segments[@]} > 1)); then
  [[ -n $out || $list == 1 ]] || { echo "usage: replay.sh LOG [LOG2 ...] --out DIR [--run-id ID]" >&2; exit 2; }
  # lcm-logger logs are sequences of events: the segments, one after the
  # other, are one log (kept as DIR/segments.lcmlog).
  if ((list)); then joined=$(mktemp --suffix=.lcmlog); else mkdir -p "$out"; joined=$out/segments.lcmlog; fi
  cat "${segments[@]}" >"$joined"
  echo "replay: ${#segments[@]} segments, played in order as one log ($joined)" >&2
  log=$joined
fi
[[ -n $log ]] || { echo "usage: replay.sh LOG --out DIR [--run-id ID] | replay.sh LOG --list" >&2; exit 2; }
[[ -f $log ]] || { echo "replay: no log file $log" >&2; exit 2; }
runs=$root/launch_scripts/lcmlog_runs.py
if ((list)); then exec /usr/bin/python3 "$runs" "$log"; fi
[[ -n $out ]] || { echo "usage: replay.sh LOG --out DIR [--run-id ID]" >&2; exit 2; }
# A re-analysis: what the file may not change is refused before anything
# is written (the recorder applies it to the run info of the log, as every
# process of the replay will).
if [[ -n $analysis ]]; then
  [[ -f $analysis ]] || { echo "replay: no analysis file $analysis" >&2; exit 2; }
  analysis=$(cd "$(dirname "$analysis")" && pwd)/$(basename "$analysis")
  if ((checked == 0)); then
    ((build_first)) && { BUILD_DIR=$build "$root/launch_scripts/setup.sh"; build_first=0; }
    "$bin/recorder" --list-nodes "$log" --analysis "$analysis" ${run_id:+--run-id "$run_id"} >/dev/null ||
      { echo "replay: refused: $analysis cannot re-analyse the run of $log" >&2; exit 2; }
  fi
fi
# With --only-verified the run is chosen among the messages that verify
# (a log of two runs, with one run's key, is then that run's).
if [[ -z $run_id && $only_verified == 0 ]]; then
  run_id=$(/usr/bin/python3 "$runs" "$log" --only) || exit 2
fi
# The recorded run's key: every message of the log is checked against it.
if [[ -z $key_file ]]; then
  key_file=$(dirname "${segments[0]}")/bus.key
  [[ -f $key_file ]] || { echo "replay: no key for ${segments[0]}: give the recorded run's key with --key-file (run_scene.sh wrote it to the run's DIR/bus.key)" >&2; exit 2; }
fi
key_file=$(cd "$(dirname "$key_file")" && pwd)/$(basename "$key_file")
if ((checked == 0)); then # on the first pass, wherever it runs (inside a namespace too)
  mkdir -p "$out"
  if ((only_verified)); then
    verified=$(cd "$out" && pwd)/verified.lcmlog
    said=$(/usr/bin/python3 "$root/launch_scripts/lcmlog_verify.py" "$log" --key-file "$key_file" --keep "$verified") && rc=0 || rc=$?
    ((rc <= 1)) || { echo "replay: $said" >&2; exit 2; }
    echo "replay: $log: $said; playing only those that verify ($verified)" >&2
    log=$verified
  else
    said=$(/usr/bin/python3 "$root/launch_scripts/lcmlog_verify.py" "$log" --key-file "$key_file") && rc=0 || rc=$?
    if ((rc != 0)); then
      echo "replay: $log: $said" >&2
      ((rc != 1)) || echo "replay: refused: the log holds messages that do not verify with $key_file (--only-verified plays the rest)" >&2
      exit 2
    fi
    echo "replay: $log: $said" >&2
  fi
fi
if [[ -z $run_id ]]; then
  run_id=$(/usr/bin/python3 "$runs" "$log" --only) || exit 2
fi
summary=$(/usr/bin/python3 "$runs" "$log" --run-id "$run_id") || exit 2
echo "replay: $summary" >&2
read -r whole expected < <(sed -E 's/.*, ([0-9]+) of ([0-9]+) frames.*/\1 \2/' <<<"$summary")
if ((whole < expected)); then
  echo "replay: the log lacks $((expected - whole)) of $expected frames of run $run_id: the replay will be incomplete" >&2
fi
log=$(cd "$(dirname "$log")" && pwd)/$(basename "$log")
mkdir -p "$out"
out=$(cd "$out" && pwd)

if [[ -z ${DYNHET_IN_NETNS:-} ]]; then
  ((build_first)) && BUILD_DIR=$build "$root/launch_scripts/setup.sh"
  exec "$root/launch_scripts/netns.sh" "$0" "$log" --out "$out" --run-id "$run_id" --key-file "$key_file" --no-build \
    --log-checked ${analysis:+--analysis "$analysis"}
fi

# Which nodes ran: the observables named in the run info of the log. The
# scene text is in the log; nodes are found by their results channels.
# From here the last line says where the results are and how it ended.
trap 'rc=$?; [[ -z ${rec:-} ]] || kill "$rec" 2>/dev/null || true
  case $rc in 0 | 1 | 2 | 130) ;; *) rc=1 ;; esac; echo "replay: results in $out (exit $rc)" >&2; exit $rc' EXIT
trap 'echo "replay: interrupted" >&2; exit 130' INT TERM
reanalysis=()
[[ -z $analysis ]] || reanalysis=(--analysis "$analysis")
nodes=$("$bin/recorder" --list-nodes "$log" --run-id "$run_id" "${reanalysis[@]}") || { echo "replay: cannot read run info from $log" >&2; exit 1; }
bus="udpm://239.255.76.67:7670?ttl=0&recv_buf_size=4194304"

"$bin/recorder" --lcm-url "$bus" --from-log "$log" --out "$out/run.h5" --run-id "$run_id" --key-file "$key_file" --bus-epoch any \
  "${reanalysis[@]}" 2>"$out/recorder.log" &
rec=$!
for _ in $(seq 100); do grep -q ready "$out/recorder.log" && break; sleep 0.1; done
status=0
for n in $nodes; do
  "$bin/$n" --lcm-url "file://$log?speed=0" --publish-url "$bus" --run-id "$run_id" --key-file "$key_file" --bus-epoch any \
    "${reanalysis[@]}" 2>"$out/$n.log" || {
    echo "replay: $n failed; log $out/$n.log" >&2; tail -3 "$out/$n.log" >&2; status=1; }
done
wait $rec || { echo "replay: recorder failed; log $out/recorder.log" >&2; tail -3 "$out/recorder.log" >&2; status=1; }
rec=""
grep -h -E "tau_alpha|frames whole" "$out"/*_node.log >&2 || true
if [[ -f $out/run.h5 ]]; then
  # every observable's figure that the run has, and overlap.png, in one
  # process (as run_scene.sh draws them)
  /usr/bin/python3 "$root/launch_scripts/plot_run.py" "$out/run.h5" "$out" || status=1
fi
exit $status
