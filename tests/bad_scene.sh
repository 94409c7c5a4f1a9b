#!/usr/bin/env bash
# run_scene.sh refuses a bad scene before starting anything, naming the key.
set -uo pipefail
root=$1 build=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
printf '[system]\nn_particles = 500\nrestitution = 1.5\n' >"$tmp/bad.toml"
BUILD_DIR=$build bash "$root/launch_scripts/run_scene.sh" "$tmp/bad.toml" --out "$tmp/out" --no-build 2>"$tmp/err"
rc=$?
cat "$tmp/err"
[[ $rc -eq 2 ]] || { echo "FAIL: exit $rc, expected 2"; exit 1; }
grep -q "system.restitution" "$tmp/err" || { echo "FAIL: the message does not name the key"; exit 1; }
grep -q "1.5" "$tmp/err" || { echo "FAIL: the message does not name the value"; exit 1; }
[[ ! -e $tmp/out/run.h5 ]] || { echo "FAIL: something ran"; exit 1; }
echo "PASS"
