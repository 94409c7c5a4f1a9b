#!/usr/bin/env bash
# The live pipeline of one build against another's,
# interleaved: the default scene (sim, every node, recorder; private bus)
# run end to end ROUNDS times with each, no plots. Prints per run the
# production's wall time and the median collisions per second of the sim's
# progress lines, then the medians and their ratios (new / old: rate;
# old / new: wall time). Each run starts from scratch (--fresh); the first
# of each build pays for its compression like the others.
# Usage: bench/pipeline_ab.sh OLD_SRC OLD_BUILD NEW_SRC NEW_BUILD [ROUNDS=5] [SCENE=scenes/default.toml] [OUT=/tmp/dynhet-pipeline-ab]
set -euo pipefail
usage="usage: pipeline_ab.sh OLD_SRC OLD_BUILD NEW_SRC NEW_BUILD [ROUNDS] [SCENE] [OUT]"
osrc=${1:?$usage} obuild=${2:?$usage} nsrc=${3:?$usage} nbuild=${4:?$usage}
rounds=${5:-5} scene=${6:-scenes/default.toml} out=${7:-/tmp/dynhet-pipeline-ab}
[[ $rounds =~ ^[1-9][0-9]*$ ]] || { echo "pipeline_ab: ROUNDS must be a positive integer, not '$rounds'" >&2; exit 2; }
for s in "$osrc" "$nsrc"; do
  [[ -x $s/launch_scripts/run_scene.sh && -f $s/$scene ]] || { echo "pipeline_ab: no run_scene.sh or $scene in $s" >&2; exit 2; }
done
for b in "$obuild" "$nbuild"; do
  [[ -x $b/bin/sim_node ]] || { echo "pipeline_ab: no $b/bin/sim_node (build first)" >&2; exit 2; }
done
mkdir -p "$out"
res=$out/results.txt
: >"$res"
for ((r = 1; r <= rounds; ++r)); do
  for w in old new; do
    src=$osrc build=$obuild
    [[ $w == new ]] && src=$nsrc build=$nbuild
    dir=$out/$w
    if ! BUILD_DIR=$build "$src/launch_scripts/run_scene.sh" "$src/$scene" --no-build --no-plots --fresh --out "$dir" \
      >"$out/$w.run.log" 2>&1; then
      echo "pipeline_ab: round $r, $w: run_scene.sh failed (its log: $out/$w.run.log)" >&2
      exit 1
    fi
    wall=$(sed -n 's/.*production wall time \([0-9.]*\) s.*/\1/p' "$dir/sim_node.log" | tail -1)
    rate=$(awk '/^\[production/ { for (i = 1; i <= NF; ++i) if ($i ~ /^coll\/s=/) { v = substr($i, 8); if (v + 0 > 0) a[++n] = v + 0 } }
      END { if (!n) { print "nan"; exit } for (i = 1; i <= n; ++i) for (j = i + 1; j <= n; ++j) if (a[j] < a[i]) { t = a[i]; a[i] = a[j]; a[j] = t }
            print (n % 2 ? a[(n + 1) / 2] : 0.5 * (a[n / 2] + a[n / 2 + 1])) }' "$dir/sim_node.log")
    echo "round $r: $w production wall ${wall} s, median coll/s $rate"
    echo "$w $wall $rate" >>"$res"
  done
done
awk 'function med(w, k,   m, i, j, t, a) { m = n[w]; for (i = 1; i <= m; ++i) a[i] = v[w, k, i]
       for (i = 1; i <= m; ++i) for (j = i + 1; j <= m; ++j) if (a[j] < a[i]) { t = a[i]; a[i] = a[j]; a[j] = t }
       return m % 2 ? a[(m + 1) / 2] : 0.5 * (a[m / 2] + a[m / 2 + 1]) }
     { ++n[$1]; v[$1, 1, n[$1]] = $2; v[$1, 2, n[$1]] = $3 }
     END { printf "\n| build | production wall (median) | median coll/s (median) | runs |\n|---|---|---|---|\n"
           printf "| old | %.1f s | %.3g | %d |\n| new | %.1f s | %.3g | %d |\n", med("old", 1), med("old", 2), n["old"], med("new", 1), med("new", 2), n["new"]
           printf "wall time old / new: %.2f; rate new / old: %.2f\n", med("old", 1) / med("new", 1), med("new", 2) / med("old", 2) }' "$res"
