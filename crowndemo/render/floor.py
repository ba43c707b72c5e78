"""The container floor as a mesh: the square floor in 3D, a strip under the slice in 2D; with
``rim``, the container's four side walls too (3D), low, so the scene reads as a dish."""
from __future__ import annotations

import numpy as np
import taichi as ti

from .camera import Geometry

FLOOR_COLOUR = (0.32, 0.34, 0.38)
SURFACE_FLOOR = (0.11, 0.11, 0.125)     # a dark dish under the milk (the surface's look)


class FloorMesh:
    """Two triangles at z = 0 (just below the film's lowest particle layer is the wall), and
    with ``rim`` (3D) a wall of the film's thickness plus the drop's diameter on each side."""

    def __init__(self, geometry: Geometry, colour=FLOOR_COLOUR, rim: bool = False):
        half_x = geometry.floor / 2
        half_y = half_x if geometry.dim == 3 else geometry.slice_depth / 2
        z = -0.5 * geometry.l0                  # the wall surface below the first fluid layer
        quads = [([-half_x, -half_y, z], [half_x, -half_y, z], [half_x, half_y, z],
                  [-half_x, half_y, z])]
        if rim and geometry.dim == 3:
            top = z + geometry.film + geometry.drop
            c = [(-half_x, -half_y), (half_x, -half_y), (half_x, half_y), (-half_x, half_y)]
            for (x0, y0), (x1, y1) in zip(c, c[1:] + c[:1]):
                quads.append(([x0, y0, z], [x1, y1, z], [x1, y1, top], [x0, y0, top]))
        corners = np.array([v for q in quads for v in q], dtype=np.float32)
        normals = []
        for q in quads:                          # each quad's own normal (drawn two-sided)
            a, b, d = (np.asarray(v, float) for v in (q[0], q[1], q[3]))
            n = np.cross(b - a, d - a)
            normals += [n / np.linalg.norm(n)] * 4
        k = np.arange(len(quads), dtype=np.int32)[:, None] * 4
        indices = (k + np.array([0, 1, 2, 0, 2, 3], dtype=np.int32)).reshape(-1)
        self.colour = tuple(colour)
        self.corners, self.indices_np = corners, indices
        self.vertices = ti.Vector.field(3, ti.f32, len(corners))
        self.normals = ti.Vector.field(3, ti.f32, len(corners))
        self.indices = ti.field(ti.i32, len(indices))
        self.vertices.from_numpy(corners)
        self.normals.from_numpy(np.asarray(normals, dtype=np.float32))
        self.indices.from_numpy(indices)

    def draw(self, scene: ti.ui.Scene) -> None:
        scene.mesh(self.vertices, self.indices, self.normals, color=self.colour,
                   two_sided=True)


__all__ = ["FloorMesh", "FLOOR_COLOUR", "SURFACE_FLOOR"]
