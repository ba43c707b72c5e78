"""The container floor as a mesh: the square floor in 3D, a strip under the slice in 2D."""
from __future__ import annotations

import numpy as np
import taichi as ti

from .camera import Geometry

FLOOR_COLOUR = (0.32, 0.34, 0.38)
SURFACE_FLOOR = (0.11, 0.11, 0.125)     # a dark dish under the milk (the surface's look)


class FloorMesh:
    """Two triangles at z = 0 (just below the film's lowest particle layer is the wall)."""

    def __init__(self, geometry: Geometry, colour=FLOOR_COLOUR):
        half_x = geometry.floor / 2
        half_y = half_x if geometry.dim == 3 else geometry.slice_depth / 2
        z = -0.5 * geometry.l0                  # the wall surface below the first fluid layer
        corners = np.array([[-half_x, -half_y, z], [half_x, -half_y, z], [half_x, half_y, z],
                            [-half_x, half_y, z]], dtype=np.float32)
        self.colour = tuple(colour)
        self.vertices = ti.Vector.field(3, ti.f32, 4)
        self.normals = ti.Vector.field(3, ti.f32, 4)
        self.indices = ti.field(ti.i32, 6)
        self.vertices.from_numpy(corners)
        self.normals.from_numpy(np.tile(np.float32([0, 0, 1]), (4, 1)))
        self.indices.from_numpy(np.array([0, 1, 2, 0, 2, 3], dtype=np.int32))

    def draw(self, scene: ti.ui.Scene) -> None:
        scene.mesh(self.vertices, self.indices, self.normals, color=self.colour,
                   two_sided=True)


__all__ = ["FloorMesh", "FLOOR_COLOUR", "SURFACE_FLOOR"]
