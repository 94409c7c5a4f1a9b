#!/usr/bin/env bash
# lcm-spy with dynhet's message types and its curve views (plugins): Q(t),
# chi4(t), MSD(t), S4(q) and C_B(t) of a channel drawn live in lcm-spy (the
# cage-relative channels, _CR, by the same views, titled so). Debian's
# /usr/bin/lcm-spy wrapper fails on current JDKs, so the Java class is
# started directly.
# Usage: launch_scripts/spy.sh [LCM_URL]     (a display is needed)
#        launch_scripts/spy.sh --classpath   print the classpath it uses
# LCM_URL defaults to $LCM_DEFAULT_URL, else udpm://239.255.76.67:7667?ttl=0.
# Double-click a channel of overlap_t, chi4_t, msd_t or s4_t for its curves
# (right-click for the structure viewer); README, "Record, replay, watch".
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$root/build}
types=$build/dynhet_lcmtypes.jar
plugins=$build/dynhet_spy_plugins.jar
usage() { sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; }
classpath_only=0
case ${1:-} in
-h | --help) usage; exit 0 ;;
--classpath) classpath_only=1 ;;
-*) echo "spy: unknown option $1 (usage: spy.sh [LCM_URL] | spy.sh --classpath)" >&2; exit 2 ;;
esac
[[ -f $types ]] || { echo "spy: $types is missing; run launch_scripts/setup.sh" >&2; exit 1; }
cp=/usr/share/java/lcm.jar:/usr/share/java/jchart2d.jar:$types
if [[ -f $plugins ]]; then cp=$cp:$plugins; else
  echo "spy: $plugins is missing (built with Java): no curve views" >&2; fi
if ((classpath_only)); then echo "$cp"; exit 0; fi
if [[ -z ${DISPLAY:-} && -z ${WAYLAND_DISPLAY:-} ]]; then
  echo "spy: no display (DISPLAY is not set); lcm-spy is a window" >&2; exit 1
fi
url=${1:-${LCM_DEFAULT_URL:-udpm://239.255.76.67:7667?ttl=0}}
exec java -cp "$cp" lcm.spy.Spy --lcm-url="$url"
