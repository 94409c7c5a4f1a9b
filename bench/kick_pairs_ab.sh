#!/usr/bin/env bash
# The engine's driven speed rows, interleaved: neighbour kick pairs with the
# partner from the kick list (the engine's default), from the 3 x 3-cell
# search (the earlier engine's, --kick-search cells) and pairs from the
# whole system ("any"); eps = 0.9, phi 0.78 and 0.80, two rounds at
# N = 10^5, one at 10^6 (list and any). Prints one line per run:
# round, mode, N, phi, collisions + kicks per second, events per second,
# bytes per particle, T. About 4 minutes on 2 cores (compressed states
# cached in CACHE, default /tmp/dynhet-bench).
# Usage: bench/kick_pairs_ab.sh [BUILD_DIR] [CACHE]
set -euo pipefail
build=${1:-build} cache=${2:-/tmp/dynhet-bench}
[[ -x $build/bin/bench_engine ]] || { echo "kick_pairs_ab: no $build/bin/bench_engine (build first)" >&2; exit 2; }
mkdir -p "$cache"
run() { # round N phi mode
  local a
  if [[ $4 == any ]]; then a=(--pairs any); else a=(--pairs neighbours --kick-search "$4"); fi
  "$build/bin/bench_engine" --n "$2" --phi "$3" --coll 20 --eps 0.9 --driven "${a[@]}" --tile-from 10000 \
    --cache "$cache" 2>&1 | tail -1 |
    awk -v m="$4" -v r="$1" '{print r, m, $1, $2, "c+k/s", $6, "events/s", $9, "B/part", $11, "T", $15}'
}
for r in 1 2; do for phi in 0.78 0.80; do for m in list cells any; do run $r 100000 $phi $m; done; done; done
for phi in 0.78 0.80; do for m in list any; do run 1 1000000 $phi $m; done; done
