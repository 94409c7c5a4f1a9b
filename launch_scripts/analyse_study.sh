#!/usr/bin/env bash
# The paper's results from a study's runs: reads STUDY_DIR/index.toml and
# every complete run.h5, writes STUDY_DIR/study.h5 (per-point quantities,
# every cross-run fit with its jackknife error over seeds, range and
# chi2), STUDY_DIR/figures/*.png and STUDY_DIR/reproduction.md (the table
# against the paper). run_study.sh runs it when a study's runs are done.
#
# Usage: launch_scripts/analyse_study.sh STUDY_DIR [--table docs/reproduction.md] [--discussion FILE] [--restate OLD.md]
#   --table FILE       write the reproduction table there as well
#   --discussion FILE  append this Markdown (what we found about each disagreement)
#   --restate OLD.md   append, for each row an earlier table judged "differs", its verdict now
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
case "${1:-}" in
-h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;;
"") grep -m1 '^# Usage:' "$0" | sed 's/^# //' >&2; exit 2 ;;
esac
exec /usr/bin/python3 "$root/launch_scripts/analyse_study.py" "$@"
