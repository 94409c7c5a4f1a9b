# Sourced by the process tests that start sim, nodes and recorder by hand
# (slow_node.sh, loss_named.sh, stopped_recorder.sh), after $root and $build
# are set and inside their private network namespace: $bin, $py, a $tmp
# removed at exit (kept with KEEP_TMP=1), check COND TEXT (sets fail=1),
# a run key in $DYNHET_KEY_FILE, start LOG COMMAND... (in the background, waits for its "ready" line; its
# pid joins $pids), and at exit every pid in $pids continued and killed.
bin=$build/bin py=/usr/bin/python3
tmp=$(mktemp -d)
# The run's key (docs/bus.md): every process started by hand finds it here.
(umask 077 && head -c 32 /dev/urandom >"$tmp/bus.key")
export DYNHET_KEY_FILE=$tmp/bus.key
pids=()
fail=0
trap 'for p in "${pids[@]}"; do kill -CONT "$p" 2>/dev/null || true; kill "$p" 2>/dev/null || true; done
  [[ -n ${KEEP_TMP:-} ]] && echo "kept $tmp" || rm -rf "$tmp"' EXIT
check() { if eval "$1"; then echo "ok   $2"; else echo "FAIL $2"; fail=1; fi; }
start() { # log, then the command: waits for its ready line
  local log=$1; shift
  "$@" 2>"$log" &
  pids+=($!)
  for _ in $(seq 100); do grep -qs ready "$log" && return 0; sleep 0.1; done
  echo "FAIL no ready line in $log"; exit 1
}
