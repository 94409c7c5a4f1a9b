#!/usr/bin/env bash
# Runs a study: a sweep of scenes (studies/README.md), on this machine or on
# a Slurm cluster, resumable: the same command again skips complete runs,
# resumes interrupted ones from their checkpoints and reruns failed ones.
#
# Usage: launch_scripts/run_study.sh STUDY.toml [options]
#   --executor local   (default) up to --jobs runs at once on this machine,
#                      each on its own private network namespace, the
#                      longest estimated run first (low phi first when run
#                      lengths are interpolated)
#   --order shortest   the shortest estimated run first instead: the most
#                      runs complete and archived by any moment, where the
#                      machine may be lost before the study ends
#   --first GLOB       the runs whose names match this shell pattern before
#                      all others (repeatable, the first pattern's first),
#                      e.g. --first 'phi0.7900_*_n65536_*'
#   --executor slurm   one sbatch job array (a task per run) and a dependent
#                      job that writes the index; --partition, --time, --mem
#                      and --sbatch=FLAG (repeatable) pass through
#   --jobs K           runs at once (local; default cores/2) or array tasks
#                      at once (slurm; default no limit)
#   --out DIR          the study directory (default runs/study-<name>)
#   --dry-run          print every run with its times, estimated CPU time and
#                      memory, and the totals; start nothing
#   --fresh            the --out directory holds another study (or anything
#                      without a study.toml, which is refused): move what it
#                      holds into DIR/old-<time>/ and start this study there
#   --no-figures       the study analysis at the end (analyse_study.sh) writes
#                      study.h5, reproduction.md and finite_size.md but draws
#                      no figure (a fraction of its time; analyse_study.sh
#                      STUDY_DIR draws them later); on Slurm, the index job's
#                      analysis too
#   --no-build         skip setup.sh (packages and build)
# The study directory holds study.toml (a copy; a study file that now says
# something else is refused, one whose comments or spacing changed is
# not), runs/<run>/{scene.toml,status.toml,run.h5,logs}, pilots/ and
# index.toml, which the analysis reads.
# Exit: 0 every run complete (and analysed); 1 a run or the analysis
# failed; 2 bad arguments, a refused study or --out (nothing run); 75
# interrupted: the same command resumes.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$root/build}
args=() build_first=1
for a in "$@"; do
  case "$a" in
  --no-build) build_first=0 ;;
  -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;;
  *) args+=("$a") ;;
  esac
done
((${#args[@]})) || { sed -n '6,6p' "$0" >&2; exit 2; }
if ((build_first)); then BUILD_DIR=$build "$root/launch_scripts/setup.sh"; fi
BUILD_DIR=$build exec /usr/bin/python3 "$root/launch_scripts/study.py" run "${args[@]}"
