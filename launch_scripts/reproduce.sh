#!/usr/bin/env bash
# The paper reproduced from nothing: runs every study that docs/reproduction.md
# and docs/finite_size.md are generated from, one after another, each run
# reduced into the results archive results/<study> the moment it completes,
# then the analysis that writes both documents from results/. Every step is
# resumable: after any interruption (a killed process, a Slurm time limit, a
# lost session, a replaced machine) the same command goes on where it
# stopped; archived runs are never run again.
#
# Usage: launch_scripts/reproduce.sh [--runs DIR] [--results DIR] [--jobs K] [--only S1,S2] [--dry-run]
#          [--analyse-only [--partial] [--text-only]] [--no-build] [--executor slurm [run_study.sh's Slurm flags]]
#   --runs DIR       scratch run directories, DIR/<study> (default: runs/ beside the
#                    checkout, ../runs)
#   --results DIR    the archives, DIR/<study> (default: the repository's results/)
#   --docs DIR       write the documents here (default: docs/; a test writes them
#                    elsewhere and compares them with docs/)
#   --jobs K         runs at once (run_study.sh --jobs)
#   --only S1,S2     these studies only (names below), e.g. --only quick,size_standard
#   --dry-run        each study's runs and estimated CPU time, and their sum; starts nothing
#   --analyse-only   the analysis alone, from the archives; refused while a study has
#                    runs not archived (their count is printed), unless --partial
#                    (unfinished sizes are then held back and named in the documents)
#   --text-only      the documents' text alone, no figure drawn (the figures stay as the
#                    last full analysis drew them); the text is the same as with figures
# The analysis rewrites the tracked documents, so it runs only once all the
# studies are archived whole (after --only too, if the others are).
#   --executor slurm submits each study's job array and returns; run this again
#                    with --analyse-only once every array has ended
# Each study's directory, DIR/<study>, is refused if it holds anything but that
# study, and so is a document path holding anything but a generated document
# (run_study.sh, analyse_study.sh); --fresh passes on to both: what is there
# moves aside (DIR/<study>/old-<time>/, FILE.old-<time>), never deleted.
# Exit: 0 done (or submitted); 1 a run or the analysis failed; 2 bad arguments
# or a refused destination; 75 interrupted: the same command goes on.
# Studies, in this order: quick (N = 4096: every row of the paper, the leading
# study), size_standard (the standard measures to N = 262144), size_cage (the
# cage-relative ones and bond breaking to N = 65536), cutoff, d_size. The
# analysis takes results/quick with every other archive --also, at each
# density's largest N (--largest-n), writes its scratch output (study.h5,
# figures) to DIR/analysis and restates, row by row, the table of commit
# 556a0f6 (the N = 4096 table that judged 16 of 53 rows "differs"; taken from
# git), and sets every row against the table of commit 9a3e6a1 (quick
# alone, N = 4096 at every density, the last table before --largest-n had
# larger boxes to take): which verdicts the larger N changed. Writes
# docs/reproduction.md (with docs/reproduction_findings.md appended),
# docs/finite_size.md and its figures.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
usage() { awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; }
all=(quick size_standard size_cage cutoff d_size) # quick leads the analysis; the rest are --also
studies=("${all[@]}")
before_commit=556a0f6
n4096_commit=9a3e6a1 # results/quick complete, every density at N = 4096 (no larger N finished yet)
runs=$root/../runs results=$root/results docs=$root/docs only="" dry=0 analyse_only=0 partial=0 build=1 pass=() fresh=()
figures=()
while (($#)); do
  case "$1" in
  --runs) runs=${2:?--runs needs a directory}; shift ;;
  --results) results=${2:?--results needs a directory}; shift ;;
  --docs) docs=${2:?--docs needs a directory}; shift ;;
  --only) only=${2:?--only needs study names}; shift ;;
  --dry-run) dry=1 ;;
  --analyse-only) analyse_only=1 ;;
  --partial) partial=1 ;;
  --text-only) figures=(--no-figures) ;;
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
runs=$(realpath -m "$runs") results=$(realpath -m "$results") # the studies run from here, the analysis from $root

if ((!analyse_only)); then
  total=0
  for s in "${studies[@]}"; do
    echo "== study $s -> $runs/$s"
    if ((dry)); then
      out=$(bash "$root/launch_scripts/run_study.sh" "$root/studies/$s.toml" --no-build --dry-run --out "$runs/$s" \
        --archive "$results/$s" "${pass[@]}")
      line=$(grep '^# total CPU' <<<"$out") || { echo "$out"; echo "reproduce: no total in $s's dry run" >&2; exit 1; }
      echo "$line"
      hours=$(sed -E 's/.*\(([0-9.]+) CPU-hours\).*/\1/' <<<"$line")
      total=$(awk -v a="$total" -v b="$hours" 'BEGIN { printf "%.2f", a + b }')
    else
      bash "$root/launch_scripts/run_study.sh" "$root/studies/$s.toml" --no-build --out "$runs/$s" \
        --archive "$results/$s" "${fresh[@]}" "${pass[@]}"
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

[[ -f $results/quick/index.toml ]] || { echo "reproduce: $results/quick/index.toml does not exist: run the studies first" >&2; exit 2; }
# Every planned run of every study archived? (each archive's study file against its index)
unfinished=$(PYTHONPATH=$root/python /usr/bin/python3 - "$results" "${all[@]}" <<'PY'
import os, sys
from dynhet.archive import ArchiveError, is_archive, study_summary
for s in sys.argv[2:]:
    d = os.path.join(sys.argv[1], s)
    if not is_archive(d):
        print(f"{s} (not run)")
        continue
    try:
        _, _, n, planned, _, _ = study_summary(d)
    except ArchiveError as e:
        print(f"{s} ({e})")
        continue
    if planned is None or n < planned:
        print(f"{s} ({n} of {planned} runs archived)")
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
rel=$(realpath -m --relative-to="$root" "$results") # the documents' headers name the archives relative to the checkout
also=()
for s in "${all[@]:1}"; do
  [[ -f $results/$s/index.toml ]] && also+=(--also "$rel/$s")
done
mkdir -p "$runs"
restate=()
if git -C "$root" cat-file -e "$before_commit:docs/reproduction.md" 2>/dev/null; then
  restate=(--restate "$before_commit:docs/reproduction.md")
else
  echo "reproduce: not a git checkout with commit $before_commit: no row-by-row restatement" >&2
fi
if git -C "$root" cat-file -e "$n4096_commit:docs/reproduction.md" 2>/dev/null; then
  restate+=(--compare "N = 4096 (quick alone)=$n4096_commit:docs/reproduction.md")
else
  echo "reproduce: not a git checkout with commit $n4096_commit: no comparison with the N = 4096 table" >&2
fi
cd "$root"
mkdir -p "$docs"
stated="launch_scripts/reproduce.sh --analyse-only"
[[ -n $unfinished ]] && stated+=" --partial" # what made the documents: with every study whole, --partial changed nothing
exec bash launch_scripts/analyse_study.sh "$rel/quick" "${also[@]}" --largest-n --out "$runs/analysis" \
  --table "$docs/reproduction.md" --finite-size "$docs/finite_size.md" --discussion docs/reproduction_findings.md \
  --command "$stated (analyse_study.sh $rel/quick ${also[*]} --largest-n)" \
  "${restate[@]}" "${fresh[@]}" "${figures[@]}"
