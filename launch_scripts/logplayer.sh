#!/usr/bin/env bash
# LCM's graphical log player (lcm-logplayer-gui) for a dynhet log. Debian's
# /usr/bin/lcm-logplayer-gui wrapper passes -Xincgc, which current JDKs
# refuse, so the Java class is started directly, as spy.sh does for lcm-spy.
# Usage: launch_scripts/logplayer.sh LOG [--inputs] [--paused] [LCM_URL]
#   --inputs   play only what the sim published (DYNHET_RUN, DYNHET_FRAME,
#              DYNHET_SIM_STATUS), so live nodes and a recorder re-analyse
#              the run instead of receiving the old results next to theirs
#   --paused   start paused
#   LCM_URL    default $LCM_DEFAULT_URL or udpm://239.255.76.67:7667?ttl=0
# A display is needed. Headless, use lcm-logplayer (README, "Replays").
set -euo pipefail
usage() { awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; }
log="" url="" opts=()
for a in "$@"; do
  case "$a" in
  -h | --help) usage; exit 0 ;;
  --inputs) opts+=(--invert-filter "--filter=^DYNHET_(RUN|FRAME|SIM_STATUS)$") ;;
  --paused) opts+=(--paused) ;;
  -*) echo "logplayer: unknown option $a (usage: logplayer.sh LOG [--inputs] [--paused] [LCM_URL])" >&2; exit 2 ;;
  *) if [[ -z $log ]]; then log=$a; elif [[ -z $url ]]; then url=$a; else
    echo "logplayer: one log and one URL at most (got also $a)" >&2; exit 2; fi ;;
  esac
done
[[ -n $log ]] || { echo "logplayer: no log given (usage: logplayer.sh LOG [--inputs] [--paused] [LCM_URL])" >&2; exit 2; }
[[ -r $log ]] || { echo "logplayer: cannot read the log $log" >&2; exit 1; }
head -c 4 "$log" | od -An -tx1 | grep -q 'ed a1 da 01' ||
  { echo "logplayer: $log is not an LCM log (no LCM event sync word at its start)" >&2; exit 1; }
if [[ -z ${DISPLAY:-} && -z ${WAYLAND_DISPLAY:-} ]]; then
  echo "logplayer: no display (DISPLAY is not set); headless, replay with lcm-logplayer (README, \"Replays\") or launch_scripts/replay.sh" >&2
  exit 1
fi
url=${url:-${LCM_DEFAULT_URL:-udpm://239.255.76.67:7667?ttl=0}}
exec java -cp /usr/share/java/lcm.jar lcm.logging.LogPlayer --lcm-url="$url" "${opts[@]}" "$log"
