"""What a scene is (particles, parameters, domain) and the lattice builders scenes share."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Iterable, Optional, Sequence, Tuple

import numpy as np

from ..core.params import Numerics, Physics
from ..core.state import DUMMY, FLUID, WALL

Box = Tuple[Tuple[float, ...], Tuple[float, ...]]


@dataclass
class Scene:
    name: str
    physics: Physics
    numerics: Numerics
    pos: np.ndarray
    vel: np.ndarray
    kind: np.ndarray
    domain: Box                 # particles outside are parked and counted
    t_end: float
    info: dict = field(default_factory=dict)   # geometry, walls present, what is left out
    # a floor at z = 0 (y in 2D) whose wall-layer plane, z = -l0/2, the domain ends at
    # (floor_cut): the collision model's plane there (core/terms.py)
    floor: bool = False

    @property
    def dim(self) -> int:
        return self.physics.dim

    def counts(self) -> dict:
        return {"fluid": int((self.kind == FLUID).sum()), "wall": int((self.kind == WALL).sum()),
                "dummy": int((self.kind == DUMMY).sum()), "total": int(len(self.kind))}


def lattice_block(lo: Sequence[float], hi: Sequence[float], l0: float) -> np.ndarray:
    """Lattice points lo + (i + 1/2) l0 that lie inside the box [lo, hi]."""
    axes = [lo_k + (np.arange(max(int(math.floor((hi_k - lo_k) / l0 + 1e-9)), 0)) + 0.5) * l0
            for lo_k, hi_k in zip(lo, hi)]
    grids = np.meshgrid(*axes, indexing="ij")
    return np.stack([g.ravel() for g in grids], axis=1)


def floor_face(dim: int) -> str:
    """The floor's face: the plane z = 0 (y = 0 in 2D) under the liquid."""
    return "z-" if dim == 3 else "y-"


def floor_cut(domain: Box, l0: float) -> Box:
    """The domain cut at the floor's wall-layer plane, z = -l0/2 (y in 2D; the floor's surface
    at 0, method.md §5): a fluid particle past it has gone through the floor, particle or
    analytic, and is parked and counted as "left through z-" there, not left among the dummy
    layers, which raise its number density until its own pressure drives it on down
    (VALIDATION.md, the booth crown's particle at 37.7 m/s)."""
    return tuple(domain[0][:-1]) + (-0.5 * l0,), tuple(domain[1])


def particle_faces(faces: Iterable[str], dim: int, numerics: Optional[Numerics]) -> list:
    """The faces built of particles: all of them, or without the floor when the numerics ask
    for the analytic plane floor (core/plane_floor.py)."""
    faces = list(faces)
    if numerics is not None and numerics.wall_model == "plane":
        faces = [f for f in faces if f != floor_face(dim)]
    return faces


def container_walls(inner_lo: Sequence[float], inner_hi: Sequence[float], l0: float,
                    layers: int, faces: Iterable[str]) -> Tuple[np.ndarray, np.ndarray]:
    """Wall (first layer) and dummy (further layers) particles on the faces named, e.g.
    {"x-", "x+", "z-"}: the lattice of the inner box continued outward. Returns (pos, kind)."""
    dim = len(inner_lo)
    faces = set(faces)
    axes = "xyz"[:dim]
    lo = [inner_lo[k] - (layers if f"{axes[k]}-" in faces else 0) * l0 for k in range(dim)]
    hi = [inner_hi[k] + (layers if f"{axes[k]}+" in faces else 0) * l0 for k in range(dim)]
    pts = lattice_block(lo, hi, l0)
    layer = np.zeros(len(pts), dtype=int)
    for k in range(dim):
        below = np.ceil((inner_lo[k] - pts[:, k]) / l0 - 1e-9).astype(int)
        above = np.ceil((pts[:, k] - inner_hi[k]) / l0 - 1e-9).astype(int)
        layer = np.maximum(layer, np.maximum(below, above))
    keep = layer > 0
    pts, layer = pts[keep], layer[keep]
    kind = np.where(layer == 1, WALL, DUMMY).astype(np.int32)
    return pts, kind


def assemble(name: str, physics: Physics, numerics: Numerics, fluid: np.ndarray,
             fluid_vel: Optional[np.ndarray], walls: Optional[Tuple[np.ndarray, np.ndarray]],
             domain: Box, t_end: float, info: dict, floor: bool = False) -> Scene:
    dim = physics.dim
    parts_pos = [fluid]
    parts_vel = [fluid_vel if fluid_vel is not None else np.zeros_like(fluid)]
    parts_kind = [np.full(len(fluid), FLUID, dtype=np.int32)]
    if walls is not None and len(walls[0]):
        parts_pos.append(walls[0])
        parts_vel.append(np.zeros_like(walls[0]))
        parts_kind.append(walls[1])
    pos = np.concatenate(parts_pos).reshape(-1, dim)
    return Scene(name, physics, numerics, pos, np.concatenate(parts_vel).reshape(-1, dim),
                 np.concatenate(parts_kind), domain, t_end, info, floor)
