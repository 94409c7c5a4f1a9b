"""A run's kept frames (observables.keep_frames) for the field's tools.

    import dynhet
    run = dynhet.open_run("runs/tiny/run.h5")
    for fr in run.frames():                 # one Frame per kept frame, in time order
        fr.time, fr.box, fr.positions       # freud: freud.box.Box.square(fr.box[0]), fr.positions3d()
    dynhet.frames.export_gsd(run, "tiny.gsd")   # MDAnalysis.Universe("tiny.gsd"), OVITO, HOOMD

Lengths are in units of the small disks' radius r1 = 1 (the paper's unit);
times in the run's time unit (kinetic energy per particle 1 at t = 0).
Species 0 are the small disks (radius 1, mass 1), species 1 the large ones
(radius the scene's system.radius_ratio, mass its square), as the
simulator resolved them (parameters/run_info)."""
from dataclasses import dataclass

import numpy as np

SPECIES_NAMES = ("small", "large")


@dataclass(frozen=True)
class Frame:
    """One kept frame of a run."""
    index: int
    """(int) the frame's position in particles/all/position (0 = the first kept)."""
    step: int
    """(int) the simulator's frame number (H5MD step)."""
    time: float
    """(float) simulation time of the frame."""
    box: np.ndarray
    """((2,) float) the periodic square box's edges (Lx, Ly), length units r1."""
    positions: np.ndarray
    """((N, 2) float) positions folded into the box, each in [0, L)."""
    images: np.ndarray
    """((N, 2) int32) periodic images: positions + images * box is the unwrapped path."""
    radii: np.ndarray
    """((N,) float) each disk's radius (1 or the radius ratio)."""
    species: np.ndarray
    """((N,) int32) 0 small, 1 large (SPECIES_NAMES)."""

    def unwrapped(self):
        """((N, 2) float) positions + images * box: continuous trajectories, for displacements."""
        return self.positions + self.images * self.box

    def positions3d(self, centred=False):
        """((N, 3) float) positions with z = 0, as 3D tools take them; centred:
        shifted into [-L/2, L/2) (freud's and HOOMD's box convention)."""
        p = self.positions - (self.box / 2 if centred else 0.0)
        return np.column_stack([p, np.zeros(len(p))])


def species_table(run):
    """(radius, mass) of each species as the simulator resolved them
    (parameters/run_info: the scene's radius ratio or its default, never a
    copy of the default here)."""
    info = run._f["parameters/run_info"].attrs
    return np.asarray(info["radius"], float), np.asarray(info["mass"], float)


def frame_count(run):
    g = run._f.get("particles/all/position/value")
    return 0 if g is None else int(g.shape[0])


def frames(run, start=0, stop=None, step=1):
    """Frames [start:stop:step] of a run with kept frames (a generator; each
    frame read when it is reached). Raises ValueError, saying so, for a run
    that kept none."""
    if not run.has_frames():
        raise ValueError(f"{run.path}: the run kept no frames (observables.keep_frames = false): "
                         "run the scene again with keep_frames = true")
    pa = run._f["particles/all"]
    box = np.asarray(pa["box/edges"][()], float)
    species = np.asarray(pa["species"][()], np.int32)
    radii = species_table(run)[0][species]
    pos, img = pa["position"], pa["image"]
    for i in range(*slice(start, stop, step).indices(frame_count(run))):
        yield Frame(index=i, step=int(pos["step"][i]), time=float(pos["time"][i]), box=box,
                    positions=np.asarray(pos["value"][i], float), images=np.asarray(img["value"][i], np.int32),
                    radii=radii, species=species)


def export_gsd(run, path, start=0, stop=None, step=1):
    """Write the run's frames to a GSD file (HOOMD's schema, 2D: dimensions 2,
    Lz = 0): positions centred in [-L/2, L/2) with z = 0, images, diameters,
    masses, types "small" and "large". MDAnalysis, OVITO and HOOMD read it.
    Returns the number of frames written."""
    import gsd.hoomd
    masses = species_table(run)[1]
    n = 0
    with gsd.hoomd.open(str(path), mode="wb") as out:
        for fr in frames(run, start, stop, step):
            s = gsd.hoomd.Snapshot()
            s.configuration.step = fr.step
            s.configuration.dimensions = 2
            s.configuration.box = [float(fr.box[0]), float(fr.box[1]), 0.0, 0.0, 0.0, 0.0]
            s.particles.N = len(fr.species)
            s.particles.types = list(SPECIES_NAMES)
            s.particles.typeid = fr.species.astype(np.uint32)
            s.particles.position = fr.positions3d(centred=True).astype(np.float32)
            s.particles.image = np.column_stack([fr.images, np.zeros(len(fr.species), np.int32)]).astype(np.int32)
            s.particles.diameter = (2 * fr.radii).astype(np.float32)
            s.particles.mass = masses[fr.species].astype(np.float32)
            s.log["dynhet/time"] = np.array([fr.time])
            out.append(s)
            n += 1
    return n
