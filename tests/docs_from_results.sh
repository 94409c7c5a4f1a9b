#!/usr/bin/env bash
# docs/reproduction.md and docs/finite_size.md are generated from the results
# archive committed under results/: their text, regenerated here from
# results/ by the command the documents state (without figures), must equal
# the committed documents line for line. A document edited by hand, an
# archive entry added without the documents, or an analysis change that moves
# a number fails here, with the difference shown.
set -euo pipefail
root=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export DYNHET_ARCHIVE_CACHE=$tmp/cache # every entry decompressed here, its hash checked
bash "$root/launch_scripts/reproduce.sh" --analyse-only --partial --text-only --no-build \
  --runs "$tmp/runs" --docs "$tmp/docs" >"$tmp/log" 2>&1 || { cat "$tmp/log"; echo "FAIL: the analysis of results/ failed"; exit 1; }
grep -E '^analyse_study: [0-9]+ rows' "$tmp/log" || true
fail=0
for doc in reproduction.md finite_size.md; do
  if diff -u "$root/docs/$doc" "$tmp/docs/$doc" >"$tmp/diff"; then
    echo "ok   docs/$doc is what results/ gives"
  else
    head -n 80 "$tmp/diff"
    echo "FAIL: docs/$doc differs from what results/ gives ($(grep -c '^[-+][^-+]' "$tmp/diff") lines);" \
      "write it again with launch_scripts/reproduce.sh --analyse-only --partial (--text-only: the text alone)"
    fail=1
  fi
done
exit $fail
