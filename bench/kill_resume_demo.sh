#!/usr/bin/env bash
# A run killed at random in production, resumed each time with the same
# command, against the same run straight through: prints what was killed
# when, which cut each resume started from, the wall times, and whether the
# two run.h5 files are equal (tests/compare_h5.py: every dataset and
# attribute but the wall-clock ones). docs/checkpoints.md quotes it.
#
# Usage: bench/kill_resume_demo.sh SCENE.toml OUTDIR [KILLS=3] [SEED=1]
#   e.g. bench/kill_resume_demo.sh scenes/n1e5.toml /tmp/demo 3 1
# Each kill: SIGKILL of one process drawn at random (sim_node, a node, the
# recorder, or the whole process group) at a random time between 2 and 12 s
# after the run's first checkpoint cut in production.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
scene=$1 out=$2 kills=${3:-3} seed=${4:-1}
[[ -f $scene ]] || { echo "usage: $0 SCENE.toml OUTDIR [KILLS] [SEED]" >&2; exit 2; }
export BUILD_DIR=${BUILD_DIR:-$root/build}
mkdir -p "$out"
RANDOM=$seed
run_id=$((900000 + seed))
nodes=$("$BUILD_DIR/bin/sim_node" "$scene" --check | sed -n 's/^nodes: *//p')
victims=(sim_node $nodes recorder all)
now() { date +%s.%N; }
since() { echo "$(now) - $1" | bc; }

t0=$(now)
bash "$root/launch_scripts/run_scene.sh" "$scene" --out "$out/ref" --run-id $run_id --no-build --no-plots --fresh \
  >"$out/ref.log" 2>&1
ref_wall=$(since "$t0")
printf '| %-26s | %-10s |\n' "reference run" "$(printf '%.0f s' "$ref_wall")"

rm -rf "$out/killed" "$out/killed.log"
segments=0 t_all=$(now)
for k in $(seq "$kills"); do
  set -m
  bash "$root/launch_scripts/run_scene.sh" "$scene" --out "$out/killed" --run-id $run_id --no-build --no-plots \
    >>"$out/killed.log" 2>&1 &
  pid=$!
  set +m
  segments=$((segments + 1))
  # The first cut of this segment in production (after a frame).
  start=$(ls -d "$out"/killed/checkpoints/cut-*/WHOLE 2>/dev/null | tail -1 || true)
  for _ in $(seq 6000); do
    newest=$(ls -d "$out"/killed/checkpoints/cut-*/WHOLE 2>/dev/null | tail -1 || true)
    if [[ -n $newest && $newest != "$start" ]] && ! grep -q "^frame -1" "$newest"; then break; fi
    kill -0 $pid 2>/dev/null || break
    sleep 0.1
  done
  wait_ms=$((2000 + RANDOM % 10000))
  v=${victims[RANDOM % ${#victims[@]}]}
  sleep "$(printf '%d.%03d' $((wait_ms / 1000)) $((wait_ms % 1000)))"
  if ! kill -0 $pid 2>/dev/null; then
    printf '| kill %d: %-18s | %-10s |\n' "$k" "run ended first" ""
    break
  fi
  if [[ $v == all ]]; then
    kill -KILL -- -$pid 2>/dev/null || true
  else
    p=$(pgrep -f "bin/$v .*--run-id $run_id|bin/$v --out $out/killed/run.h5" | head -1 || true)
    [[ -z $p ]] || kill -KILL "$p"
  fi
  set +e; wait $pid; rc=$?; set -e
  cut=$(ls -d "$out"/killed/checkpoints/cut-*/WHOLE 2>/dev/null | tail -1 || true)
  frame=$([[ -n $cut ]] && sed -n 's/^frame //p' "$cut" || echo -)
  printf '| kill %d: %-18s | %-10s | exit %s; newest whole cut after frame %s\n' "$k" "$v" \
    "$(printf '+%.1f s' "$(echo "$wait_ms / 1000" | bc -l)")" "$rc" "$frame"
done
until bash "$root/launch_scripts/run_scene.sh" "$scene" --out "$out/killed" --run-id $run_id --no-build --no-plots \
  >>"$out/killed.log" 2>&1; do
  segments=$((segments + 1))
  ((segments < kills + 5)) || { echo "the killed run does not complete: $out/killed.log"; exit 1; }
done
segments=$((segments + 1))
killed_wall=$(since "$t_all")
printf '| %-26s | %-10s |\n' "killed run, $segments segments" "$(printf '%.0f s' "$killed_wall")"
grep -h "resuming run" "$out/killed.log" | sed 's/^/  /'
/usr/bin/python3 "$root/tests/compare_h5.py" "$out/ref/run.h5" "$out/killed/run.h5"
