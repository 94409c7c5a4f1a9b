#!/usr/bin/env bash
# Each study archived under results/ analysed on its own, as run_study.sh
# analyses a study when its runs are done: every step of the analysis runs
# or says why it does not apply (an observable the study does not compute),
# none fails. docs_from_results analyses them together, with quick as the
# main study, which does not run the steps of a study that lacks chi4 or S4
# on its own. quick is left out here: it is that main study.
set -euo pipefail
root=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export DYNHET_ARCHIVE_CACHE=$tmp/cache # every entry decompressed here, its hash checked
fail=0
for dir in "$root"/results/*/; do
  s=$(basename "$dir")
  [[ -f $dir/index.toml && $s != quick ]] || continue
  if bash "$root/launch_scripts/analyse_study.sh" "$dir" --no-figures --out "$tmp/$s" >"$tmp/$s.log" 2>&1 &&
    ! grep -q "analyse_study: FAILED\|Traceback" "$tmp/$s.log"; then
    echo "ok   results/$s analysed on its own: $(grep -Eo '[0-9]+ rows' "$tmp/$s.log" | head -1)"
  else
    tail -n 30 "$tmp/$s.log"
    echo "FAIL results/$s analysed on its own: a step failed"
    fail=1
  fi
done
exit $fail
