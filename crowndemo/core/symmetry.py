"""Mirror symmetry planes through the scene's axis (x = 0, and y = 0 in 3D): one half or one
quarter of a symmetric scene is simulated, and every neighbour sum sees the mirrored rest.

Once per grid build, every particle within re of a plane (within the surface stress's pair
support, 3 l0, where that model's wide walk reaches further) gets a mirror image across it (near
two planes, also the image across both), stored after the particles, in slots [n, n + images):
the source's kind, its position and velocity reflected. The grid holds the images, so every
pass that walks it (number density S9, viscosity S12, surface tension S22, pressure gradient
S11, collisions, the relative Courant speed) sees them as it sees any particle, with no special
case; no pass takes an image as its own particle i (they lie past n), so nothing integrates,
measures or records them. An image follows its source after each stage that changes what a
later pass reads of it: velocity after the predictor's u* (S15; the collision pass reads it),
pressure and number density after the density pass (S17; the corrector reads P_j).

A particle that crosses a plane is reflected back, position and velocity, right after each
move (S16, S20): in the whole scene its mirror twin crosses the other way at the same moment,
so the state is the same and no particle is ever on the far side.

``mirror_whole`` turns a snapshot of the simulated part back into the whole scene, for the
renderer, the crown metrics and the exports.
"""

import math
from typing import Dict, Sequence, Tuple

import numpy as np
import taichi as ti

from .state import GONE, ParticleState

AXES = "xyz"
# scene.symmetry: the part of a scene symmetric about its vertical axis that is simulated
SYMMETRIES = {"full": 0, "half": 1, "quarter": 2}      # name -> planes (x = 0, then y = 0)


def planes_of(symmetry: str, dim: int) -> Tuple[int, ...]:
    """The plane axes of ``scene.symmetry`` (0: x = 0, 1: y = 0); a plane is never normal to
    the vertical axis. 2D has one plane (half); quarter needs 3D."""
    count = SYMMETRIES[symmetry]
    if count > dim - 1:
        raise ValueError(f"symmetry {symmetry} needs {count} horizontal axes; {dim}D has "
                         f"{dim - 1}")
    return tuple(range(count))


def symmetry_name(planes: Sequence[int]) -> str:
    return {0: "full", 1: "half", 2: "quarter"}[len(tuple(planes))]


def plane_names(planes: Sequence[int]) -> list:
    """The planes as axis names, as records and metadata state them: ['x', 'y']."""
    return [AXES[a] for a in planes]


def fraction(planes: Sequence[int]) -> float:
    """The simulated share of the whole scene: 1, 1/2 or 1/4."""
    return 0.5 ** len(tuple(planes))


def plane_sets(planes: Sequence[int]):
    """The non-empty sets of planes an image is reflected across, as tuples of axes."""
    planes = tuple(planes)
    return [tuple(a for b, a in enumerate(planes) if m >> b & 1)
            for m in range(1, 2 ** len(planes))]


def images_of(pos: np.ndarray, planes: Sequence[int], reach: float) -> int:
    """How many mirror images the particles at ``pos`` have within ``reach`` of the planes."""
    pos = np.asarray(pos, dtype=float)
    return int(sum(np.all(pos[:, list(axes)] < reach, axis=1).sum()
                   for axes in plane_sets(planes)))


IMAGE_ROOM = 3.0            # images allowed for, times those of the initial state
IMAGE_ROOM_MIN = 1024


def image_room(pos: np.ndarray, planes: Sequence[int], reach: float) -> int:
    """The slots a simulator sets aside for images: three times those of the initial state (a
    crown's sheet rising along a plane adds its own), at least 1024; 0 without planes. A run
    whose images outgrow it stops with a clear cause (Symmetry.make_images)."""
    if not tuple(planes):
        return 0
    return max(int(math.ceil(IMAGE_ROOM * images_of(pos, planes, reach))), IMAGE_ROOM_MIN)


def mirror_whole(snapshot: Dict[str, np.ndarray], planes: Sequence[int],
                 vectors: Sequence[str] = ("pos", "vel")) -> Dict[str, np.ndarray]:
    """The whole scene from a snapshot of its simulated part: every particle and its images
    across each set of planes; the ``vectors`` fields are reflected, the others copied."""
    planes = tuple(planes)
    if not planes:
        return snapshot
    out = {name: [np.asarray(a)] for name, a in snapshot.items()}
    for axes in plane_sets(planes):
        for name, a in snapshot.items():
            a = np.array(a, copy=True)
            if name in vectors:
                a[:, list(axes)] *= -1
            out[name].append(a)
    return {name: np.concatenate(parts) for name, parts in out.items()}


def cut(pos: np.ndarray, planes: Sequence[int], tol: float) -> np.ndarray:
    """The mask of the particles on the simulated side (x > 0, y > 0) of a scene that is mirror
    symmetric about the planes; ValueError if the scene is not (a particle whose mirror image
    is not a particle within ``tol``, or a particle on a plane)."""
    pos = np.asarray(pos, dtype=float)
    planes = tuple(planes)
    keep = np.all(pos[:, list(planes)] > 0, axis=1) if planes else np.ones(len(pos), bool)
    if not planes:
        return keep
    if (np.abs(pos[:, list(planes)]) < tol).any():
        raise ValueError("a particle lies on a symmetry plane: build the lattice at "
                         "(k + 1/2) l0 from the planes")
    mirrored = mirror_whole({"pos": pos[keep]}, planes)["pos"]
    key = lambda p: np.round(p / tol).astype(np.int64)
    if len(mirrored) != len(pos) or {tuple(k) for k in key(mirrored)} != {
            tuple(k) for k in key(pos)}:
        raise ValueError(f"the scene is not mirror symmetric about the plane(s) "
                         f"{', '.join(a + ' = 0' for a in plane_names(planes))}")
    return keep


@ti.data_oriented
class Symmetry:
    """The mirror images of one simulator's particles (module docstring)."""

    def __init__(self, state: ParticleState, planes: Sequence[int]):
        self.state, self.planes, self.dim = state, tuple(planes), state.dim
        if not self.planes or any(not 0 <= a < state.dim - 1 for a in self.planes):
            raise ValueError(f"symmetry planes {self.planes}: axes 0 .. {state.dim - 2}")
        self.masks = [sum(1 << b for b, a in enumerate(self.planes) if a in axes)
                      for axes in plane_sets(self.planes)]
        self.source = ti.field(ti.i32, state.capacity)    # per image slot: its particle
        self.mask = ti.field(ti.i32, state.capacity)      # per image slot: bit b = plane b
        self.wanted = ti.field(ti.i32, shape=())          # images the last build asked for
        self.reach = ti.field(float, shape=())
        self.crossings = ti.field(ti.i32, shape=())       # reflections so far (diagnostic)

    def configure(self, reach: float) -> None:
        """Particles within ``reach`` (re, or the grid's wide walk's radius) of a plane have
        images."""
        self.reach[None] = reach

    def clear(self) -> None:
        self.state.n_images[None] = 0

    def nbytes(self) -> int:
        from .state import field_nbytes
        return field_nbytes(self.source) + field_nbytes(self.mask)

    def make_images(self) -> int:
        """The images of the particles at their current positions; returns how many were
        wanted (more than ``room`` means some are missing: the caller stops the run)."""
        self._make()
        return int(self.wanted[None])

    @property
    def room(self) -> int:
        """Image slots left above the particles."""
        return self.state.capacity - self.state.count

    @ti.func
    def _reflected(self, v, mask: ti.template()):
        w = v
        for b in ti.static(range(len(self.planes))):
            if ti.static(mask >> b & 1):
                w[self.planes[b]] = -w[self.planes[b]]
        return w

    @ti.kernel
    def _make(self):
        n = self.state.n[None]
        self.wanted[None] = 0
        for i in range(n):
            k = self.state.kind[i]
            if k != GONE:
                x = self.state.pos[i]
                for mask in ti.static(self.masks):
                    near = True
                    for b in ti.static(range(len(self.planes))):
                        if ti.static(mask >> b & 1):
                            if x[self.planes[b]] >= self.reach[None]:
                                near = False
                    if near:
                        slot = n + ti.atomic_add(self.wanted[None], 1)
                        if slot < self.state.capacity:
                            self.state.pos[slot] = self._reflected(x, mask)
                            self.state.vel[slot] = self._reflected(self.state.vel[i], mask)
                            self.state.kind[slot] = k
                            self.state.pressure[slot] = self.state.pressure[i]
                            self.state.density[slot] = self.state.density[i]
                            self.source[slot] = i
                            self.mask[slot] = mask
        self.state.n_images[None] = ti.min(self.wanted[None], self.state.capacity - n)

    @ti.kernel
    def sync_motion(self):
        """Images take their sources' (reflected) position and velocity, and their kind (a
        source that left the domain takes its images with it): after the corrector (S20),
        for a predictor that reuses the last images (terms.py, the predictor's pairs from
        the list)."""
        n = self.state.n[None]
        for s in range(n, n + self.state.n_images[None]):
            i = self.source[s]
            self.state.pos[s] = self._mirrored(self.state.pos[i], s)
            self.state.vel[s] = self._mirrored(self.state.vel[i], s)
            self.state.kind[s] = self.state.kind[i]

    @ti.func
    def _mirrored(self, v, s):
        """v reflected across the planes of image slot s (its run-time mask)."""
        w = v
        for b in ti.static(range(len(self.planes))):
            if self.mask[s] >> b & 1:
                w[self.planes[b]] = -w[self.planes[b]]
        return w

    @ti.kernel
    def sync_velocity(self):
        """Images take their sources' (reflected) velocity: after u* (S15)."""
        n = self.state.n[None]
        for s in range(n, n + self.state.n_images[None]):
            self.state.vel[s] = self._mirrored(self.state.vel[self.source[s]], s)

    @ti.kernel
    def sync_pressure(self):
        """Images take their sources' pressure and number density: after S17."""
        n = self.state.n[None]
        for s in range(n, n + self.state.n_images[None]):
            self.state.pressure[s] = self.state.pressure[self.source[s]]
            self.state.density[s] = self.state.density[self.source[s]]

    @ti.kernel
    def reflect(self):
        """A particle on the far side of a plane is reflected back (module docstring)."""
        for i in range(self.state.n[None]):
            if self.state.kind[i] != GONE:
                for b in ti.static(range(len(self.planes))):
                    a = ti.static(self.planes[b])
                    if self.state.pos[i][a] < 0.0:
                        self.state.pos[i][a] = -self.state.pos[i][a]
                        self.state.vel[i][a] = -self.state.vel[i][a]
                        ti.atomic_add(self.crossings[None], 1)


__all__ = ["Symmetry", "SYMMETRIES", "planes_of", "plane_names", "symmetry_name", "fraction",
           "mirror_whole", "cut", "images_of", "image_room", "plane_sets"]
