#!/usr/bin/env bash
# The paper's results from a study's runs: reads STUDY_DIR/index.toml and
# every complete run.h5, writes STUDY_DIR/study.h5 (per-point quantities,
# every cross-run fit with its jackknife error over seeds, range and
# chi2), STUDY_DIR/figures/*.png, STUDY_DIR/reproduction.md (the table
# against the paper) and STUDY_DIR/finite_size.md (every measure against N
# where a density was run at several N, with a verdict).
#
# Usage: launch_scripts/analyse_study.sh STUDY_DIR [--also STUDY_DIR2 ...] [--table docs/reproduction.md]
#          [--finite-size docs/finite_size.md] [--discussion FILE] [--restate OLD.md [--restate-via LABEL=T.md ...]]
#   --also DIR         add the complete runs of another study (e.g. other N)
#   --table FILE       write the reproduction table there as well
#   --finite-size FILE write the finite-size report there as well (figures in finite_size/ beside it)
#   --discussion FILE  append this Markdown (what we found about each disagreement)
#   --restate OLD.md   append, for each row an earlier table judged "differs", its verdict now
#   --restate-via LABEL=T.md  a table made in between (repeatable, in order): its verdicts in a
#                      column, and at which step each verdict moved
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
case "${1:-}" in
-h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;;
"") grep -m1 '^# Usage:' "$0" | sed 's/^# //' >&2; exit 2 ;;
esac
exec /usr/bin/python3 "$root/launch_scripts/analyse_study.py" "$@"
