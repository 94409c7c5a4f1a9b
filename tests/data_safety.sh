#!/usr/bin/env bash
# No command writes over results it did not write for the same purpose:
# run_scene.sh, replay.sh, record.sh, run_study.sh, analyse_study.sh and
# reproduce.sh refuse such a destination (exit 2, naming what is there and
# --fresh), leave it byte for byte as it was, and with --fresh move it aside
# to the place they name, intact. A run that fails at run time exits 1 with
# its last line said; a run's own directory still resumes. setup.sh refuses
# a build that would change the id of a build whose programs are running.
set -uo pipefail
root=$1 build=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export BUILD_DIR=$build
fail=0
check() { if eval "$1"; then echo "ok   $2"; else echo "FAIL $2"; fail=1; fi; }
sum() { sha256sum "$1" | cut -d' ' -f1; }
run() { # out-file, command...: its exit code in $rc, its stderr and stdout in out-file
  local o=$1
  shift
  "$@" >"$o" 2>&1 && rc=0 || rc=$?
}
mkrun() { # DIR: a run's files (a run.h5 and a node log), as a run of somebody else's left them
  mkdir -p "$1"
  head -c 4096 /dev/urandom >"$1/run.h5"
  echo "overlap_node: 180 frames whole" >"$1/overlap_node.log"
}

# run_scene.sh on a DIR holding a run.h5 without the scene.toml it came from.
mkrun "$tmp/r1"
h=$(sum "$tmp/r1/run.h5")
run "$tmp/r1.out" bash "$root/launch_scripts/run_scene.sh" "$root/scenes/tiny.toml" --out "$tmp/r1" --no-build --no-plots
check '[[ $rc == 2 && $(sum "$tmp/r1/run.h5") == "$h" ]] && grep -q "refused: $tmp/r1 holds .*run.h5" "$tmp/r1.out" &&
  grep -q -- "--fresh" "$tmp/r1.out" && [[ $(ls "$tmp/r1") == $(printf "overlap_node.log\nrun.h5") ]]' \
  "run_scene: a run.h5 without its scene.toml is refused (exit $rc), named, its checksum unchanged, nothing added"
# ... holding a run of another scene: the keys that differ are named.
sed 's/^seed = 7/seed = 8/' "$root/scenes/tiny.toml" >"$tmp/other.toml"
mkrun "$tmp/r2"
cp "$tmp/other.toml" "$tmp/r2/scene.toml"
h=$(sum "$tmp/r2/run.h5")
run "$tmp/r2.out" bash "$root/launch_scripts/run_scene.sh" "$root/scenes/tiny.toml" --out "$tmp/r2" --no-build --no-plots
check '[[ $rc == 2 && $(sum "$tmp/r2/run.h5") == "$h" ]] && grep -q "system.seed" "$tmp/r2.out" && grep -q "a run of another scene" "$tmp/r2.out"' \
  "run_scene: a run of another scene is refused (exit $rc), the key that differs named"
# ... its own run of this scene, complete: nothing to do (the resume path is not refused).
mkdir -p "$tmp/r3"
cp "$root/scenes/tiny.toml" "$tmp/r3/scene.toml"
/usr/bin/python3 -c "import h5py, sys; h5py.File(sys.argv[1], 'w').attrs['complete'] = 1" "$tmp/r3/run.h5"
h=$(sum "$tmp/r3/run.h5")
run "$tmp/r3.out" bash "$root/launch_scripts/run_scene.sh" "$root/scenes/tiny.toml" --out "$tmp/r3" --no-build --no-plots
check '[[ $rc == 0 && $(sum "$tmp/r3/run.h5") == "$h" ]] && grep -q "complete: nothing to resume" "$tmp/r3.out"' \
  "run_scene: its own complete run of this scene: nothing to resume, exit $rc"
# ... with --fresh the old run moves aside, intact; the run (phi = 0.86: its
# compression stalls) fails at run time: exit 1, the last line says so.
sed 's/^packing_fraction = .*/packing_fraction = 0.86/' "$root/scenes/tiny.toml" >"$tmp/stall.toml"
mkrun "$tmp/r4"
h=$(sum "$tmp/r4/run.h5")
t0=$(date +%s%N)
run "$tmp/r4.out" timeout 120 bash "$root/launch_scripts/run_scene.sh" "$tmp/stall.toml" --out "$tmp/r4" --no-build --no-plots --fresh
ms=$((($(date +%s%N) - t0) / 1000000))
old=$(sed -n "s|^run_scene: --fresh: the earlier run in .* moved to \(.*\)$|\1|p" "$tmp/r4.out")
check '[[ -n $old && -f $old/run.h5 && $(sum "$old/run.h5") == "$h" && -f $old/overlap_node.log && $old == $tmp/r4/old-* ]]' \
  "run_scene --fresh: the old run.h5 is intact where it says ($old)"
check '[[ $rc == 1 ]] && grep -q "compression stalled" "$tmp/r4.out" && [[ $(tail -1 "$tmp/r4.out") == "run_scene: results in $tmp/r4 (exit 1)" ]]' \
  "run_scene: a run that fails at run time exits 1 (got $rc after $ms ms), its last line: $(tail -1 "$tmp/r4.out")"

# replay.sh LOG --out <a live run's directory>.
mkrun "$tmp/live"
cp "$root/scenes/tiny.toml" "$tmp/live/scene.toml"
echo "sim_node: production" >"$tmp/live/sim_node.log"
head -c 32 /dev/urandom >"$tmp/live/bus.key"
head -c 1000 /dev/urandom >"$tmp/live/run.lcmlog"
h=$(sum "$tmp/live/run.h5") hl=$(sum "$tmp/live/sim_node.log")
run "$tmp/p1.out" bash "$root/launch_scripts/replay.sh" "$tmp/live/run.lcmlog" --out "$tmp/live" --no-build
check '[[ $rc == 2 && $(sum "$tmp/live/run.h5") == "$h" && $(sum "$tmp/live/sim_node.log") == "$hl" ]] &&
  grep -q "refused: $tmp/live holds a run.s results .*run.h5" "$tmp/p1.out" && grep -q -- "--fresh" "$tmp/p1.out"' \
  "replay: a live run's directory is refused (exit $rc), its run.h5 and logs unchanged"
run "$tmp/p2.out" bash "$root/launch_scripts/replay.sh" "$tmp/live/run.lcmlog" --out "$tmp/live" --no-build --fresh
old=$(sed -n "s|^replay: --fresh: what .* moved to \(.*\)$|\1|p" "$tmp/p2.out")
check '[[ -n $old && $(sum "$old/run.h5") == "$h" && $(sum "$old/sim_node.log") == "$hl" && -f $tmp/live/run.lcmlog && -f $tmp/live/bus.key ]]' \
  "replay --fresh: the live run's run.h5 and logs are intact where it says ($old), its log and key stay"
# ... a replay of the same log into the directory it wrote before replays again (its REPLAY names the log).
mkdir -p "$tmp/again"
realpath "$tmp/live/run.lcmlog" >"$tmp/again/REPLAY"
echo "recorder: ready" >"$tmp/again/recorder.log"
run "$tmp/p3.out" bash "$root/launch_scripts/replay.sh" "$tmp/live/run.lcmlog" --out "$tmp/again" --no-build --key-file "$tmp/live/bus.key"
check '! grep -q refused "$tmp/p3.out" && [[ $rc == 2 ]]' "replay: its own earlier replay of the same log is not refused (exit $rc: the log is no lcm log)"

# record.sh LOG over an existing log.
head -c 1000 /dev/urandom >"$tmp/rec.lcmlog"
h=$(sum "$tmp/rec.lcmlog")
run "$tmp/l1.out" bash "$root/launch_scripts/record.sh" "$tmp/rec.lcmlog" "bogus://nothing"
check '[[ $rc == 2 && $(sum "$tmp/rec.lcmlog") == "$h" ]] && grep -q "refused: $tmp/rec.lcmlog exists" "$tmp/l1.out"' \
  "record: an existing log is refused (exit $rc), unchanged"
run "$tmp/l2.out" timeout 10 bash "$root/launch_scripts/record.sh" "$tmp/rec.lcmlog" "bogus://nothing" --fresh
old=$(sed -n "s|^record: --fresh: the earlier .* moved to \(.*\)$|\1|p" "$tmp/l2.out")
check '[[ -n $old && $(sum "$old") == "$h" ]]' "record --fresh: the old log is intact where it says ($old)"

# run_study.sh --out DIR holding a run, not a study; reproduce.sh on such a DIR/<study>.
mkrun "$tmp/s1"
h=$(sum "$tmp/s1/run.h5")
run "$tmp/s1.out" bash "$root/launch_scripts/run_study.sh" "$root/studies/tiny.toml" --out "$tmp/s1" --no-build
check '[[ $rc == 2 && $(sum "$tmp/s1/run.h5") == "$h" && ! -e $tmp/s1/study.toml ]] &&
  grep -q "is not a study directory (no study.toml) and holds overlap_node.log, run.h5" "$tmp/s1.out" && grep -q -- "--fresh" "$tmp/s1.out"' \
  "run_study: a directory that is not a study is refused (exit $rc), unchanged"
mkrun "$tmp/rp/quick"
h=$(sum "$tmp/rp/quick/run.h5")
run "$tmp/rp.out" bash "$root/launch_scripts/reproduce.sh" --runs "$tmp/rp" --results "$tmp/results" --only quick --no-build
check '[[ $rc == 2 && $(sum "$tmp/rp/quick/run.h5") == "$h" && ! -e $tmp/rp/quick/study.toml ]] && grep -q "is not a study directory" "$tmp/rp.out"' \
  "reproduce: a study directory holding something else is refused (exit $rc), unchanged"

# analyse_study.sh --table FILE: a file it did not generate is refused; one it did is written again.
mkdir -p "$tmp/st"
: >"$tmp/st/index.toml"
echo "# my notes" >"$tmp/notes.md"
h=$(sum "$tmp/notes.md")
run "$tmp/a1.out" bash "$root/launch_scripts/analyse_study.sh" "$tmp/st" --table "$tmp/notes.md"
check '[[ $rc == 2 && $(sum "$tmp/notes.md") == "$h" ]] && grep -q "refused: $tmp/notes.md exists and is not a document this analysis wrote" "$tmp/a1.out"' \
  "analyse_study: a --table that it did not write is refused (exit $rc), unchanged"
run "$tmp/a2.out" bash "$root/launch_scripts/analyse_study.sh" "$tmp/st" --finite-size "$tmp/notes.md" --fresh
old=$(sed -n "s|^analyse_study: --fresh: .* moved to \(.*\)$|\1|p" "$tmp/a2.out")
check '[[ -n $old && $(sum "$old") == "$h" && $rc == 1 ]] && grep -q "no complete run" "$tmp/a2.out"' \
  "analyse_study --fresh: the file is intact where it says ($old); a study with no complete run fails at run time (exit $rc)"
git -C "$root" show HEAD:docs/reproduction.md >"$tmp/gen.md" 2>/dev/null || head -5 "$root/docs/reproduction.md" >"$tmp/gen.md"
run "$tmp/a3.out" bash "$root/launch_scripts/analyse_study.sh" "$tmp/st" --table "$tmp/gen.md"
check '[[ $rc == 1 ]] && ! grep -q refused "$tmp/a3.out"' "analyse_study: a table it generated is not refused (exit $rc: no complete run)"
run "$tmp/a4.out" bash "$root/launch_scripts/analyse_study.sh" "$tmp/nostudy"
check '[[ $rc == 2 ]] && grep -q "not a study directory" "$tmp/a4.out"' "analyse_study: a directory that is not a study is a bad argument (exit $rc)"

# setup.sh on a build directory whose programs run: a build that would change
# its id is refused (exit 2, the processes named, nothing built), since their
# checkpoints carry the id and a resume refuses another build's; the same id,
# or --force, goes on to the build (here a build directory with an empty
# CMake cache, so the build fails at once: exit 1).
version=$(sed -n 's/^project(dynhet VERSION \([0-9.]*\).*/\1/p' "$root/CMakeLists.txt")
mkdir -p "$tmp/b/common" "$tmp/b/bin"
: >"$tmp/b/CMakeCache.txt"
cmake -DSRC="$root" -DOUT="$tmp/b/common/build_id.cpp" -DVERSION=0.0.0 -P "$root/common/build_id.cmake"
cp "$(command -v sleep)" "$tmp/b/bin/sleep"
"$tmp/b/bin/sleep" 120 &
busy=$!
BUILD_DIR=$tmp/b run "$tmp/b1.out" bash "$root/launch_scripts/setup.sh"
check '[[ $rc == 2 && ! -e $tmp/b.build.log ]] && grep -q "refused: .*$tmp/b is build 0.0.0-" "$tmp/b1.out" &&
  grep -q "pid $busy: $tmp/b/bin/sleep 120" "$tmp/b1.out"' \
  "setup: a build that would change the id of a running build is refused (exit $rc), the process named, nothing built"
BUILD_DIR=$tmp/b run "$tmp/b2.out" bash "$root/launch_scripts/setup.sh" --force
check '[[ $rc == 1 && -e $tmp/b.build.log ]] && grep -q -- "--force: building" "$tmp/b2.out"' \
  "setup --force: builds anyway, said (exit $rc: this directory's empty cache)"
rm -f "$tmp/b.build.log"
cmake -DSRC="$root" -DOUT="$tmp/b/common/build_id.cpp" -DVERSION="$version" -P "$root/common/build_id.cmake"
BUILD_DIR=$tmp/b run "$tmp/b3.out" bash "$root/launch_scripts/setup.sh"
check '[[ $rc == 1 && -e $tmp/b.build.log ]] && ! grep -q refused "$tmp/b3.out"' \
  "setup: a build that keeps the id of a running build is not refused (exit $rc: this directory's empty cache)"
kill $busy 2>/dev/null
BUILD_DIR=$tmp/b run "$tmp/b4.out" bash "$root/launch_scripts/setup.sh" --frobnicate
check '[[ $rc == 2 ]] && grep -q "unknown argument" "$tmp/b4.out"' "setup: an unknown argument is refused (exit $rc)"

if ((fail)); then
  for f in "$tmp"/*.out; do echo "== $f"; tail -8 "$f"; done
  exit 1
fi
echo PASS
