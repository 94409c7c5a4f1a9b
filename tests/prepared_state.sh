#!/usr/bin/env bash
# Prepared states: sim_node --prepare-only compresses once; runs of two
# restitutions that start from it (system.initial_state) end bit for bit
# like the runs that compress themselves; an H5MD file of positions starts
# a run; an equilibrated state (--prepare-only --equilibrate, also made in
# two steps) starts a run of the same dynamics that ends bit for bit like
# the run that equilibrates itself; a state for another system or other
# dynamics, one equilibrated beyond the scene's equilibration, overlapping
# positions, a checkpoint taken in production and a missing file are
# refused with messages that name the problem. Runs in a private network namespace.
set -euo pipefail
root=$1 bin=$2
if [[ -z ${DYNHET_IN_NETNS:-} ]]; then exec "$root/launch_scripts/netns.sh" bash "$0" "$@"; fi
tmp=$(mktemp -d)
(umask 077 && head -c 32 /dev/urandom >"$tmp/bus.key") # the run's key (docs/bus.md)
export DYNHET_KEY_FILE=$tmp/bus.key
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
url='udpm://239.255.76.67:7693?ttl=0'
py=/usr/bin/python3
fail=0
check() { if eval "$1"; then echo "ok   $2"; else echo "FAIL $2"; fail=1; fi; }
scene() { # eps, extra line
  cat <<TOML
[system]
n_particles = 1500
packing_fraction = 0.76
restitution = $1
seed = 5
$2
[run]
equilibration_time = ${3:-6.0}
checkpoint_interval = 3.0
[schedule]
origins = 2
origin_spacing = 2.0
lag_min = 0.5
lag_max = 2.0
TOML
}
same() { # two checkpoints: bit for bit the same state, after real work
  $py -c "
import h5py, numpy as np, sys
a, b = h5py.File(\"$1\", \"r\"), h5py.File(\"$2\", \"r\")
bad = [k for k in (\"x\", \"y\", \"vx\", \"vy\", \"image_x\", \"image_y\", \"collision_count\", \"rng\") if not np.array_equal(a[k][()], b[k][()])]
bad += [k for k in (\"time\", \"collisions\", \"kicks\", \"virial\") if a.attrs[k][0] != b.attrs[k][0]]
sys.exit(1 if bad or a.attrs[\"collisions\"][0] < 10000 else 0)"
}
scene 0.9 "" >prep.toml
"$bin/sim_node" prep.toml --prepare-only state.h5 2>prep.log
check 'grep -q "prepared state (N=1500, phi=0.7600, seed 5)" prep.log' "sim_node --prepare-only writes a prepared state"
for eps in 0.9 0.7; do
  scene $eps "" >self$eps.toml
  scene $eps 'initial_state = "state.h5"' >from$eps.toml
  "$bin/sim_node" self$eps.toml --lcm-url "$url" --checkpoint self$eps.h5 2>self$eps.log
  "$bin/sim_node" from$eps.toml --lcm-url "$url" --checkpoint from$eps.h5 2>from$eps.log
  check 'grep -q "started from .*state.h5" from$eps.log' "eps $eps: the run starts from the prepared state (no compression)"
  check 'same self$eps.h5 from$eps.h5' "eps $eps: ends bit for bit like the run that compresses itself"
done
# Equilibrated states: to t = 3 from the prepared state, then on to 6 from that one.
scene 0.9 'initial_state = "state.h5"' 3.0 >eq3.toml
"$bin/sim_node" eq3.toml --prepare-only eq3.h5 --equilibrate 2>eq3.log
check 'grep -q "equilibrated state (N=1500, phi=0.7600, eps=0.900, seed 5) from t = 0 to 3 " eq3.log' \
  "--prepare-only --equilibrate writes a state at t = 3 ($(tail -n 1 eq3.log))"
scene 0.9 'initial_state = "eq3.h5"' >eq6.toml
"$bin/sim_node" eq6.toml --prepare-only eq6.h5 --equilibrate 2>eq6.log
check 'grep -q "from t = 3 to 6 " eq6.log' "an equilibrated state is extended from a shorter one"
for st in eq3 eq6; do
  scene 0.9 "initial_state = \"$st.h5\"" >from_$st.toml
  "$bin/sim_node" from_$st.toml --lcm-url "$url" --checkpoint from_$st.h5 2>from_$st.log
  check 'same self0.9.h5 from_$st.h5' "a run from the state equilibrated to ${st#eq} ends bit for bit like the run that equilibrates itself"
done
# Positions from an H5MD file (the prepared positions, shifted by a box: folded back).
$py - <<'PY'
import h5py, numpy as np
s = h5py.File("state.h5", "r")
L = None
with h5py.File("pos.h5", "w") as f:
    xy = np.stack([s["x"][()], s["y"][()]], axis=1)
    f.create_dataset("particles/all/position/value", data=xy[None, :, :] + 0.0)
with h5py.File("overlap.h5", "w") as f:
    xy = np.stack([s["x"][()], s["y"][()]], axis=1)
    xy[1] = xy[0] + [0.3, 0.0]
    f.create_dataset("particles/all/position/value", data=xy)
with h5py.File("short.h5", "w") as f:
    f.create_dataset("particles/all/position/value", data=np.zeros((10, 2)))
PY
scene 0.9 'initial_state = "pos.h5"' >h5md.toml
"$bin/sim_node" h5md.toml --lcm-url "$url" 2>h5md.log && rc=0 || rc=$?
check '[[ $rc == 0 ]] && grep -q "started from .*pos.h5" h5md.log' "a run starts from H5MD positions"
refused() { # scene extra line, expected text, what
  local want=$2
  scene 0.9 "$1" >bad.toml
  "$bin/sim_node" bad.toml --lcm-url "$url" 2>bad.log && rc=0 || rc=$?
  check '[[ $rc != 0 ]] && grep -q "$want" bad.log' "$3 (exit $rc: $(grep -v '^\[' bad.log | tail -n 1))"
}
refused 'initial_state = "overlap.h5"' "overlap" "overlapping positions are refused"
refused 'initial_state = "short.h5"' "not whole frames of 2 x 1500" "positions of another N are refused"
refused 'initial_state = "missing.h5"' "missing.h5: no such file" "a missing file is refused"
refused 'initial_state = "self0.9.h5"' "a checkpoint taken after frame [0-9]*, not a prepared state" "a checkpoint taken in production is refused"
scene 0.7 'initial_state = "eq3.h5"' >bad.toml
"$bin/sim_node" bad.toml --lcm-url "$url" 2>bad.log && rc=0 || rc=$?
check '[[ $rc != 0 ]] && grep -q "equilibrated with another system.restitution" bad.log' "a state equilibrated at another restitution is refused"
scene 0.9 'initial_state = "eq6.h5"' 4.0 >bad.toml
"$bin/sim_node" bad.toml --lcm-url "$url" 2>bad.log && rc=0 || rc=$?
check '[[ $rc != 0 ]] && grep -q "equilibrated to t = 6.*beyond the scene.s run.equilibration_time = 4" bad.log' "a state equilibrated beyond the scene's equilibration is refused"
# A state with a NaN position is refused, as a start and as a resume.
cp state.h5 nan.h5
cp self0.9.h5 nanresume.h5
$py -c "
import h5py, sys
for p in ('nan.h5', 'nanresume.h5'):
    with h5py.File(p, 'r+') as f:
        x = f['x'][()]
        x[3] = float('nan')
        f['x'][...] = x
"
refused 'initial_state = "nan.h5"' "particle 3 has a non-finite position or velocity" "a state with a NaN position is refused"
"$bin/sim_node" --resume nanresume.h5 --lcm-url "$url" 2>bad.log && rc=0 || rc=$?
check '[[ $rc != 0 ]] && grep -q "non-finite position" bad.log' "a checkpoint with a NaN position is not resumed (exit $rc)"
scene 0.9 'initial_state = "state.h5"' | sed 's/^seed = 5/seed = 6/' >bad.toml
"$bin/sim_node" bad.toml --lcm-url "$url" 2>bad.log && rc=0 || rc=$?
check '[[ $rc != 0 ]] && grep -q "prepared for system.seed = 5, the scene has 6" bad.log' "a state prepared for another seed is refused"
exit $fail
