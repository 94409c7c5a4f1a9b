"""launch_scripts/positions_from_checkpoint.py: a run's checkpoint as an H5MD
positions file that sim_node takes as system.initial_state."""
import os
import subprocess

import h5py
import numpy as np

from dynhet.study.paths import SIM

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TOOL = os.path.join(ROOT, "launch_scripts", "positions_from_checkpoint.py")


def tool(*args):
    return subprocess.run(["/usr/bin/python3", TOOL, *map(str, args)], capture_output=True, text=True)


def checkpoint(path, x, y, t=12.5):
    with h5py.File(path, "w") as f:
        f.attrs["format"] = b"dynhet checkpoint 1"
        f.attrs["time"] = [t]
        f["x"], f["y"] = x, y


def test_the_positions_by_id_with_the_box_and_their_source(tmp_path):
    run = tmp_path / "run"
    run.mkdir()
    x, y = np.arange(16) * 1.0, np.arange(16) * 2.0
    checkpoint(run / "checkpoint.h5", x, y)
    with h5py.File(run / "run.h5", "w") as r:
        r["particles/all/box/edges"] = [15.97, 15.97]
    out = tmp_path / "state.h5"
    p = tool(run, out)
    assert p.returncode == 0, p.stderr
    with h5py.File(out, "r") as f:
        pos = f["particles/all/position/value"][()]
        assert pos.shape == (1, 16, 2)
        assert np.array_equal(pos[0, :, 0], x) and np.array_equal(pos[0, :, 1], y)
        assert list(f["particles/all/box/edges"][()]) == [15.97, 15.97]
        assert f.attrs["source_time"] == 12.5 and len(f.attrs["source_sha256"]) == 64
    assert tool(run, out).returncode != 0                       # an existing file is not overwritten


def test_what_is_not_a_checkpoint_is_refused_by_name(tmp_path):
    with h5py.File(tmp_path / "run.h5", "w") as f:
        f["x"] = [1.0]
    p = tool(tmp_path / "run.h5", tmp_path / "o.h5")
    assert p.returncode != 0 and "not a sim checkpoint" in p.stderr and not (tmp_path / "o.h5").exists()
    checkpoint(tmp_path / "nan.h5", [1.0, float("nan")], [1.0, 2.0])
    p = tool(tmp_path / "nan.h5", tmp_path / "o.h5")
    assert p.returncode != 0 and "not a number" in p.stderr


def test_sim_node_starts_from_the_file(tmp_path):
    """The engine places the disks at those positions (it refuses overlaps and
    another box): 64 disks on an 8 x 8 grid, 3.99 apart, in the box of 64
    disks at phi 0.3 (radii 1 and 1.43: 31.9 wide)."""
    g = (np.arange(64) % 8) * 3.99 + 1.0, (np.arange(64) // 8) * 3.99 + 1.0
    run = tmp_path / "run"
    run.mkdir()
    checkpoint(run / "checkpoint.h5", *g)
    assert tool(run, tmp_path / "state.h5").returncode == 0
    (tmp_path / "scene.toml").write_text(
        "[system]\nn_particles = 64\npacking_fraction = 0.3\nradius_ratio = 1.43\ninitial_state = \"state.h5\"\n"
        "[run]\nequilibration_time = 1.0\ncheckpoint_interval = 0.5\n")
    # (--equilibrate: the dynamics from the scene's initial_state; without it --prepare-only compresses)
    p = subprocess.run([SIM, str(tmp_path / "scene.toml"), "--prepare-only", str(tmp_path / "prepared.h5"), "--equilibrate"],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    checkpoint(run / "checkpoint.h5", g[0] * 0.5, g[1] * 0.5)  # 2.0 apart: the disks overlap
    os.remove(tmp_path / "state.h5")
    assert tool(run, tmp_path / "state.h5").returncode == 0
    os.remove(tmp_path / "prepared.h5")
    p = subprocess.run([SIM, str(tmp_path / "scene.toml"), "--prepare-only", str(tmp_path / "prepared.h5"), "--equilibrate"],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode != 0 and "state.h5" in p.stderr and "overlap" in p.stderr
