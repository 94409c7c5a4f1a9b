#!/usr/bin/env bash
# Cage-relative measures and bond breaking live: the tiny scene
# with [observables] cage_relative = true and bond_breaking, end to end over
# LCM in a private network namespace. Its run.h5 holds overlap_cr, chi4_cr,
# msd_cr and displacement_cr beside the standard groups, F_s and alpha_2
# in msd and msd_cr, and bond_breaking; the standard results still equal
# brute force from the kept frames (tests/check_run.py), the cage-relative
# ones and F_s, alpha_2 equal brute force with cages from scipy's Delaunay,
# not the node's CGAL (tests/check_cage_relative.py), and so does bond
# breaking, from all pairs (tests/check_bond_breaking.py). Then the same run is
# stopped by SIGTERM mid-production and resumed with the same command: its
# run.h5 equals the uninterrupted one's bit for bit (the cage-relative
# accumulators are in the overlap node's checkpoint part, the cages rebuilt).
set -euo pipefail
root=$1 build=$2
if [[ -z ${DYNHET_IN_NETNS:-} ]]; then exec "$root/launch_scripts/netns.sh" bash "$0" "$@"; fi
export BUILD_DIR=$build
export LCM_DEFAULT_URL='udpm://239.255.76.67:7743?ttl=0'
tmp=$(mktemp -d)
trap '[[ -n ${KEEP_TMP:-} ]] && echo "kept $tmp" || rm -rf "$tmp"' EXIT
py=/usr/bin/python3
fail=0
check() { if eval "$1"; then echo "ok   $2"; else echo "FAIL $2"; fail=1; fi; }
# The tiny scene, cage-relative, with bond breaking (bonds that break at
# 1.2 sigma_ij, so that C_B crosses 1/e within its lags).
sed -e 's/^keep_frames = true/keep_frames = true\ncage_relative = true/' \
  -e 's/"clusters", "s4"\]/"clusters", "s4", "bond_breaking"]/' "$root/scenes/tiny.toml" >"$tmp/scene.toml"
printf '\n[bond_breaking]\na1 = 1.1\na2 = 1.2\n' >>"$tmp/scene.toml"
grep -q "^cage_relative = true" "$tmp/scene.toml" && grep -q '"bond_breaking"]' "$tmp/scene.toml"
# The resumed run's scene takes checkpoint cuts often (cuts change where
# the engine synchronises, so it is its own reference).
sed 's/^equilibration_time = 5.0/equilibration_time = 5.0\ncheckpoint_interval = 0.5/' "$tmp/scene.toml" >"$tmp/cuts.toml"
run_id=4712
run() { # SCENE DIR [more run_scene arguments]
  bash "$root/launch_scripts/run_scene.sh" "$1" --out "$2" --run-id $run_id --no-build --no-plots "${@:3}" >>"$2.log" 2>&1
}

run "$tmp/scene.toml" "$tmp/ref" || { tail -20 "$tmp/ref.log"; exit 1; }
check '$py "$root/tests/check_run.py" "$tmp/ref/run.h5" "$tmp/scene.toml" >"$tmp/check_run.out" 2>&1' \
  "the standard results equal brute force with the cage-relative ones beside them"
grep FAIL "$tmp/check_run.out" || true
check '$py "$root/tests/check_cage_relative.py" "$tmp/ref/run.h5"' "the cage-relative results equal brute force"
check 'PYTHONPATH="$root/python" $py -c "import sys; from dynhet.schema import main; sys.exit(main(sys.argv[1:]))" "$tmp/ref/run.h5"' \
  "the file fits the schema of run.h5, its _cr groups and bond breaking too (docs/run_h5.md)"
check '$py "$root/tests/check_bond_breaking.py" "$tmp/ref/run.h5"' "bond breaking equals brute force"
check 'grep -q "overlap_node (cage-relative): a=0.6 tau_alpha=" "$tmp/ref/overlap_node.log"' \
  "the overlap node states the cage-relative tau_alpha"

# The other cages: within the first minima of g_ab (the clusters node's
# neighbours), against brute force with the cutoffs the clusters node found.
sed 's/^cage_relative = true/cage_relative = true\ncage = "g_ab"/' "$tmp/scene.toml" >"$tmp/gab.toml"
run "$tmp/gab.toml" "$tmp/gab" || { tail -20 "$tmp/gab.log"; exit 1; }
check '$py "$root/tests/check_cage_relative.py" "$tmp/gab/run.h5"' "with g_ab cages: the cage-relative results equal brute force"
check 'grep -q "g_ab cages (r11" "$tmp/gab/overlap_node.log"' "the overlap node says which cages"

# Stopped by SIGTERM mid-production (the nodes slowed, which changes no
# result, so that production
# lasts seconds), then resumed by the same command.
run "$tmp/cuts.toml" "$tmp/straight" || { tail -20 "$tmp/straight.log"; exit 1; }
set -m
bash "$root/launch_scripts/run_scene.sh" "$tmp/cuts.toml" --out "$tmp/term" --run-id $run_id --no-build --no-plots \
  --test-node-delay 0.1 >>"$tmp/term.log" 2>&1 &
pid=$!
set +m
# The SIGTERM once the run is in production with a whole checkpoint cut
# (checkpoints/cut-*/WHOLE, and the nodes' parts at frame boundaries in
# checkpoints/frames/), so that the second command has a cut to resume
# from however long the processes take to start; at most 90 s.
in_cut=0
for _ in $(seq 1800); do
  if ls "$tmp"/term/checkpoints/cut-*/WHOLE >/dev/null 2>&1 && ls "$tmp"/term/checkpoints/frames/*.part >/dev/null 2>&1; then
    in_cut=1
    break
  fi
  kill -0 "$pid" 2>/dev/null || break
  sleep 0.05
done
if ((!in_cut)); then
  echo "FAIL no whole checkpoint cut in production within 90 s of the start (or the run ended first): no SIGTERM sent"
  kill -TERM -- -$pid 2>/dev/null || true
  wait $pid || true
  tail -20 "$tmp/term.log"
  exit 1
fi
kill -TERM -- -$pid 2>/dev/null || true
set +e; wait $pid; rc=$?; set -e
check '[[ $rc == 75 ]]' "SIGTERM mid-production: run_scene.sh exits 75, resumable (got $rc)"
for _ in 1 2 3; do run "$tmp/cuts.toml" "$tmp/term" --test-node-delay 0.1 && break; done
check 'grep -q "resuming run .* from checkpoint cut" "$tmp/term.log"' "the second command resumed from a cut"
check '$py "$root/tests/compare_h5.py" "$tmp/straight/run.h5" "$tmp/term/run.h5" >"$tmp/cmp.out" 2>&1' \
  "stopped and resumed: run.h5 equals the uninterrupted run's, the _cr groups too"
((fail == 0)) || { tail -20 "$tmp/cmp.out"; tail -20 "$tmp/term.log"; }
exit $fail
