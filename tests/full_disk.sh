#!/usr/bin/env bash
# A full disk: a run whose kept frames do not fit on a 12 MB tmpfs (in a
# private mount namespace, with a private network namespace) must end
# non-zero with run.h5 readable, marked incomplete, naming ENOSPC; no
# process may abort. Then a sim whose checkpoint does not fit names the
# full disk, not a broken file.
set -euo pipefail
root=$1 build=$2
if [[ -z ${DYNHET_IN_MOUNTNS:-} ]]; then exec env DYNHET_IN_MOUNTNS=1 unshare -m bash "$0" "$@"; fi
if [[ -z ${DYNHET_IN_NETNS:-} ]]; then exec "$root/launch_scripts/netns.sh" bash "$0" "$@"; fi
export BUILD_DIR=$build
export LCM_DEFAULT_URL='udpm://239.255.76.67:7697?ttl=0'
tmp=$(mktemp -d)
(umask 077 && head -c 32 /dev/urandom >"$tmp/bus.key") # the run's key (docs/bus.md)
export DYNHET_KEY_FILE=$tmp/bus.key
disk=$tmp/disk
mkdir -p "$disk"
mount -t tmpfs -o size=12m tmpfs "$disk"
trap 'umount "$disk" 2>/dev/null || true; rm -rf "$tmp"' EXIT
fail=0
check() { if eval "$1"; then echo "ok   $2"; else echo "FAIL $2"; fail=1; fi; }
sed -e 's/^n_particles = 300/n_particles = 10000/' "$root/scenes/tiny.toml" >"$tmp/big.toml"
bash "$root/launch_scripts/run_scene.sh" "$tmp/big.toml" --out "$disk/out" --no-build >"$tmp/run.log" 2>&1 && rc=0 || rc=$?
check '[[ $rc != 0 ]]' "a run that fills the disk exits non-zero (got $rc)"
check '! grep -qiE "Aborted|core dumped|infinite loop" "$tmp/run.log" "$disk"/out/*.log' "no process aborts"
check 'grep -q "no space left on device (ENOSPC)" "$disk/out/recorder.log"' "the recorder names ENOSPC"
check '/usr/bin/python3 -c "
import h5py, sys
f = h5py.File(\"$disk/out/run.h5\", \"r\")
m = f.attrs[\"missing\"]
m = m.decode() if isinstance(m, bytes) else str(m)
sys.exit(0 if int(f.attrs[\"complete\"]) == 0 and \"ENOSPC\" in m and \"particles/all/position\" in f else 1)"' \
  "run.h5 stays readable, says incomplete and why, and holds the frames written"
# The sim alone, its checkpoint on a full disk.
head -c $(( $(stat -f -c '%a' "$disk") * $(stat -f -c '%S' "$disk") - 200000 )) /dev/zero >"$disk/filler" 2>/dev/null || true
"$build/bin/sim_node" "$root/scenes/tiny.toml" --checkpoint "$disk/ck.h5" >"$tmp/sim.log" 2>&1 && rc=0 || rc=$?
check '[[ $rc != 0 ]] && grep -q "no space left on device (ENOSPC) for the checkpoint" "$tmp/sim.log"' \
  "a checkpoint on a full disk names ENOSPC (exit $rc: $(grep -o "ck.h5: .*" "$tmp/sim.log" | head -1))"
((fail == 0)) || { tail -20 "$tmp/run.log"; tail -5 "$disk"/out/recorder.log; }
exit $fail
