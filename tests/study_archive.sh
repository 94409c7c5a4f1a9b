#!/usr/bin/env bash
# The results archive (dynhet.archive) on studies/tiny.toml: run_study.sh
# --archive writes each run's entry as it completes (size, hash and
# provenance checked against the runs themselves); analyse_study.sh gives
# the same numbers from the archive as from the study directory; a study
# whose run directories are gone resumes from its archive without running
# a run or pilot again; a corrupted entry, an unlisted file and a
# half-written one are never read as entries; the archive command
# (study.py archive) archives an existing study directory.
set -euo pipefail
root=$1 build=$2
export BUILD_DIR=$build
tmp=$(mktemp -d)
trap 'pkill -TERM -f "study.py run .*$tmp" 2>/dev/null || true; rm -rf "$tmp"' EXIT
# (--no-figures: the study's analysis is compared by its numbers, study.h5
# and the table; the figures drawn are the archive's analysis's below)
study=(bash "$root/launch_scripts/run_study.sh" --no-build --no-figures)
analyse=(bash "$root/launch_scripts/analyse_study.sh")
fail=0
check() { if eval "$1"; then echo "ok   $2"; else echo "FAIL $2"; fail=1; fi; }

"${study[@]}" "$root/studies/tiny.toml" --out "$tmp/study/tiny" --archive "$tmp/results/tiny" --jobs 2 >"$tmp/s.out" 2>&1 ||
  { cat "$tmp/s.out"; exit 1; }
check 'grep -q "4 of 4 runs complete, 0 failed" "$tmp/s.out" && [[ $(grep -c ": archived in " "$tmp/s.out") == 4 ]]' \
  "tiny study: 4 runs complete, each archived the moment it completed"
/usr/bin/python3 "$root/tests/check_archive.py" entries "$tmp/results/tiny" "$tmp/study/tiny" || fail=1
# A pilot's tau_alpha is the one of its last scene: a longer attempt runs again (--fresh), it does not
# find the earlier attempt's run.h5 complete and keep its tau_alpha.
check '/usr/bin/python3 -c "
import glob, sys, tomllib, h5py
ok = []
for d in glob.glob(\"$tmp/study/tiny/pilots/*/\"):
    want = tomllib.load(open(d + \"scene.toml\", \"rb\"))[\"schedule\"][\"lag_max\"]
    got = float(h5py.File(d + \"run.h5\", \"r\")[\"parameters/schedule\"].attrs[\"lag_max\"])
    ok.append(abs(got - want) < 1e-9 * want)
sys.exit(0 if ok and all(ok) else 1)"' "each pilot's run.h5 is of its last scene (a longer attempt ran again)"

# The same analysis from the archive as from the study directory.
"${analyse[@]}" "$tmp/results/tiny" --out "$tmp/from_archive" >"$tmp/an.out" 2>&1 || { cat "$tmp/an.out"; fail=1; }
/usr/bin/python3 "$root/tests/check_archive.py" same-analysis "$tmp/study/tiny/study.h5" "$tmp/from_archive/study.h5" || fail=1
check 'diff <(grep "^| " "$tmp/study/tiny/reproduction.md") <(grep "^| " "$tmp/from_archive/reproduction.md") >/dev/null' \
  "reproduction.md: every table row the same from the archive"
check '[[ ! -e $tmp/results/tiny/study.h5 && ! -d $tmp/results/tiny/figures ]]' "the analysis of an archive writes nothing into it"

# study.py archive: an existing study directory into an archive of its own.
/usr/bin/python3 "$root/launch_scripts/study.py" archive "$tmp/study/tiny" --to "$tmp/arch2" >"$tmp/a2.out" 2>&1 || { cat "$tmp/a2.out"; fail=1; }
check 'grep -q "4 runs archived now, 0 already, 0 not complete; 4 runs in" "$tmp/a2.out"' "study.py archive: 4 runs of a study directory archived"
/usr/bin/python3 "$root/tests/check_archive.py" entries "$tmp/arch2" "$tmp/study/tiny" || fail=1
/usr/bin/python3 "$root/launch_scripts/study.py" archive "$tmp/study/tiny" --to "$tmp/arch2" >"$tmp/a3.out" 2>&1 || fail=1
check 'grep -q "0 runs archived now, 4 already" "$tmp/a3.out"' "archiving again adds nothing"

# The machine is replaced: the run directories and pilots are gone. The same
# command resumes from the archive: nothing runs, the analysis reads the archive.
rm -rf "$tmp/study/tiny/runs" "$tmp/study/tiny/pilots" "$tmp/study/tiny/states" "$tmp/study/tiny/study.h5"
"${study[@]}" "$root/studies/tiny.toml" --out "$tmp/study/tiny" --archive "$tmp/results/tiny" --jobs 2 >"$tmp/r.out" 2>&1 ||
  { cat "$tmp/r.out"; fail=1; }
check 'grep -q "4 runs complete in the archive" "$tmp/r.out" && grep -q "4 of 4 runs complete already (skipped)" "$tmp/r.out" &&
  grep -q "4 done, 0 running, 0 left" "$tmp/r.out" && ! ls "$tmp"/study/tiny/runs/*/run.h5 >/dev/null 2>&1 &&
  [[ ! -d $tmp/study/tiny/pilots ]] && grep -q "4 of 4 runs complete, 0 failed" "$tmp/r.out"' \
  "run directories gone: the study resumes from its archive, no run or pilot run again"
/usr/bin/python3 "$root/tests/check_archive.py" same-analysis "$tmp/study/tiny/study.h5" "$tmp/from_archive/study.h5" || fail=1

# A corrupted entry is refused by name, by the analysis and by the study.
entry=$(ls "$tmp"/results/tiny/runs/*.h5.gz | head -1)
name=$(basename "$entry" .h5.gz)
cp "$entry" "$tmp/keep.h5.gz"
printf 'X' | dd of="$entry" bs=1 seek=2000 conv=notrunc 2>/dev/null
"${analyse[@]}" "$tmp/results/tiny" --out "$tmp/bad" >"$tmp/bad.out" 2>&1 && rc=0 || rc=$?
check '[[ $rc != 0 ]] && grep -q "entry .$name.: .* does not match the index" "$tmp/bad.out"' \
  "a corrupted entry: the analysis refuses it by name (exit $rc)"
rm -rf "$tmp/study/tiny/runs"
"${study[@]}" "$root/studies/tiny.toml" --out "$tmp/study/tiny" --archive "$tmp/results/tiny" --jobs 1 >"$tmp/bad2.out" 2>&1 && rc=0 || rc=$?
check 'grep -q "$name.*does not match the index" "$tmp/bad2.out"' "a corrupted entry: the study refuses it by name"
cp "$tmp/keep.h5.gz" "$entry"

# A half-written entry (the temporary name an entry is written to) and a file
# the index does not list are not entries: the archive reads as before.
cp "$entry" "$tmp/results/tiny/runs/$name.h5.gz.tmp.host.1"
cp "$entry" "$tmp/results/tiny/runs/unlisted.h5.gz"
# (--no-figures: the text alone; study.h5 is what is compared, and the figures of an archive's analysis are
# those of the first analysis above)
"${analyse[@]}" "$tmp/results/tiny" --out "$tmp/again" --no-figures >"$tmp/again.out" 2>&1 || { cat "$tmp/again.out"; fail=1; }
/usr/bin/python3 "$root/tests/check_archive.py" same-analysis "$tmp/from_archive/study.h5" "$tmp/again/study.h5" || fail=1

((fail == 0)) || { echo "--- outputs"; tail -n 30 "$tmp"/*.out; }
exit $fail
