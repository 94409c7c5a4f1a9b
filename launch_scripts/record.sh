#!/usr/bin/env bash
# Records every LCM message of a run into an lcm-logger log, until Ctrl-C.
# Usage: launch_scripts/record.sh LOG [LCM_URL]
# (LCM 1.3.1: lcm-logger's -l flag is broken, --lcm-url= works.)
# To record a run started by run_scene.sh, use its --record LOG option (it
# runs the logger on the run's own, possibly private, bus).
set -euo pipefail
case ${1:-} in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac
[[ $# -ge 1 ]] || { echo "usage: record.sh LOG [LCM_URL]" >&2; exit 2; }
url=${2:-${LCM_DEFAULT_URL:-udpm://239.255.76.67:7667?ttl=0}}
# Frames come in bursts of chunks: without a big socket buffer the logger
# drops some (9 and 4 of 180 frames were seen lost while the nodes lost none).
[[ $url == udpm://* && $url != *recv_buf_size* ]] && url="$url$([[ $url == *\?* ]] && echo '&' || echo '?')recv_buf_size=8388608"
# Ahead of the other processes where allowed (root).
exec nice -n -5 lcm-logger --lcm-url="$url" --force "$1" 2>/dev/null || exec lcm-logger --lcm-url="$url" --force "$1"
