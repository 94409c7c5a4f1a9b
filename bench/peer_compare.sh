#!/usr/bin/env bash
# dynhet's engine side by side with l09rin/EDMD, a public 2D port of
# Smallenburg's event-driven hard-sphere code (one event per particle,
# neighbour shells, Paul's calendar): elastic hard disks, the same starting
# states, interleaved runs (peer, dynhet, peer, ...) pinned to one core
# (docs/engine.md, "Against another EDMD code").
#
# The peer's code is never part of this repository: the scripts in
# PEER_SCRIPTS (compare.sh, build.sh, convert.py, summarize.py, ...) build
# it from a snapshot of its public repository in PEER_DIR, which you bring
# there yourself, e.g.
#   git --git-dir=<a mirror of github.com/l09rin/EDMD> archive HEAD | tar -x -C ../peer-edmd
#
# usage: bench/peer_compare.sh [N:PHI ...]   (default 10000:0.78 100000:0.78 1000000:0.78)
# env: BUILD_DIR (default build), PEER_DIR (default ../peer-edmd beside the
#      project root), PEER_SCRIPTS (default /work/shared/peer), WORK_DIR
#      (default PEER_DIR/runs), PAIRS (interleaved pairs per case, default
#      5), COLL (collisions per run, default 2e7), CORE (default 1).
# Prints summarize.py's table (collisions per CPU second, medians and the
# ratio dynhet/peer; collision frequency and Z of both codes as a check).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${BUILD_DIR:-$root/build}" && pwd)
scripts=${PEER_SCRIPTS:-/work/shared/peer}
export PEER_DIR=${PEER_DIR:-$(cd "$root/.." && pwd)/peer-edmd}
export WORK_DIR=${WORK_DIR:-$PEER_DIR/runs}
export PAIRS=${PAIRS:-5}
cases=("$@")
[ ${#cases[@]} -gt 0 ] || cases=(10000:0.78 100000:0.78 1000000:0.78)
[ -d "$PEER_DIR/Cylinder2D" ] || { echo "peer_compare: no snapshot of l09rin/EDMD in $PEER_DIR (see the head of this script)" >&2; exit 2; }
[ -f "$scripts/compare.sh" ] || { echo "peer_compare: no comparison scripts in $scripts (PEER_SCRIPTS)" >&2; exit 2; }
mkdir -p "$WORK_DIR"
# The scripts read dynhet from DYNHET_SRC with its build in DYNHET_SRC/build:
# a tree of links gives them this source with BUILD_DIR as its build.
src=$(mktemp -d)
trap 'rm -rf "$src"' EXIT
for d in sim_node common; do ln -s "$root/$d" "$src/$d"; done
ln -s "$build" "$src/build"
[ -x "$WORK_DIR/dynhet_z" ] || bash "$scripts/build_dynhet_z.sh" "$src" "$WORK_DIR"
DYNHET_SRC=$src DYNHET_BIN=$build/bin bash "$scripts/compare.sh" "${cases[@]}"
/usr/bin/python3 "$scripts/summarize.py" "$WORK_DIR"
