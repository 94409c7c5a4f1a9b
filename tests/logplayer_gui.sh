#!/usr/bin/env bash
# LCM's graphical log player through launch_scripts/logplayer.sh, on a
# virtual display (Xvfb): a tiny run is recorded (run_scene.sh --record),
# then in a private network namespace logplayer.sh --inputs plays the log
# while lcm-logger listens; the logger must receive exactly the log's
# DYNHET_RUN, DYNHET_FRAME and DYNHET_SIM_STATUS events, byte for byte,
# and nothing of the old results. Also: a file that is no LCM log, and no
# display, are refused with messages that say so.
set -euo pipefail
root=$1 build=$2
export BUILD_DIR=$build
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
check() { if eval "$1"; then echo "ok   $2"; else echo "FAIL $2"; fail=1; fi; }
bash "$root/launch_scripts/run_scene.sh" "$root/scenes/tiny.toml" --no-build --out "$tmp/live" \
  --record "$tmp/run.lcmlog" --run-id 4242 >"$tmp/live.log" 2>&1 || { tail -5 "$tmp/live.log"; exit 1; }
cat >"$tmp/play.sh" <<SH
url='udpm://239.255.76.67:7713?ttl=0'
lcm-logger --lcm-url="\$url" "$tmp/played.lcmlog" >/dev/null 2>&1 &
logger=\$!
sleep 1
# The player's own pid (logplayer.sh execs java) is written for the end:
# stopping it, not xvfb-run, lets xvfb-run stop its X server.
xvfb-run -a bash -c 'bash "\$1" "\$2" --inputs "\$3" & echo \$! >"\$4"; wait' _ \
  "$root/launch_scripts/logplayer.sh" "$tmp/run.lcmlog" "\$url" "$tmp/player.pid" >"$tmp/player.log" 2>&1 &
want=\$(/usr/bin/python3 "$tmp/events.py" "$tmp/run.lcmlog" | wc -l)
# lcm-logger writes a message out only when the next one comes (or at its
# end): once its file has stopped growing for 3 s the player is through,
# and SIGINT makes the logger write what it holds.
last=-1 still=0
for _ in \$(seq 120); do
  sleep 0.5
  got=\$( [[ -f "$tmp/played.lcmlog" ]] && /usr/bin/python3 "$tmp/events.py" "$tmp/played.lcmlog" | wc -l || echo 0)
  (( got >= want )) && break
  if (( got > 0 && got == last )); then ((++still)); else still=0; fi
  (( still >= 6 )) && break
  last=\$got
done
kill -INT \$logger 2>/dev/null || true
wait \$logger 2>/dev/null || true
kill \$(cat "$tmp/player.pid") 2>/dev/null || true
wait 2>/dev/null || true
SH
# The inputs of a log, one line per event: channel and a hash of its bytes.
cat >"$tmp/events.py" <<'PY'
import hashlib, struct, sys
data = open(sys.argv[1], "rb").read()
pos = 0
while pos + 28 <= len(data):
    _, _, _, clen, dlen = struct.unpack_from(">IqqII", data, pos)
    ch = data[pos + 28:pos + 28 + clen].decode()
    if ch in ("DYNHET_RUN", "DYNHET_FRAME", "DYNHET_SIM_STATUS"):
        print(ch, hashlib.sha1(data[pos + 28 + clen:pos + 28 + clen + dlen]).hexdigest())
    pos += 28 + clen + dlen
PY
bash "$root/launch_scripts/netns.sh" bash "$tmp/play.sh"
/usr/bin/python3 "$tmp/events.py" "$tmp/run.lcmlog" | sort >"$tmp/want.txt"
/usr/bin/python3 "$tmp/events.py" "$tmp/played.lcmlog" | sort >"$tmp/got.txt"
check '[[ -s $tmp/want.txt ]] && cmp -s "$tmp/want.txt" "$tmp/got.txt"' \
  "logplayer.sh --inputs plays the log's $(wc -l <"$tmp/want.txt") input events byte for byte (received $(wc -l <"$tmp/got.txt"))"
check '! /usr/bin/python3 -c "
import struct, sys
data = open(sys.argv[1], \"rb\").read(); pos = 0
while pos + 28 <= len(data):
    _, _, _, cl, dl = struct.unpack_from(\">IqqII\", data, pos)
    if data[pos + 28:pos + 28 + cl].startswith((b\"DYNHET_OVERLAP_\", b\"DYNHET_CHI4_\", b\"DYNHET_NODE_STATUS_\")): sys.exit(0)
    pos += 28 + cl + dl
sys.exit(1)" "$tmp/played.lcmlog"' "none of the old results is played"
bash "$root/launch_scripts/logplayer.sh" "$root/README.md" >"$tmp/bad.out" 2>&1 && rc=0 || rc=$?
check '[[ $rc == 1 ]] && grep -q "is not an LCM log" "$tmp/bad.out"' "a file that is no LCM log is refused"
DISPLAY= WAYLAND_DISPLAY= bash "$root/launch_scripts/logplayer.sh" "$tmp/run.lcmlog" >"$tmp/nodisp.out" 2>&1 && rc=0 || rc=$?
check '[[ $rc == 1 ]] && grep -q "no display" "$tmp/nodisp.out"' "without a display it says so and names the headless player"
((fail == 0)) || cat "$tmp/player.log"
exit $fail
