#!/usr/bin/env bash
# Sets up (packages, build) and runs the default test suite (everything but
# the long stress runs and the long Slurm requeue test: ctest -L stress, -L long).
# Usage: launch_scripts/test.sh [extra ctest args]
set -euo pipefail
case ${1:-} in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac
root=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$root/build}
BUILD_DIR=$build "$root/launch_scripts/setup.sh"
cd "$build"
ctest --output-on-failure -j2 -LE 'stress|long' --timeout 600 "$@"
