#!/usr/bin/env bash
# lcm-spy's curve views (spy_plugins/), on virtual displays (Xvfb), in a
# private network namespace:
# 1. launch_scripts/spy.sh starts lcm-spy, which finds the four plugins on
#    the classpath spy.sh gives it;
# 2. tests/spy/dynhet/spycheck/SpyPluginCheck.java, with spy.sh's
#    classpath, starts lcm-spy in its own JVM on the bus of a real run of
#    the tiny scene at N = 1200 (run_scene.sh --record): views opened by double clicks on the channels
#    update as the results arrive and end with exactly the final messages'
#    points; every result message of the log, fed one by one, is drawn
#    point for point; hostile messages are rejected and counted, nothing is
#    thrown. Screenshots (PNG) stay in BUILD/test_output/spy_plugins/.
# Usage: tests/spy_plugins.sh ROOT BUILD [SCENE]   (SCENE: watch another
# scene's run; its cutoffs must include 0.6)
set -euo pipefail
root=$1 build=$2
if [[ -z ${DYNHET_IN_NETNS:-} ]]; then exec "$root/launch_scripts/netns.sh" bash "$0" "$@"; fi
export BUILD_DIR=$build
url='udpm://239.255.76.67:7741?ttl=0'
spy=$root/launch_scripts/spy.sh
out=$build/test_output/spy_plugins
rm -rf "$out"
mkdir -p "$out"
tmp=$(mktemp -d)
checker=""
# On an early exit: the checker's processes (java and Xvfb, xvfb-run's
# children), so that no X server outlives the test.
trap '[[ -z $checker ]] || kill $(pgrep -P "$checker") 2>/dev/null || true; rm -rf "$tmp"' EXIT
fail=0
check() { if eval "$1"; then echo "ok   $2"; else echo "FAIL $2"; fail=1; fi; }
for jar in dynhet_spy_plugins dynhet_spy_check; do
  [[ -f $build/$jar.jar ]] || { echo "FAIL $build/$jar.jar is missing (built with Java)"; exit 1; }
done

# 1. spy.sh: lcm-spy lists the plugins it found, then is stopped.
xvfb-run -a bash -c 'bash "$1" "$2" >"$3" 2>&1 &
  p=$!
  for _ in $(seq 200); do grep -q "^Found [0-9]* plugins" "$3" && break; sleep 0.1; done
  sleep 0.5
  kill $p 2>/dev/null
  wait $p 2>/dev/null || true' _ "$spy" "$url" "$out/spy_sh.out"
found=$(sed -n 's/^Found \([0-9]*\) plugins/\1/p' "$out/spy_sh.out")
all_five() {
  for c in OverlapPlugin Chi4Plugin MsdPlugin S4Plugin BondBreakingPlugin; do
    grep -q "^ dynhet\.spy\.$c@" "$1" || return 1
  done
}
check '[[ $found == 5 ]] && all_five "$out/spy_sh.out"' \
  "spy.sh: lcm-spy finds the 5 curve plugins (Q(t), chi4(t), MSD(t), S4(q), C_B(t)) (found ${found:-none})"

# 2. lcm-spy watching a real run, with the checker. lcm-spy 1.3 changes its
# Swing table from its LCM and rate threads, off Swing's thread; a checker
# that is stuck (its watchdog prints every thread's stack and exits 3) is
# reported with the stacks and watched once more on a new run.
cp=$(bash "$spy" --classpath):$build/dynhet_spy_check.jar
# The tiny scene at N = 1200 with 30 origins: its results come for about 4 s
# (the tiny scene's for 0.2 s, too fast to watch); or SCENE.
scene=${3:-$tmp/watched.toml}
sed -e 's/^n_particles = 300/n_particles = 1200/' -e 's/^origins = 4/origins = 30/' \
  "$root/scenes/tiny.toml" >"$tmp/watched.toml"
watch_run() { # ATTEMPT: sets rc (the run) and crc (the checker)
  rm -rf "$tmp/live" "$tmp/run.lcmlog" "$tmp/done"
  xvfb-run -a -s "-screen 0 1920x1080x24" java -cp "$cp" dynhet.spycheck.SpyPluginCheck \
    "$url" "$tmp/run.lcmlog" "$tmp/done" "$out" >"$out/check.out" 2>"$out/check.err" &
  checker=$!
  for _ in $(seq 300); do
    grep -qs '^ready' "$out/check.out" && break
    kill -0 $checker 2>/dev/null || break
    sleep 0.1
  done
  grep -qs '^ready' "$out/check.out" ||
    { echo "FAIL the checker did not start:"; cat "$out/check.out" "$out/check.err"; exit 1; }
  LCM_DEFAULT_URL=$url bash "$root/launch_scripts/run_scene.sh" "$scene" --no-build --out "$tmp/live" \
    --record "$tmp/run.lcmlog" --run-id $((4746 + $1)) >"$tmp/live.log" 2>&1 && rc=0 || rc=$?
  touch "$tmp/done"
  wait $checker && crc=0 || crc=$?
  checker=""
}
watch_run 1
if ((crc == 3)); then
  mv "$out/check.out" "$out/check_stuck.out"; mv "$out/check.err" "$out/check_stuck.err"
  echo "note the checker was stuck on the first run (its report: $out/check_stuck.out, stacks:"
  echo "     $out/check_stuck.err); the checker's, Swing's and any blocked thread's stacks:"
  grep -E '^(ok|FAIL|live) ' "$out/check_stuck.out" | tail -3 | sed 's/^/     /'
  awk -v RS= '/^"(main|AWT-EventQueue)|BLOCKED/' "$out/check_stuck.err" | head -80 | sed 's/^/     /'
  watch_run 2
fi
check '[[ $rc == 0 ]]' "the run watched by lcm-spy is complete (run_scene.sh exit $rc)"
((rc == 0)) || tail -5 "$tmp/live.log"
grep -E '^(ok|FAIL|live) ' "$out/check.out" || true
check '[[ $crc == 0 ]]' "the checker's checks pass (exit $crc)"
((crc == 0)) || head -c 20000 "$out/check.err"
check '[[ -s $out/spy_live.png && -s $out/spy_final.png && -s $out/view_DYNHET_OVERLAP_a0.6.png ]]' \
  "screenshots in $out"
exit $fail
