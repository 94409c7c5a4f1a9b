#!/usr/bin/env bash
# Records every LCM message of a run into an lcm-logger log, until Ctrl-C.
# Usage: launch_scripts/record.sh LOG [LCM_URL] [--fresh]
# A LOG that exists is refused (a recording is not written over); --fresh
# moves it aside to LOG.old-<time> first (nothing is deleted).
# Exit: lcm-logger's (stopped by Ctrl-C); 2 bad arguments or a refused LOG.
# (LCM 1.3.1: lcm-logger's -l flag is broken, --lcm-url= works.)
# To record a run started by run_scene.sh, use its --record LOG option (it
# runs the logger on the run's own, possibly private, bus).
set -euo pipefail
fresh=0 args=()
for a in "$@"; do
  case $a in
  -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;;
  --fresh) fresh=1 ;;
  -*) echo "record: unknown option $a" >&2; exit 2 ;;
  *) args+=("$a") ;;
  esac
done
[[ ${#args[@]} -ge 1 && ${#args[@]} -le 2 ]] || { echo "usage: record.sh LOG [LCM_URL] [--fresh]" >&2; exit 2; }
log=${args[0]}
if [[ -e $log ]]; then
  ((fresh)) || { echo "record: refused: $log exists (a recording is not written over): give another LOG, or --fresh to move it aside to $log.old-<time>" >&2; exit 2; }
  to=$log.old-$(date +%Y%m%d-%H%M%S)
  k=1; while [[ -e $to ]]; do k=$((k + 1)); to=$log.old-$(date +%Y%m%d-%H%M%S)-$k; done
  mv -- "$log" "$to"
  echo "record: --fresh: the earlier $log moved to $to" >&2
fi
url=${args[1]:-${LCM_DEFAULT_URL:-udpm://239.255.76.67:7667?ttl=0}}
# Frames come in bursts of chunks: without a big socket buffer the logger
# drops some (9 and 4 of 180 frames were seen lost while the nodes lost none).
[[ $url == udpm://* && $url != *recv_buf_size* ]] && url="$url$([[ $url == *\?* ]] && echo '&' || echo '?')recv_buf_size=8388608"
# Ahead of the other processes where allowed (root); without --force,
# lcm-logger itself refuses a LOG that appeared meanwhile.
exec nice -n -5 lcm-logger --lcm-url="$url" "$log" 2>/dev/null || exec lcm-logger --lcm-url="$url" "$log"
