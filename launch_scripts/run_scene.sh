#!/usr/bin/env bash
# Runs a scene end to end: the sim, the analysis nodes the scene needs and
# the recorder, then plots. The whole pipeline checkpoints as it goes
# (DIR/checkpoints, docs/checkpoints.md): the same command on the same
# --out DIR resumes an interrupted run from its last whole cut, bit for bit.
# Exit: 0 complete; 1 the run failed; 2 bad arguments or a refused --out
# (nothing written); 75 interrupted and resumable (SIGTERM/SIGINT, or a
# process died: run the same command again); 130 interrupted, not
# resumable (--no-checkpoints). The last line says where and the exit.
#
# Usage: launch_scripts/run_scene.sh SCENE.toml [options]
#   --out DIR       where run.h5, plots and logs go (default runs/<scene>-<time>);
#                   a DIR that holds an interrupted run of the same scene is
#                   resumed from its last whole checkpoint cut; a DIR that
#                   holds anything else of a run (a run.h5 without its
#                   scene.toml, a run of another scene) is refused
#   --fresh         start over in DIR: what it holds of an earlier run (run.h5,
#                   checkpoints, logs, plots, key) is moved into DIR/old-<time>/,
#                   never deleted
#   --no-checkpoints  no checkpoint cuts (the run cannot be resumed)
#   --bus private   (default) a private network namespace: no packet leaves
#                   the machine, nothing else on the host sees the run
#   --bus host      this host's LCM bus ($LCM_DEFAULT_URL, else
#                   udpm://239.255.76.67:7667?ttl=0): lcm-spy (spy.sh) on this
#                   host can watch; no packet leaves the host
#   --bus lan       the LAN's bus (ttl=1): other hosts can watch, or run the
#                   analysis (--role); receive buffers of 4 MiB
#   --bus tcpq      lossless: LCM's TCP hub (lcm.lcm.TCPService, from
#                   liblcm-java) on a free loopback port of a private network
#                   namespace, every process connected to it (tcpq://); the
#                   hub holds a publisher back instead of dropping (README,
#                   "Transport"). For a hub of your own: --bus host --url
#                   tcpq://127.0.0.1:PORT
#   --role R        all (default): sim, nodes and recorder here; analysis:
#                   the nodes and the recorder only (results and plots here);
#                   sim: the sim only. Start the analysis on one host and the
#                   sim on another, both with --bus lan, the same scene and
#                   the same --run-id (README, "Several hosts")
#   --url URL       LCM URL (default udpm://239.255.76.67:7667?ttl=0, and
#                   ttl=1 with --bus lan)
#   --record LOG    also record everything with lcm-logger into LOG (a
#                   resumed run records its segment into LOG.2, LOG.3, ...)
#   --no-build      skip setup.sh (packages and build)
#   --no-plots      write run.h5 only, no PNGs (plot later with
#                   launch_scripts/plot_<observable>.py RUN.h5 OUT.png)
#   --resume CKPT   continue the run saved in checkpoint CKPT (instead of a
#                   scene) with fresh nodes and recorder: use the run's
#                   checkpoint_before_frames.h5 (the last one before its
#                   first frame, which every run keeps), so that the nodes
#                   see every frame; the result equals the uninterrupted run
#   --run-id ID     the run's id (default: random; with --resume, the
#                   checkpoint's). Sim, nodes and recorder all get it, so
#                   they take only this run's messages: two runs on one bus
#                   never cross
#   --key-file KEY  the run's key (default DIR/bus.key, created when missing:
#                   32 random bytes, mode 0600). Every process tags each
#                   message it publishes with it and drops every message
#                   whose tag does not verify (docs/bus.md). A run split over
#                   hosts (--role) needs the same key on both: copy the
#                   analysis host's DIR/bus.key to the sim's host (scp -p,
#                   keeping mode 0600) and give it there with --key-file
#   --bus-epoch E   this launch's number, carried in every message's tag
#                   (default: drawn at random at each start and resume on
#                   one host, so that a message recorded in one segment of
#                   a run cannot be replayed into the next; 0 with --role,
#                   unless both hosts are given the same E)
#   --author NAME   run.h5's h5md/author name (default: $DYNHET_AUTHOR,
#                   else $USER, else "unknown")
#   --author-email ADDRESS  run.h5's h5md/author email (default: none)
set -euo pipefail
# A signal before the run's processes start (checking the scene, finding
# the last whole cut: seconds on a busy machine) changes nothing that the
# same command cannot take up again: interrupted, resumable. (Bash's
# default ended the script 143, and a study or a Slurm job read that as a
# failure.) The traps below take over once the processes run.
trap 'echo "run_scene: interrupted before the run started; the same command starts or resumes it" >&2; exit 75' TERM INT
root=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$root/build}
bin=$build/bin

scene="" out="" bus=private url="" record="" build_first=1 plots=1 resume="" run_id="" role=all author="" author_email=""
key_file="" bus_epoch=""
fresh=0 no_cuts=0 test_node_delay=${DYNHET_TEST_NODE_DELAY:-} test_sim_delay=${DYNHET_TEST_SIM_DELAY:-}
while (($#)); do
  case "$1" in
  --out) out=$2; shift 2 ;;
  --fresh) fresh=1; shift ;;
  --no-checkpoints) no_cuts=1; shift ;;
  --test-node-delay) test_node_delay=$2; shift 2 ;; # tests: seconds of sleep per frame in every node
  --bus) bus=$2; shift 2 ;;
  --url) url=$2; shift 2 ;;
  --record) record=$2; shift 2 ;;
  --no-build) build_first=0; shift ;;
  --no-plots) plots=0; shift ;;
  --resume) resume=$2; shift 2 ;;
  --run-id) run_id=$2; shift 2 ;;
  --key-file) key_file=$2; shift 2 ;;
  --bus-epoch) bus_epoch=$2; shift 2 ;;
  --role) role=$2; shift 2 ;;
  --author) author=$2; shift 2 ;;
  --author-email) author_email=$2; shift 2 ;;
  -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;;
  -*) echo "run_scene: unknown option $1" >&2; exit 2 ;;
  *) [[ -z $scene ]] || { echo "run_scene: one scene only" >&2; exit 2; }; scene=$1; shift ;;
  esac
done
if [[ -n $resume ]]; then
  [[ -z $scene ]] || { echo "run_scene: give a scene or --resume CHECKPOINT, not both" >&2; exit 2; }
  [[ -f $resume ]] || { echo "run_scene: no checkpoint $resume" >&2; exit 2; }
  resume=$(cd "$(dirname "$resume")" && pwd)/$(basename "$resume")
  sim_input=(--resume "$resume")
else
  [[ -n $scene ]] || { echo "usage: run_scene.sh SCENE.toml [--out DIR] [--bus private|host|lan|tcpq] [--url URL] [--record LOG] [--resume CKPT] (--help: all options)" >&2; exit 2; }
  [[ -f $scene ]] || { echo "run_scene: no scene file $scene" >&2; exit 2; }
  sim_input=("$scene")
fi
[[ $bus == private || $bus == host || $bus == lan || $bus == tcpq ]] || { echo "run_scene: --bus is private, host, lan or tcpq, not $bus" >&2; exit 2; }
[[ $bus != tcpq || -z $url ]] || { echo "run_scene: --bus tcpq starts its own hub; for a hub of yours use --bus host --url tcpq://HOST:PORT" >&2; exit 2; }
[[ $bus != tcpq || $role == all ]] || { echo "run_scene: --bus tcpq is a private bus; across hosts use --url tcpq://HUB:PORT" >&2; exit 2; }
[[ $role == all || $role == sim || $role == analysis ]] || { echo "run_scene: --role is all, sim or analysis, not $role" >&2; exit 2; }
if [[ $role != all ]]; then
  [[ $bus == lan || -n $url ]] || { echo "run_scene: --role $role splits a run over hosts: use --bus lan (or --url)" >&2; exit 2; }
  [[ -n $run_id || -n $resume ]] || { echo "run_scene: --role $role needs --run-id ID, the same on both hosts" >&2; exit 2; }
fi

if ((build_first)) && [[ -z ${DYNHET_IN_NETNS:-} ]]; then BUILD_DIR=$build "$root/launch_scripts/setup.sh"; fi

# What --out DIR may already hold: the run this command resumes (DIR's
# scene.toml is this scene, checkpoint cuts on) or continues (--resume from
# DIR's own checkpoint, its run.h5 not complete). Anything else of a run
# that it would write over is refused, naming it; --fresh moves it into
# DIR/old-<time>/ first (and the scene or checkpoint to run from, if it was
# among it, is read from there).
source "$root/launch_scripts/lib/out_dir.sh"
guard_out() {
  local own=0 why="" there=() move=() to f
  [[ ! -e $out || -d $out ]] || { echo "run_scene: --out $out is a file, not a directory" >&2; exit 2; }
  if [[ $role == all && -z $resume && $no_cuts == 0 && -f $out/scene.toml ]] && cmp -s "$scene" "$out/scene.toml"; then own=1; fi
  [[ -z $resume || $(realpath -m "$(dirname "$resume")") != "$(realpath -m "$out")" ]] || own=1
  mapfile -t there < <(held "$out" run.h5 checkpoint.h5 checkpoint_before_frames.h5 checkpoints scene.toml '*.log' '*.png' |
    grep -vx run_scene.log) # (run_scene.log: a study's log of its calls, open while this runs)
  # (an empty checkpoints/ holds nothing: one may be made beforehand, e.g. a link to another disk)
  [[ -n $(ls -A "$out/checkpoints/" 2>/dev/null) ]] || mapfile -t there < <(printf '%s\n' "${there[@]}" | grep -vx -e checkpoints -e '')
  if ((${#there[@]})); then
    if ((own)); then
      [[ -z $resume ]] || ! complete_run "$out/run.h5" || why="a complete run, which --resume would compute again"
    elif [[ -n $scene && -f $out/scene.toml ]] && ! cmp -s "$scene" "$out/scene.toml"; then
      /usr/bin/python3 "$root/launch_scripts/scene_diff.py" "$out/scene.toml" "$scene" >&2 || true
      why="a run of another scene (the keys that differ above)"
    elif [[ -f $out/scene.toml ]]; then
      why="a run of this scene that this command would start over, not resume (it resumes with checkpoint cuts on, --role all)"
    else
      why="results of a run without the scene.toml that says which (not written by run_scene.sh for this scene)"
    fi
  fi
  if [[ -n $record && -e $record ]] && ((!own)); then
    why+="${why:+; and }--record $record exists"
  fi
  if [[ -n $why ]] && ((!fresh)); then
    echo "run_scene: refused: $out holds $why: ${there[*]:-}" >&2
    echo "run_scene: nothing was written; give another --out, or add --fresh to move what it holds into $out/old-<time>/ (nothing is deleted)" >&2
    exit 2
  fi
  ((fresh)) || return 0
  # --fresh: the earlier run moves aside whole (with the scene it ran, which
  # stays in place when it is the scene to run now, a study's run directory)
  for f in "${there[@]}"; do
    [[ $f == scene.toml && $(realpath -m "${scene:-/}") == "$(realpath -m "$out/scene.toml")" ]] || move+=("$f")
  done
  [[ -n $key_file || ! -e $out/bus.key ]] || move+=(bus.key) # a new run, a new key
  if ((${#move[@]})); then
    to=$(move_aside "$out" "${move[@]}")
    [[ ! -f $out/scene.toml || " ${move[*]} " == *" scene.toml "* ]] || cp -p "$out/scene.toml" "$to/"
    [[ -z $resume || ! -e $to/$(basename "$resume") || -e $resume ]] || resume=$to/$(basename "$resume")
    echo "run_scene: --fresh: the earlier run in $out (${move[*]}) moved to $to" >&2
  fi
  if [[ -n $record && -e $record ]] && ((!own)); then
    to=$record.old-$(date +%Y%m%d-%H%M%S)
    mv -- "$record" "$to"
    echo "run_scene: --fresh: the earlier log $record moved to $to" >&2
  fi
  return 0
}

# Refuse a bad scene before anything starts.
check=$("$bin/sim_node" "${sim_input[@]}" --check) || exit 2
nodes=$(sed -n 's/^nodes: *//p' <<<"$check")

name=$(basename "${scene:-$resume}" .toml)
name=${name%.h5}
out=${out:-$root/runs/$name-$(date +%Y%m%d-%H%M%S)}
guard_out
[[ -z $resume ]] || sim_input=(--resume "$resume") # (moved aside with the run it belongs to)
mkdir -p "$out"
out=$(cd "$out" && pwd)
[[ -z $record ]] || record=$(cd "$(dirname "$record")" && pwd)/$(basename "$record")

if [[ ($bus == private || $bus == tcpq) && -z ${DYNHET_IN_NETNS:-} ]]; then
  args=(--out "$out" --bus "$bus" --no-build)
  ((plots)) || args+=(--no-plots)
  [[ -z $resume ]] || args+=(--resume "$resume")
  [[ -z $url ]] || args+=(--url "$url")
  [[ -z $record ]] || args+=(--record "$record")
  [[ -z $run_id ]] || args+=(--run-id "$run_id")
  [[ -z $key_file ]] || args+=(--key-file "$(realpath -m "$key_file")")
  [[ -z $bus_epoch ]] || args+=(--bus-epoch "$bus_epoch")
  [[ -z $author ]] || args+=(--author "$author")
  [[ -z $author_email ]] || args+=(--author-email "$author_email")
  ((fresh == 0)) || args+=(--fresh)
  ((no_cuts == 0)) || args+=(--no-checkpoints)
  [[ -z $test_node_delay ]] || args+=(--test-node-delay "$test_node_delay")
  exec "$root/launch_scripts/netns.sh" "$0" ${scene:+"$scene"} "${args[@]}"
fi

pids=() names=() reaped=()
# On every exit from here: the run's processes stopped (lcm-logger too: an
# early exit left it recording), and the last line says where the results
# are and how it ended, with one of the exit codes above (an unforeseen
# failure of a command of this script is the run's failure, 1).
cleanup() {
  local rc=$?
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  [[ -z ${logger_pid:-} ]] || kill -INT "$logger_pid" 2>/dev/null || true
  [[ -z ${hub_pid:-} ]] || kill "$hub_pid" 2>/dev/null || true
  case $rc in 0 | 1 | 2 | 75 | 130) ;; *) rc=1 ;; esac
  echo "run_scene: results in $out (exit $rc)" >&2
  exit "$rc"
}
trap cleanup EXIT

# Checkpoint cuts of the whole pipeline (one host, a scene given): a run
# interrupted in DIR resumes from its last whole cut.
cuts="" cut_args=() resume_cut=()
if [[ $role == all && -z $resume && $no_cuts == 0 ]]; then
  cuts=$out/checkpoints
  # (a DIR holding a run of another scene was refused, or moved aside by --fresh, above)
  if [[ -f $out/run.h5 && -f $out/scene.toml ]] && complete_run "$out/run.h5"; then
    echo "run_scene: $out/run.h5 is complete: nothing to resume (--fresh moves it aside and starts over)" >&2
    exit 0
  fi
  cp "$scene" "$out/scene.toml.tmp" && mv "$out/scene.toml.tmp" "$out/scene.toml"
  cut_args=(--checkpoint-dir "$cuts")
  if [[ -d $cuts ]]; then
    set +e
    found=$("$bin/sim_node" "$scene" --checkpoint-dir "$cuts" --find-cut 2>"$out/find_cut.log")
    set -e
    sed 's/^sim_node: /run_scene: /' "$out/find_cut.log" >&2
    if [[ $found =~ ^cut\ ([0-9]+)\ frame\ (-?[0-9]+)\ time\ ([^ ]+)\ run_id\ ([0-9]+) ]]; then
      cut=${BASH_REMATCH[1]}
      [[ -z $run_id || $run_id == "${BASH_REMATCH[4]}" ]] || { echo "run_scene: --run-id $run_id, but $out holds run ${BASH_REMATCH[4]}" >&2; exit 2; }
      run_id=${BASH_REMATCH[4]}
      resume_cut=(--resume-cut "$cut")
      # Cuts after it were refused or never whole: they go.
      for d in "$cuts"/cut-*; do
        n=$((10#${d##*cut-}))
        ((n > cut)) && rm -rf "$d"
      done
      echo "run_scene: resuming run $run_id from checkpoint cut $cut: frames up to ${BASH_REMATCH[2]} done, t = ${BASH_REMATCH[3]}; what came after it is computed again" >&2
    else
      echo "run_scene: no whole checkpoint cut in $cuts: starting the run from the beginning" >&2
      rm -rf "$cuts"/cut-* "$cuts"/frames "$cuts"/recorder.journal
    fi
  fi
fi
# A signal while the processes start (before the sim): stop those started
# and end as interrupted (75), before the sim starts. From the trap itself:
# a group signal also ends the command the script is in (a sleep, a python
# check), and under errexit its failure would end the script 143, a failure
# to a study or a Slurm job, before the script looked at stop_signal again.
stop_early() {
  for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
  pids=()
  echo "run_scene: interrupted (SIG$stop_signal) while the run's processes started; the same command starts or resumes it" >&2
  exit 75
}
if [[ -n $cuts ]]; then
  # SIGTERM/SIGINT: every process takes its part of one more cut and stops;
  # this script waits for them (below) and exits 75. Before the sim is
  # launched: stop_early. Either is passed on as SIGTERM (the programs take
  # both alike, and a process started with & by a non-interactive bash
  # ignores SIGINT until its own handler is in place).
  stop_signal="" launching_sim=""
  trap 'stop_signal=TERM; [[ -n $launching_sim ]] || stop_early; for p in "${pids[@]}" ${sim_pid:-}; do kill -TERM "$p" 2>/dev/null || true; done' TERM
  trap 'stop_signal=INT; [[ -n $launching_sim ]] || stop_early; for p in "${pids[@]}" ${sim_pid:-}; do kill -TERM "$p" 2>/dev/null || true; done' INT
else
  trap 'echo "run_scene: interrupted" >&2; exit 130' INT TERM
fi

if [[ $bus == tcpq ]]; then
  # LCM's TCP hub on a free loopback port of this (private) namespace; it
  # goes when the run's processes have gone (hub_pid, below).
  port=$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
  java -cp /usr/share/java/lcm.jar lcm.lcm.TCPService "$port" >"$out/tcpservice.log" 2>&1 &
  hub_pid=$!
  hub_up=0
  for _ in $(seq 150); do
    # Connect, and read the hub's 8-byte greeting (a close with it unread
    # would reset the connection).
    (exec 3<>"/dev/tcp/127.0.0.1/$port" && timeout 5 head -c 8 <&3 >/dev/null) 2>/dev/null && { hub_up=1; break; }
    kill -0 "$hub_pid" 2>/dev/null || break
    sleep 0.1
  done
  ((hub_up)) || { echo "run_scene: the tcpq hub did not start:" >&2; cat "$out/tcpservice.log" >&2; exit 1; }
  url=tcpq://127.0.0.1:$port
fi
if [[ -n $url ]]; then export LCM_DEFAULT_URL=$url; fi
# Only the LAN bus leaves the host (ttl=1); a private bus never leaves its
# namespace anyway.
if [[ $bus == lan ]]; then default_ttl=1; else default_ttl=0; fi
url=${LCM_DEFAULT_URL:-udpm://239.255.76.67:7667?ttl=$default_ttl}
# Frames come in bursts of chunks: ask for a big socket receive buffer.
[[ $url == udpm://* && $url != *recv_buf_size* ]] && url="$url&recv_buf_size=4194304"
export LCM_DEFAULT_URL=$url

# One run id for every process of this run (the checkpoint's when resuming).
if [[ -n $resume ]]; then
  run_id=$(/usr/bin/python3 -c "import h5py, sys; print(int(h5py.File(sys.argv[1], 'r').attrs['run_id'][0]))" "$resume")
elif [[ -z $run_id ]]; then
  run_id=$(( (RANDOM << 30 | RANDOM << 15 | RANDOM) + 1 ))
fi
[[ $run_id =~ ^[1-9][0-9]*$ ]] || { echo "run_scene: --run-id must be a positive integer, not $run_id" >&2; exit 2; }

# The run's key: every message on the bus is tagged with it (docs/bus.md);
# --fresh starts a new run, with a new key.
if [[ -z $key_file ]]; then
  [[ $role != sim ]] || { echo "run_scene: --role sim needs --key-file KEY: the run's key, copied from the analysis host's DIR/bus.key" >&2; exit 2; }
  key_file=$out/bus.key
  if [[ ! -e $key_file ]]; then
    rm -f "$key_file.tmp"
    (umask 077 && head -c 32 /dev/urandom >"$key_file.tmp" && mv "$key_file.tmp" "$key_file")
    [[ $role != analysis ]] || echo "run_scene: the run's key is $key_file: copy it to the sim's host (scp -p) and give it there with --key-file" >&2
  fi
fi
[[ -f $key_file ]] || { echo "run_scene: no key file $key_file" >&2; exit 2; }
# This launch's epoch: a receiver takes only messages of its own launch.
if [[ -z $bus_epoch ]]; then
  if [[ $role == all ]]; then bus_epoch=$(od -An -N8 -tu8 /dev/urandom | tr -d ' \n'); else bus_epoch=0; fi
fi
[[ $bus_epoch =~ ^[0-9]+$ ]] || { echo "run_scene: --bus-epoch is a non-negative integer, not $bus_epoch" >&2; exit 2; }
key=(--key-file "$key_file" --bus-epoch "$bus_epoch")

start() { # name, then the command; waits for its "ready" line
  # On resume the log goes on: only the lines after this start's own
  # separator count (an earlier attempt's "ready" is not this process's),
  # and a process that replays its part (the recorder its journal, which
  # grows with the run) gets up to 10 minutes, with a word every 30 s.
  local n=$1 limit=100 from=1; shift
  if ((${#resume_cut[@]})); then
    echo "---- resumed from cut ${resume_cut[1]}" >>"$out/$n.log"
    from=$(wc -l <"$out/$n.log") limit=6000
  else : >"$out/$n.log"; fi
  "$@" 2>>"$out/$n.log" &
  pids+=($!) names+=("$n")
  # (tests: DYNHET_TEST_READY_PAUSE seconds here, a process launched and not yet seen ready)
  [[ -z ${DYNHET_TEST_READY_PAUSE:-} ]] || sleep "$DYNHET_TEST_READY_PAUSE"
  for ((i = 1; i <= limit; ++i)); do
    [[ -z ${stop_signal:-} ]] || stop_early
    tail -n +"$from" "$out/$n.log" 2>/dev/null | grep -q "ready" && return 0
    kill -0 "${pids[-1]}" 2>/dev/null ||
      { [[ -z ${stop_signal:-} ]] || stop_early; echo "run_scene: $n died at start:" >&2; tail -n +"$from" "$out/$n.log" >&2; exit 1; }
    ((i % 300)) || echo "run_scene: $n is not ready after $((i / 10)) s (resuming: replaying its part)" >&2
    sleep 0.1
  done
  echo "run_scene: $n did not get ready in $((limit / 10)) s" >&2; exit 1
}

echo "run_scene: ${scene:-resuming $resume} -> $out (bus $bus, $url, run $run_id, role $role)" >&2
if [[ $role == sim ]]; then # the sim alone; the analysis host records and plots
  launching_sim=1
  "$bin/sim_node" "${sim_input[@]}" --run-id "$run_id" "${key[@]}" --pace-nodes --checkpoint "$out/checkpoint.h5" \
    --checkpoint-before-frames "$out/checkpoint_before_frames.h5" 2> >(tee ${resume:+-a} "$out/sim_node.log" >&2)
  exit $?
fi
if [[ -n $record ]]; then
  if ((${#resume_cut[@]})) && [[ -e $record ]]; then
    # A resumed run records a new segment beside the earlier ones:
    # replay.sh LOG LOG.2 LOG.3 ... plays them in order as one run.
    n=2; while [[ -e $record.$n ]]; do n=$((n + 1)); done
    record=$record.$n
    echo "run_scene: recording this segment into $record (replay.sh takes the segments in order)" >&2
  fi
  if [[ -e $record ]]; then # (this run's own earlier attempt, started over: its log is kept)
    to=$record.old-$(date +%Y%m%d-%H%M%S)
    mv -- "$record" "$to"
    echo "run_scene: the earlier attempt's log $record moved to $to" >&2
  fi
  # Ahead of the other processes where allowed (root): a starved lcm-logger
  # drops what overflows its 30-message subscription queue.
  nice -n -5 lcm-logger --lcm-url="$url" --force "$record" >"$out/lcm-logger.log" 2>&1 &
  logger_pid=$!
fi
# On the analysis host the sim may be started minutes later, by hand.
wait_run=(); [[ $role == analysis ]] && wait_run=(--wait-run 900)
authorship=(); [[ -z $author ]] || authorship+=(--author "$author")
[[ -z $author_email ]] || authorship+=(--author-email "$author_email")
# (tests: DYNHET_TEST_RECORDER_DELAY seconds of sleep per message, a recorder that falls behind the bus)
recorder_delay=(); [[ -z ${DYNHET_TEST_RECORDER_DELAY:-} ]] || recorder_delay=(--test-message-delay "$DYNHET_TEST_RECORDER_DELAY")
start recorder "$bin/recorder" --out "$out/run.h5" --run-id "$run_id" "${key[@]}" "${wait_run[@]}" "${authorship[@]}" \
  "${cut_args[@]}" "${resume_cut[@]}" "${recorder_delay[@]}"
node_delay=(); [[ -z $test_node_delay ]] || node_delay=(--test-frame-delay "$test_node_delay")
for n in $nodes; do start "$n" "$bin/$n" --run-id "$run_id" "${key[@]}" "${wait_run[@]}" "${cut_args[@]}" "${resume_cut[@]}" "${node_delay[@]}"; done
if [[ -n $record ]]; then
  # lcm-logger says nothing when it is ready. The nodes publish their status
  # every second from the start: once the log holds anything (it is flushed
  # every 0.1 s), the logger is on the bus and the sim may start. (Without
  # this wait a loaded machine could start the sim before the logger had
  # joined, and the log, not the run, missed the first frames.)
  for _ in $(seq 150); do [[ -s $record ]] && break; sleep 0.1; done
  [[ -s $record ]] || { echo "run_scene: lcm-logger records nothing:" >&2; cat "$out/lcm-logger.log" >&2; exit 1; }
fi

# The sim in the foreground (its progress line goes to the terminal and
# sim_node.log); with --role analysis it runs on another host.
set +e
if [[ $role == analysis ]]; then
  launching_sim=1  # the sim is another host's: from here a signal is passed on as in a whole run
  echo "run_scene: waiting for run $run_id's sim on the bus (start it with --role sim --run-id $run_id --key-file KEY, KEY a copy of $key_file)" >&2
  sim_rc=0
elif [[ -n $cuts ]]; then
  # In the background, watched with the others: a process that dies takes
  # the run down at once (killed: the last whole cut is the restart point).
  if ((${#resume_cut[@]})); then echo "---- resumed from cut ${resume_cut[1]}" >>"$out/sim_node.log"; else : >"$out/sim_node.log"; fi
  sim_delay=(); [[ -z $test_sim_delay ]] || sim_delay=(--test-frame-delay "$test_sim_delay")
  # (tests: DYNHET_TEST_START_PAUSE seconds here, the nodes up and the sim not)
  [[ -z ${DYNHET_TEST_START_PAUSE:-} ]] || sleep "$DYNHET_TEST_START_PAUSE"
  [[ -z $stop_signal ]] || stop_early
  launching_sim=1  # from here a signal is passed on to every process, the sim too
  "$bin/sim_node" "${sim_input[@]}" --run-id "$run_id" "${key[@]}" --pace-nodes --checkpoint "$out/checkpoint.h5" \
    --checkpoint-before-frames "$out/checkpoint_before_frames.h5" "${cut_args[@]}" "${resume_cut[@]}" "${sim_delay[@]}" \
    2> >(trap '' TERM INT; exec tee -a "$out/sim_node.log" >&2) &
  sim_pid=$!
  # A signal between the check above and this line reached every process
  # but the sim: pass it on.
  [[ -z $stop_signal ]] || kill -TERM "$sim_pid" 2>/dev/null || true
  died=""
  while kill -0 "$sim_pid" 2>/dev/null; do
    for i in "${!pids[@]}"; do
      if [[ -z ${reaped[$i]:-} ]] && ! kill -0 "${pids[$i]}" 2>/dev/null; then
        wait "${pids[$i]}"; rc=$?
        reaped[$i]=$rc
        # Killed (by a signal, the OOM killer, ...): the others cannot finish
        # this run; one that failed by itself has said why, and the rest end
        # on their own as before.
        if [[ $rc -gt 128 && -z $stop_signal ]]; then died="${names[$i]} (exit $rc)"; break 2; fi
      fi
    done
    sleep 0.1
  done
  if [[ -n $died ]]; then
    echo "run_scene: $died died: stopping the run (it resumes from its last whole checkpoint cut)" >&2
    kill -KILL "$sim_pid" "${pids[@]}" 2>/dev/null || true
    wait "$sim_pid" 2>/dev/null
    sim_rc=137
  else
    wait "$sim_pid"; sim_rc=$?
    # A signal arrives during wait: wait again for the sim's own exit.
    while kill -0 "$sim_pid" 2>/dev/null; do wait "$sim_pid"; sim_rc=$?; done
    if [[ $sim_rc -gt 128 && -z $stop_signal ]]; then # killed: the rest cannot go on
      echo "run_scene: sim_node died (exit $sim_rc): stopping the run" >&2
      kill -KILL "${pids[@]}" 2>/dev/null || true
    fi
  fi
else
  "$bin/sim_node" "${sim_input[@]}" --run-id "$run_id" "${key[@]}" --pace-nodes --checkpoint "$out/checkpoint.h5" \
    --checkpoint-before-frames "$out/checkpoint_before_frames.h5" 2> >(tee ${resume:+-a} "$out/sim_node.log" >&2)
  sim_rc=$?
fi
set -e
if [[ $sim_rc -ne 0 ]]; then
  echo "run_scene: sim_node failed (exit $sim_rc); giving the others 15 s to finish" >&2
  for _ in $(seq 150); do
    alive=0
    for p in "${pids[@]}"; do kill -0 "$p" 2>/dev/null && alive=1; done
    ((alive)) || break
    sleep 0.1 || true  # (a second signal ends the sleep: errexit must not end the script 143)
  done
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
fi

status=$sim_rc
for i in "${!pids[@]}"; do
  set +e
  if [[ -n ${reaped[$i]:-} ]]; then rc=${reaped[$i]}; else
    wait "${pids[$i]}"; rc=$?
    # A signal ends the wait, not the process (still writing its last cut): wait on.
    while kill -0 "${pids[$i]}" 2>/dev/null; do wait "${pids[$i]}"; rc=$?; done
  fi
  set -e
  if [[ $rc -ne 0 ]]; then
    echo "run_scene: ${names[$i]} failed (exit $rc); its log: $out/${names[$i]}.log" >&2
    tail -5 "$out/${names[$i]}.log" >&2
    status=1
  fi
done
pids=()
if [[ -n $record ]]; then
  # Stop the logger once it has written everything: the bus is quiet now
  # (every process of the run has exited), so the log stops growing when the
  # logger has caught up; a starved logger on a loaded machine may need
  # seconds for the last frames, which a fixed 0.3 s could cut off.
  size=-1 still=0
  for _ in $(seq 300); do # 30 s at most
    now=$(stat -c %s "$record" 2>/dev/null || echo 0)
    if [[ $now == "$size" ]]; then still=$((still + 1)); else still=0 size=$now; fi
    ((still >= 8)) && break # 0.8 s without growth: 8 of lcm-logger's 0.1 s flushes
    sleep 0.1 || true
  done
  kill -INT "$logger_pid" 2>/dev/null || true
  wait "$logger_pid" 2>/dev/null || true
  # Say so if the log missed frames (lcm-logger takes no part in the flow
  # control: a starved logger drops): the run itself is whole, its log not.
  if ((${#resume_cut[@]} == 0)) && [[ $role == all && -z ${stop_signal:-} ]]; then # a segment holds part of the frames by design
    if ! line=$(/usr/bin/python3 "$root/launch_scripts/lcmlog_runs.py" "$record" --run-id "$run_id" --whole 2>&1); then
      # The UDP counters of this network namespace say whether the kernel
      # dropped datagrams (RcvbufErrors: a socket buffer full).
      udp=$(awk '/^Udp:/ { if (h) { for (i = 2; i <= NF; i++) printf "%s %s ", k[i], $i } else { h = 1; for (i = 2; i <= NF; i++) k[i] = $i } }' /proc/net/snmp 2>/dev/null)
      echo "run_scene: the log $record is not whole ($line): lcm-logger could not keep up; the run itself is" \
        "(UDP here: ${udp:-unknown})" >&2
    fi
  fi
fi
grep -h -E "tau_alpha|frames whole|complete|missing" "$out"/*_node.log "$out/recorder.log" >&2 || true

# A run stopped by a signal goes on later: no plots now (a Slurm task has
# seconds left before its time limit).
if ((plots)) && [[ -f $out/run.h5 && -z ${stop_signal:-} ]]; then
  # every observable's figure that the run has, and overlap.png, in one process
  /usr/bin/python3 "$root/launch_scripts/plot_run.py" "$out/run.h5" "$out" ||
    { echo "run_scene: plotting failed" >&2; status=1; }
fi
if [[ -n $cuts && $status -eq 0 && -f $out/run.h5 ]] &&
  /usr/bin/python3 -c "import h5py, sys; sys.exit(0 if int(h5py.File(sys.argv[1], 'r').attrs.get('complete', 0)) == 1 else 1)" "$out/run.h5" 2>/dev/null; then
  rm -rf "$cuts"/cut-* "$cuts"/frames "$cuts"/recorder.journal # complete: nothing to resume
  rmdir "$cuts" 2>/dev/null || true
fi
if [[ -n $cuts && $status -ne 0 ]]; then
  last=$(ls -d "$cuts"/cut-*/WHOLE 2>/dev/null | tail -1 || true) # (none: ls fails, and so would the script)
  if [[ -n $last ]]; then
    echo "run_scene: interrupted${stop_signal:+ by SIG$stop_signal}; resumable from $(dirname "$last"): run the same command again (exit 75)" >&2
    status=75
  elif [[ -n ${stop_signal:-} ]]; then
    echo "run_scene: interrupted by SIG$stop_signal before the first checkpoint cut: the same command starts the run again (exit 75)" >&2
    status=75
  fi
fi
# (a process's own exit code is said above; the script's is one of those in its header)
[[ $status == 0 || $status == 75 ]] || status=1
exit $status
