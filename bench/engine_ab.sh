#!/usr/bin/env bash
# The engine's speed rows, the engine of one build against another's,
# interleaved (one run of each per round, ROUNDS rounds), then the median
# of each row: elastic at N = 10^4 (200 collisions per particle), 10^5 (20)
# and 10^6 (5), phi 0.78 and 0.805; driven (eps 0.9) at 10^5 (20) and 10^6
# (5), phi 0.78 and 0.80, with neighbour kick pairs and with pairs from the
# whole system ("any"). Rates are per CPU second of the benchmark's thread:
# collisions per second (elastic), collisions plus kicks per second
# (driven). Both builds start from the same compressed (and, driven,
# relaxed) states, kept in CACHE by whichever runs first (the first round
# prepares them, untimed). Prints one line
# per run, then the table of medians with the ratios new / old and, for the
# driven rows of the new build, neighbours / any; then the same table of the
# event loop's rates alone (the timed span less its synchronisations,
# bench_engine's c+k/s_loop), where both builds print them.
# Usage: bench/engine_ab.sh OLD_BUILD NEW_BUILD [ROUNDS=5] [CACHE=/tmp/dynhet-bench]
#        ROWS='elastic 10000 0.78 50;neighbours 1000000 0.78 4' bench/engine_ab.sh ...  (other rows:
#        "mode N phi collisions-per-particle", separated by ';')
#        bench/engine_ab.sh --table RUNS_FILE   (the table again from a run's file of runs)
set -euo pipefail
table() { # the medians of a file of runs "build mode N phi rate"
  echo
  echo "| model | N | phi | old (median) | new (median) | new / old | runs each |"
  echo "|---|---|---|---|---|---|---|"
  awk '{ k = $2 " " $3 " " $4; v[k, $1, ++n[k, $1]] = $5; keys[k] = 1 }
    function median(k, w,   m, i, j, t, a) {
      m = n[k, w]; for (i = 1; i <= m; ++i) a[i] = v[k, w, i]
      for (i = 1; i <= m; ++i) for (j = i + 1; j <= m; ++j) if (a[j] < a[i]) { t = a[i]; a[i] = a[j]; a[j] = t }
      return m % 2 ? a[(m + 1) / 2] : 0.5 * (a[m / 2] + a[m / 2 + 1])
    }
    END { for (k in keys) { split(k, f, " "); o = median(k, "old"); w = median(k, "new")
            printf "| %s | %d | %s | %.3g | %.3g | %.2f | %d |\n", f[1], f[2], f[3], o, w, w / o, n[k, "new"]
            med[f[1] " " f[2] " " f[3]] = w }
          for (k in keys) { split(k, f, " "); a = "any " f[2] " " f[3]
            if (f[1] == "neighbours" && (a in med))
              printf "~neighbours / any, new build, N = %d, phi = %s: %.2f\n", f[2], f[3], med[k] / med[a] } }' "$1" |
    LC_ALL=C sort | sed "s/^~//"
}
loop_table() { # the same table of the event loop's rates alone (the synchronisations left out), where both builds print them
  awk '$6 != "-" && NF >= 6 {print $1, $2, $3, $4, $6}' "$1" >"$1.loop"
  [[ $(awk '{print $1}' "$1.loop" | sort -u | wc -l) == 2 ]] || return 0
  echo
  echo "The event loop alone (c+k/s_loop: the timed span less its synchronisations):"
  table "$1.loop"
}
if [[ ${1:-} == --table ]]; then table "${2:?usage: engine_ab.sh --table RUNS_FILE}"; loop_table "$2"; exit 0; fi
old=${1:?usage: engine_ab.sh OLD_BUILD NEW_BUILD [ROUNDS] [CACHE]} new=${2:?usage: engine_ab.sh OLD_BUILD NEW_BUILD [ROUNDS] [CACHE]}
rounds=${3:-5} cache=${4:-/tmp/dynhet-bench}
for b in "$old" "$new"; do
  [[ -x $b/bin/bench_engine ]] || { echo "engine_ab: no $b/bin/bench_engine (build first)" >&2; exit 2; }
done
[[ $rounds =~ ^[1-9][0-9]*$ ]] || { echo "engine_ab: ROUNDS must be a positive integer, not '$rounds'" >&2; exit 2; }
mkdir -p "$cache"
out=$cache/engine_ab.$$.txt  # the runs, kept: bench/engine_ab.sh --table FILE prints the table again
: >"$out"
# row: label N phi coll mode (elastic | neighbours | any)
rows=("elastic 10000 0.78 200" "elastic 10000 0.805 200" "elastic 100000 0.78 20" "elastic 100000 0.805 20"
      "elastic 1000000 0.78 5" "elastic 1000000 0.805 5"
      "neighbours 100000 0.78 20" "neighbours 100000 0.80 20" "any 100000 0.78 20" "any 100000 0.80 20"
      "neighbours 1000000 0.78 5" "neighbours 1000000 0.80 5" "any 1000000 0.78 5" "any 1000000 0.80 5")
if [[ -n ${ROWS:-} ]]; then IFS=';' read -r -a rows <<<"$ROWS"; fi
run() { # which build mode N phi coll
  local a=(--n "$4" --phi "$5" --coll "$6" --sync 10 --tile-from 10000 --cache "$cache")
  case $3 in
  elastic) ;;
  neighbours) a+=(--eps 0.9 --driven --pairs neighbours) ;;
  any) a+=(--eps 0.9 --driven --pairs any) ;;
  esac
  # columns: N phi prep_s coll/s kicks/s c+k/s ... and, where the build prints it, c+k/s_loop (18th)
  "$2/bin/bench_engine" "${a[@]}" 2>&1 | tail -1 |
    awk -v w="$1" -v m="$3" '{print w, m, $1, $2, ($5 == 0 ? $4 : $6), (NF >= 18 ? $18 : "-")}'
}
for ((r = 1; r <= rounds; ++r)); do
  for row in "${rows[@]}"; do
    read -r mode n phi coll <<<"$row"
    for w in old new; do
      b=$old; [[ $w == new ]] && b=$new
      line=$(run "$w" "$b" "$mode" "$n" "$phi" "$coll")
      echo "round $r: $line"
      echo "$line" >>"$out"
    done
  done
done
table "$out"
loop_table "$out"
echo "(runs in $out)"
