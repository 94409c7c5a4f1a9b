#!/usr/bin/env bash
# Every launch script a user runs (launch_scripts/*.sh, and the *.py with a
# main) answers --help with its usage: exit 0 within seconds, a line with
# "usage" on stdout, no line of its own code (set -e..., x=$(...)), and
# nothing started: no file appears in the directory it ran in (record.sh
# would start lcm-logger on a log named --help, setup.sh a build).
set -euo pipefail
root=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0 n=0
for s in "$root"/launch_scripts/*.sh "$root"/launch_scripts/*.py; do
  [[ $s == *.py ]] && ! grep -q '__name__ == "__main__"' "$s" && continue # a library (plot_common)
  name=$(basename "$s")
  if [[ $s == *.py ]]; then cmd=(/usr/bin/python3 "$s" --help); else cmd=(bash "$s" --help); fi
  mkdir "$tmp/$name"
  (cd "$tmp/$name" && BUILD_DIR="$tmp/$name/build" timeout 20 "${cmd[@]}" >"$tmp/$name.out" 2>"$tmp/$name.err") && rc=0 || rc=$?
  n=$((n + 1))
  why=""
  [[ $rc == 0 ]] || why+=" exit $rc;"
  grep -qi "usage" "$tmp/$name.out" || why+=" no usage line;"
  ! grep -qE '^ *(set -[a-z]|[a-z_]+=\$\(|exec |case |esac|if \[\[)' "$tmp/$name.out" || why+=" prints code;"
  [[ -z $(ls -A "$tmp/$name") ]] || why+=" left files: $(ls -A "$tmp/$name" | tr '\n' ' ');"
  if [[ -z $why ]]; then echo "ok   $name --help"; else echo "FAIL $name --help:$why"; head -5 "$tmp/$name.out" "$tmp/$name.err"; fail=1; fi
done
((n >= 15)) || { echo "FAIL only $n scripts found"; fail=1; }
exit $fail
