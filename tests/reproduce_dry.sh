#!/usr/bin/env bash
# launch_scripts/reproduce.sh, the recipe behind docs/reproduction.md and
# docs/finite_size.md: every study it names dry-runs (the study file parses,
# every run's scene passes sim_node --check), its sum is the sum of theirs,
# and bad input is refused by name before anything runs, as is an analysis
# (which rewrites the tracked documents) while runs are unfinished.
set -euo pipefail
root=$1 build=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
out=$(BUILD_DIR=$build bash "$root/launch_scripts/reproduce.sh" --no-build --dry-run --runs "$tmp/runs")
echo "$out"
n=$(grep -c '^== study ' <<<"$out")
[[ $n == 7 ]] || { echo "FAIL: $n studies, expected 7"; exit 1; }
/usr/bin/python3 - "$out" <<'PY'
import re, sys
out = sys.argv[1]
parts = [float(x) for x in re.findall(r"^# total CPU .*\(([0-9.]+) CPU-hours\)", out, re.M)]
total = float(re.search(r"^# all 7 studies: ([0-9.]+) CPU-hours", out, re.M).group(1))
assert len(parts) == 7 and all(p > 0 for p in parts), parts
assert abs(total - sum(parts)) < 0.011, (total, sum(parts))
print(f"ok   7 studies, {total} CPU-hours = sum of theirs")
PY
rc=0; bash "$root/launch_scripts/reproduce.sh" --no-build --only quick,nope --runs "$tmp/runs" 2>"$tmp/err" || rc=$?
[[ $rc == 2 ]] && grep -q "no study 'nope'" "$tmp/err" || { echo "FAIL bad --only: rc $rc: $(cat "$tmp/err")"; exit 1; }
rc=0; bash "$root/launch_scripts/reproduce.sh" --no-build --analyse-only --runs "$tmp/runs" 2>"$tmp/err" || rc=$?
[[ $rc == 2 ]] && grep -q "quick/index.toml does not exist" "$tmp/err" || { echo "FAIL analyse-only without studies: rc $rc: $(cat "$tmp/err")"; exit 1; }
[[ ! -e $tmp/runs || -z $(ls -A "$tmp/runs") ]] || { echo "FAIL: the dry run left $(ls -A "$tmp/runs")"; exit 1; }
# An analysis while runs are unfinished would rewrite the tracked documents from part of the data.
mkdir -p "$tmp/runs/quick"
printf '[runs.a]\nstate = "complete"\n[runs.b]\nstate = "running"\n' >"$tmp/runs/quick/index.toml"
rc=0; bash "$root/launch_scripts/reproduce.sh" --no-build --analyse-only --runs "$tmp/runs" 2>"$tmp/err" || rc=$?
[[ $rc == 2 ]] && grep -q "quick (1 of 2 runs not complete); finite_size (not run)" "$tmp/err" && grep -q "refused" "$tmp/err" ||
  { echo "FAIL analyse-only with unfinished runs: rc $rc: $(cat "$tmp/err")"; exit 1; }
echo "ok   refused: an unknown study, an analysis without its studies, one while runs are unfinished"
