#!/usr/bin/env bash
# The paper reproduced from nothing: runs every study that docs/reproduction.md
# and docs/finite_size.md are generated from, one after another, then the
# analysis that writes both documents. Every step is resumable: after any
# interruption (a killed process, a Slurm time limit, a lost session) the same
# command goes on where it stopped; complete studies are skipped.
#
# Usage: launch_scripts/reproduce.sh [--runs DIR] [--jobs K] [--only S1,S2] [--dry-run]
#          [--analyse-only [--partial]] [--no-build] [--executor slurm [run_study.sh's Slurm flags]]
#   --runs DIR       where the studies go, DIR/<study> (default: runs/ beside the
#                    checkout, ../runs, as the documents' headers name them)
#   --jobs K         runs at once (run_study.sh --jobs)
#   --only S1,S2     these studies only (names below), e.g. --only quick,scale
#   --dry-run        each study's runs and estimated CPU time, and their sum; starts nothing
#   --analyse-only   the analysis alone; refused while a study has runs not complete
#                    (their names are printed), unless --partial (unfinished sizes are
#                    then held back and named in the documents)
# The analysis rewrites the tracked documents, so it runs only once all seven
# studies are complete (after --only too, if the others are).
#   --executor slurm submits each study's job array and returns; run this again
#                    with --analyse-only once every array has ended
# Each study's directory, DIR/<study>, is refused if it holds anything but that
# study, and so is a document path holding anything but a generated document
# (run_study.sh, analyse_study.sh); --fresh passes on to both: what is there
# moves aside (DIR/<study>/old-<time>/, FILE.old-<time>), never deleted.
# Exit: 0 done (or submitted); 1 a run or the analysis failed; 2 bad arguments
# or a refused destination; 75 interrupted: the same command goes on.
# Studies, in this order: quick (N = 4096: every row of the paper, the leading
# study), finite_size, cutoff, cage, cage_bonds, d_size, scale (issue 27: N to
# 262144, the longest by far). The analysis takes quick with every other study
# --also, at each density's largest N (--largest-n), and restates, row by row,
# the table of commit 556a0f6 (the N = 4096 table that judged 16 of 53 rows
# "differs"; taken from git). Writes docs/reproduction.md (with
# docs/reproduction_findings.md appended), docs/finite_size.md and its figures.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
usage() { awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; }
all=(quick finite_size cutoff cage cage_bonds d_size scale) # quick leads the analysis; the rest are --also
studies=("${all[@]}")
before_commit=556a0f6
runs=$root/../runs only="" dry=0 analyse_only=0 partial=0 build=1 pass=() fresh=()
while (($#)); do
  case "$1" in
  --runs) runs=${2:?--runs needs a directory}; shift ;;
  --only) only=${2:?--only needs study names}; shift ;;
  --dry-run) dry=1 ;;
  --analyse-only) analyse_only=1 ;;
  --partial) partial=1 ;;
  --no-build) build=0 ;;
  --fresh) fresh=(--fresh) ;;
  -h | --help) usage; exit 0 ;;
  *) pass+=("$1") ;;
  esac
  shift
done
if [[ -n $only ]]; then
  IFS=, read -ra want <<<"$only"
  for s in "${want[@]}"; do
    [[ " ${all[*]} " == *" $s "* ]] || { echo "reproduce: no study '$s'; the studies: ${all[*]}" >&2; exit 2; }
  done
  studies=("${want[@]}")
fi
if ((build)); then BUILD_DIR=${BUILD_DIR:-$root/build} "$root/launch_scripts/setup.sh"; fi
((dry)) || mkdir -p "$runs"
runs=$(realpath -m "$runs") # the studies run from here, the analysis from $root

if ((!analyse_only)); then
  total=0
  for s in "${studies[@]}"; do
    echo "== study $s -> $runs/$s"
    if ((dry)); then
      out=$(bash "$root/launch_scripts/run_study.sh" "$root/studies/$s.toml" --no-build --dry-run --out "$runs/$s" "${pass[@]}")
      line=$(grep '^# total CPU' <<<"$out") || { echo "$out"; echo "reproduce: no total in $s's dry run" >&2; exit 1; }
      echo "$line"
      hours=$(sed -E 's/.*\(([0-9.]+) CPU-hours\).*/\1/' <<<"$line")
      total=$(awk -v a="$total" -v b="$hours" 'BEGIN { printf "%.2f", a + b }')
    else
      bash "$root/launch_scripts/run_study.sh" "$root/studies/$s.toml" --no-build --out "$runs/$s" "${fresh[@]}" "${pass[@]}"
    fi
  done
  if ((dry)); then
    echo "# all ${#studies[@]} studies: $total CPU-hours by the studies' estimates (pilots not counted)"
    exit 0
  fi
  [[ " ${pass[*]} " == *" slurm "* || " ${pass[*]} " == *"--executor=slurm"* ]] && {
    echo "reproduce: submitted; once every array has ended: launch_scripts/reproduce.sh --analyse-only --runs $runs"
    exit 0
  }
fi

[[ -f $runs/quick/index.toml ]] || { echo "reproduce: $runs/quick/index.toml does not exist: run the studies first" >&2; exit 2; }
# Every run of every study complete? (each index.toml: [runs.<name>] tables with a state)
unfinished=$(/usr/bin/python3 - "$runs" "${all[@]}" <<'PY'
import os, sys, tomllib
for s in sys.argv[2:]:
    idx = os.path.join(sys.argv[1], s, "index.toml")
    if not os.path.exists(idx):
        print(f"{s} (not run)")
        continue
    with open(idx, "rb") as fh:
        runs = tomllib.load(fh).get("runs", {})
    left = sum(1 for m in runs.values() if m.get("state") != "complete")
    if left:
        print(f"{s} ({left} of {len(runs)} runs not complete)")
PY
)
if [[ -n $unfinished ]]; then
  echo "reproduce: not complete: $(paste -sd ';' <<<"$unfinished" | sed 's/;/; /g')" >&2
  if ((!analyse_only)); then
    echo "reproduce: the documents are left as they are; --analyse-only --partial writes them from what is complete" >&2
    exit 0
  fi
  ((partial)) || { echo "reproduce: refused: --partial to write the documents from what is complete" >&2; exit 2; }
fi
rel=$(realpath -m --relative-to="$root" "$runs") # the documents' headers name the studies relative to the checkout
also=()
for s in "${all[@]:1}"; do
  [[ -f $runs/$s/index.toml ]] && also+=(--also "$rel/$s")
done
restate=()
if git -C "$root" cat-file -e "$before_commit:docs/reproduction.md" 2>/dev/null; then
  # (its own file, a generated table: anything else by that name is not written over)
  if [[ -e $runs/reproduction_before.md ]] && ! grep -q 'Generated by `launch_scripts/analyse_study' "$runs/reproduction_before.md"; then
    echo "reproduce: refused: $runs/reproduction_before.md exists and is not a generated table (the restatement's base goes there): move it away" >&2
    exit 2
  fi
  git -C "$root" show "$before_commit:docs/reproduction.md" >"$runs/reproduction_before.md"
  restate=(--restate "$rel/reproduction_before.md")
else
  echo "reproduce: not a git checkout with commit $before_commit: no row-by-row restatement" >&2
fi
cd "$root"
exec bash launch_scripts/analyse_study.sh "$rel/quick" "${also[@]}" --largest-n --table docs/reproduction.md \
  --finite-size docs/finite_size.md --discussion docs/reproduction_findings.md "${restate[@]}" "${fresh[@]}"
