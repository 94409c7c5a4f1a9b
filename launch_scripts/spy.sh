#!/usr/bin/env bash
# lcm-spy with dynhet's message types. Debian's /usr/bin/lcm-spy wrapper
# fails on current JDKs, so the Java class is started directly.
# Usage: launch_scripts/spy.sh [LCM_URL]   (a display is needed)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$root/build}
jar=$build/dynhet_lcmtypes.jar
case ${1:-} in
-h | --help) sed -n '2,4p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
-*) echo "spy: unknown option $1 (usage: spy.sh [LCM_URL])" >&2; exit 2 ;;
esac
[[ -f $jar ]] || { echo "spy: $jar is missing; run launch_scripts/setup.sh" >&2; exit 1; }
url=${1:-${LCM_DEFAULT_URL:-udpm://239.255.76.67:7667?ttl=0}}
exec java -cp "/usr/share/java/lcm.jar:/usr/share/java/jchart2d.jar:$jar" lcm.spy.Spy --lcm-url="$url"
