#!/usr/bin/env bash
# launch_scripts/reproduce.sh, the recipe behind docs/reproduction.md and
# docs/finite_size.md: every study it names dry-runs (the study file parses,
# every run's scene passes sim_node --check), its sum is the sum of theirs,
# and bad input is refused by name before anything runs, as is an analysis
# (which rewrites the tracked documents) while planned runs are not archived.
set -euo pipefail
root=$1 build=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
out=$(BUILD_DIR=$build bash "$root/launch_scripts/reproduce.sh" --no-build --dry-run --runs "$tmp/runs" --results "$tmp/results")
echo "$out"
n=$(grep -c '^== study ' <<<"$out")
[[ $n == 5 ]] || { echo "FAIL: $n studies, expected 5"; exit 1; }
/usr/bin/python3 - "$out" <<'PY'
import re, sys
out = sys.argv[1]
parts = [float(x) for x in re.findall(r"^# total CPU .*\(([0-9.]+) CPU-hours\)", out, re.M)]
total = float(re.search(r"^# all 5 studies: ([0-9.]+) CPU-hours", out, re.M).group(1))
assert len(parts) == 5 and all(p > 0 for p in parts), parts
assert abs(total - sum(parts)) < 0.011, (total, sum(parts))
print(f"ok   5 studies, {total} CPU-hours = sum of theirs")
PY
rc=0; bash "$root/launch_scripts/reproduce.sh" --no-build --only quick,nope --runs "$tmp/runs" 2>"$tmp/err" || rc=$?
[[ $rc == 2 ]] && grep -q "no study 'nope'" "$tmp/err" || { echo "FAIL bad --only: rc $rc: $(cat "$tmp/err")"; exit 1; }
rc=0; bash "$root/launch_scripts/reproduce.sh" --no-build --analyse-only --runs "$tmp/runs" --results "$tmp/results" 2>"$tmp/err" || rc=$?
[[ $rc == 2 ]] && grep -q "results/quick/index.toml does not exist" "$tmp/err" || { echo "FAIL analyse-only without archives: rc $rc: $(cat "$tmp/err")"; exit 1; }
for d in runs results; do
  [[ ! -e $tmp/$d || -z $(ls -A "$tmp/$d") ]] || { echo "FAIL: the dry run left $(ls -A "$tmp/$d")"; exit 1; }
done
# An analysis while planned runs are not archived would rewrite the tracked documents from part of the data.
mkdir -p "$tmp/results/quick"
cp "$root/studies/quick.toml" "$tmp/results/quick/study.toml"
printf '[system]\nn_particles = 4096\n' >"$tmp/results/quick/base_scene.toml"
printf '[archive]\nformat = 1\nstudy = "quick"\n' >"$tmp/results/quick/index.toml"
rc=0; bash "$root/launch_scripts/reproduce.sh" --no-build --analyse-only --runs "$tmp/runs" --results "$tmp/results" 2>"$tmp/err" || rc=$?
[[ $rc == 2 ]] && grep -q "quick (0 of 114 runs archived); size_standard (not run)" "$tmp/err" && grep -q "refused" "$tmp/err" ||
  { echo "FAIL analyse-only with runs not archived: rc $rc: $(cat "$tmp/err")"; exit 1; }
echo "ok   refused: an unknown study, an analysis without its studies, one while runs are unfinished"
