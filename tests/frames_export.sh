#!/usr/bin/env bash
# A run's kept frames for the field's tools: the tiny scene (keep_frames) on
# a private bus; run.frames() gives every kept frame (time, box, positions
# in the box, images, radii, species) and launch_scripts/export_frames.py
# writes them as GSD, which MDAnalysis (Debian's python3-mdanalysis) reads
# back: the same frames, box and positions (GSD stores float32: to 1e-5 of
# the box), the same types and diameters.
set -euo pipefail
root=$1 build=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export BUILD_DIR=$build
bash "$root/launch_scripts/run_scene.sh" "$root/scenes/tiny.toml" --out "$tmp/run" --bus private --no-build --no-plots \
  >"$tmp/run.out" 2>&1 || { cat "$tmp/run.out"; exit 1; }
/usr/bin/python3 "$root/launch_scripts/export_frames.py" "$tmp/run" "$tmp/tiny.gsd"
rc=0; /usr/bin/python3 "$root/launch_scripts/export_frames.py" "$tmp/none/run.h5" "$tmp/x.gsd" 2>"$tmp/err" || rc=$?
[[ $rc == 1 ]] && grep -q "export_frames: " "$tmp/err" || { echo "FAIL: a missing run: rc $rc, $(cat "$tmp/err")"; exit 1; }
PYTHONPATH=$root/python /usr/bin/python3 - "$tmp/run/run.h5" "$tmp/tiny.gsd" <<'PY'
import sys, warnings
import numpy as np
import dynhet
warnings.filterwarnings("ignore")
import MDAnalysis as mda

fails = []
def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    ok or fails.append(what)

with dynhet.open_run(sys.argv[1]) as run:
    frames = list(run.frames())
    n = run.n_particles
    ratio = float(run._f["parameters/run_info"].attrs["radius"][1])
check(len(frames) > 10, f"run.frames(): {len(frames)} kept frames")
f0 = frames[0]
L = f0.box[0]
check(f0.positions.shape == (n, 2) and f0.images.shape == (n, 2) and f0.radii.shape == (n,), "shapes (N, 2), (N, 2), (N,)")
check(all(((fr.positions >= 0) & (fr.positions < L)).all() for fr in frames), "positions folded into [0, L)")
check(ratio == 1.43 and set(np.unique(f0.radii)) == {1.0, ratio} and (f0.radii[f0.species == 1] == ratio).all(),
      "radii 1 and the radius ratio (the model's 1.43, as the sim resolved it) by species")
check(all(b.time > a.time for a, b in zip(frames, frames[1:])), "frames in increasing time")
step = max(np.abs(b.unwrapped() - a.unwrapped()).max() for a, b in zip(frames, frames[1:]))
crossed = sum(int((b.images != a.images).any()) for a, b in zip(frames, frames[1:]))
check(step < 0.1 * L and crossed > 0, f"unwrapped paths continue across the box (largest step {step:.3g}, "
      f"{crossed} frame pairs with a boundary crossing)")

u = mda.Universe(sys.argv[2])
check(u.trajectory.n_frames == len(frames) and u.atoms.n_atoms == n, f"MDAnalysis reads {u.trajectory.n_frames} frames of {u.atoms.n_atoms} disks")
worst = 0.0
for ts, fr in zip(u.trajectory, frames):
    worst = max(worst, np.abs(ts.positions[:, :2] - (fr.positions - L / 2)).max())
    if abs(ts.dimensions[0] - L) > 1e-4 * L or abs(ts.dimensions[1] - L) > 1e-4 * L:
        fails.append(f"box of frame {fr.index}: {ts.dimensions[:2]} against {L}")
check(worst < 1e-5 * L, f"every position equal within float32 (worst {worst:.2e}, box {L:.3g}); boxes equal")
check(sorted(set(u.atoms.types)) == ["large", "small"],
      "types small and large")
sys.exit(1 if fails else 0)
PY
