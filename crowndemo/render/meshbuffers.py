"""The surface mesh's GGUI fields: vertices, normals, colours and indices, allocated with
headroom and reallocated only when a mesh outgrows them (or needs under a quarter of them:
GGUI copies the whole field every draw, so the fields follow the mesh's size).

GGUI 1.7.4 on lavapipe sometimes draws nothing of a mesh: measured, growing spheres drawn
offscreen at 320 x 180 came out blank in 10-25 % of the frames whose fields were made bigger
(never in 128 frames where the vertex or the index count stayed the same). ``fill`` with
``remake`` makes the fields anew even for a mesh that fits; ``Renderer.render_surface`` compares
each frame with the frame without the mesh and draws a blank one again in new fields. (A
first check, an extra magenta draw and capture on frames with new fields, provoked more
blanks than it caught: 9 of the first 13 frames of a 20cm-drop seed-rung recording; the
same recording made again with the present check drew all 25, none redrawn.)"""
from __future__ import annotations

from typing import Iterator, Tuple

import numpy as np
import taichi as ti

HEADROOM = 1.25          # capacity / size of the mesh that made the fields
SHRINK = 0.25            # a mesh below this share of the capacity reallocates smaller
# GGUI passes index counts and offsets through 32-bit floats: exact up to 2^24; a bigger mesh
# is drawn in pieces of 3 * 2^22 indices (each count and offset then exact)
MAX_INDICES = 3 * 2 ** 22


class MeshBuffers:
    def __init__(self):
        self.vertex_capacity = self.index_capacity = 0
        self._tree = None
        self.vertices = self.normals = self.colours = self.indices = None
        self.n_vertices = self.n_indices = 0
        self.allocations = 0                   # how often fields were made (tests, summary)

    def _allocate(self, n_vertices: int, n_indices: int) -> None:
        if self._tree is not None:
            self._tree.destroy()
        nv = max(int(n_vertices * HEADROOM), 16)
        ni = max(int(n_indices * HEADROOM) // 3 * 3, 48)
        fb = ti.FieldsBuilder()
        self.vertices, self.normals, self.colours = (ti.Vector.field(3, ti.f32)
                                                     for _ in range(3))
        self.indices = ti.field(ti.i32)
        fb.dense(ti.i, nv).place(self.vertices, self.normals, self.colours)
        fb.dense(ti.i, ni).place(self.indices)
        self._tree = fb.finalize()
        self.vertex_capacity, self.index_capacity = nv, ni
        self.allocations += 1

    def _fits(self, n_vertices: int, n_indices: int) -> bool:
        return (n_vertices <= self.vertex_capacity and n_indices <= self.index_capacity
                and n_vertices >= SHRINK * self.vertex_capacity)

    def fill(self, vertices: np.ndarray, triangles: np.ndarray, normals: np.ndarray,
             colours: np.ndarray, remake: bool = False) -> None:
        """Copy one mesh in (``remake``: into new fields even if it fits)."""
        nv, ni = len(vertices), 3 * len(triangles)
        if remake or not self._fits(nv, ni):
            self._allocate(nv, ni)
        for field, data in ((self.vertices, vertices), (self.normals, normals),
                            (self.colours, colours)):
            pad = np.zeros((self.vertex_capacity, 3), np.float32)
            pad[:nv] = data
            field.from_numpy(pad)
        idx = np.zeros(self.index_capacity, np.int32)
        idx[:ni] = np.asarray(triangles, dtype=np.int64).reshape(-1)
        self.indices.from_numpy(idx)
        self.n_vertices, self.n_indices = nv, ni

    def pieces(self) -> Iterator[Tuple[int, int]]:
        """(index offset, index count) of the draws that cover the mesh."""
        for start in range(0, self.n_indices, MAX_INDICES):
            yield start, min(MAX_INDICES, self.n_indices - start)


__all__ = ["MeshBuffers", "MAX_INDICES", "HEADROOM"]
