#!/usr/bin/env bash
# Records every LCM message of a run into an lcm-logger log, until Ctrl-C.
# Usage: launch_scripts/record.sh LOG [LCM_URL]
# (LCM 1.3.1: lcm-logger's -l flag is broken, --lcm-url= works.)
# To record a run started by run_scene.sh, use its --record LOG option (it
# runs the logger on the run's own, possibly private, bus).
set -euo pipefail
[[ $# -ge 1 ]] || { echo "usage: record.sh LOG [LCM_URL]" >&2; exit 2; }
url=${2:-${LCM_DEFAULT_URL:-udpm://239.255.76.67:7667?ttl=0}}
exec lcm-logger --lcm-url="$url" --force "$1"
