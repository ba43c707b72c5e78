"""The film at rest drawn flat: columns of the film whose particles all sit at the film's own
height are left out of the surface reconstruction and drawn as flat quads at the height the
reconstruction gives the film top beside them. At booth quality that takes a frame's mesh
from 0.68 to 0.13 million triangles at 0 ms, 1.00 to 0.57 at 2 ms, 1.50 to 1.15 at 4 ms, and
no pixel changes by more than 8/255 (BENCHMARKS.md; tests/test_still_film.py compares them).

Columns are squares of CELL l0 over the floor. A column's *film* particles are those below
the film thickness h + NEAR l0 (higher ones are spray or crown and are always reconstructed).
A column is flat when it holds film particles, the highest of them lies within RAISED l0 of
the film's top layer (the median of the columns' highest), and no column next to it is
empty (the film's free edges stay reconstructed). The reconstruction takes every column
within KEEP + the surface's band (SurfaceParams.band, the reach of its kernel and smoothing)
of a column that is not flat, so that the false edge where the film is left out lies a band
beyond the mesh that is kept; the kept mesh covers the columns within KEEP of them, the
quads the rest and one column under the mesh's edge (a hair under the mesh, which wins where
both are).
A trimmed film (scene.trim) ends at a free edge that only the trimming made: the film left
out beyond it lies at rest by construction (scenes/crown.py, reach_radius), so it is drawn as
one flat ring at the same height, from a circle EDGE l0 inside the free edge (where the
edge's rounding begins) out to the floor's edge, and the dish reads full of milk. With
symmetry planes the columns are laid from the planes, and the quads mirrored with the mesh."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Dict, Optional, Sequence, Tuple

import numpy as np

from .surface import SurfaceMesh, mirror, plane_axes, used_vertices

CELL = 4.0      # column side / l0
NEAR = 3.0      # particles below the film's thickness h + NEAR l0 are the film's
RAISED = 0.5    # a column whose highest film particle is this many l0 off the top layer moves
KEEP = 2        # columns of flat film kept in the mesh around those that are not flat
SINK = 0.02     # the quads lie this many l0 under the film top: the mesh wins where they meet
EDGE = 5.0      # l0 inside a trimmed film's edge that the left-out film reaches
ANNULUS = 512   # rays of the left-out film's mesh (a multiple of 8)
TOP = 0.59      # the film top / l0 above the top layer where no flat film is kept in the
                # mesh to measure it (a film of 3 layers reads 3.18 l0 thick, surface.py)


@dataclass
class FilmColumns:
    """Which particles to reconstruct and which columns to draw flat."""
    keep: np.ndarray            # (N,) bool: particles to reconstruct
    flat: np.ndarray            # (nx, ny) bool: columns drawn as quads: the cut ones and
                                # the flat ones beside them
    cut: np.ndarray             # (nx, ny) bool: flat columns where the mesh is cut away
    origin: np.ndarray          # (2,) the columns' lower corner, metres
    cell: float                 # column side, metres
    top_layer: float            # the film's top particle layer, metres
    l0: float
    planes: Tuple[str, ...]
    left_out: Optional[Tuple[float, float]] = None   # (floor side, film extent): trimmed

    def column_of(self, xy: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """Column indices of points (M x 2; folded across the planes) and whether inside."""
        xy = np.array(xy, dtype=np.float64)
        for a in plane_axes(self.planes):
            xy[:, a] = np.abs(xy[:, a])
        ij = np.floor((xy - self.origin) / self.cell).astype(np.int64)
        nx, ny = self.flat.shape
        inside = (ij[:, 0] >= 0) & (ij[:, 0] < nx) & (ij[:, 1] >= 0) & (ij[:, 1] < ny)
        return np.clip(ij, 0, [nx - 1, ny - 1]), inside


def _grow(mask: np.ndarray, k: int) -> np.ndarray:
    """``mask`` dilated by k columns (a square of side 2k + 1)."""
    out = mask.copy()
    for axis in (0, 1):
        src = out.copy()
        for s in range(1, k + 1):
            lo = [slice(None)] * 2
            hi = [slice(None)] * 2
            lo[axis], hi[axis] = slice(s, None), slice(None, -s)
            out[tuple(lo)] |= src[tuple(hi)]
            out[tuple(hi)] |= src[tuple(lo)]
    return out


def _edge(filled: np.ndarray, axes: Tuple[int, ...]) -> np.ndarray:
    """Columns next to an empty one or to the grid's end (not across a symmetry plane,
    which the grid starts at: the mirror side is filled where this side is)."""
    padded = np.pad(filled, 1, constant_values=False)
    for a in axes:
        first = [slice(1, -1)] * 2
        first[a] = slice(0, 1)
        inner = [slice(1, -1)] * 2
        inner[a] = slice(1, 2)
        padded[tuple(first)] = padded[tuple(inner)]
    return _grow(~padded, 1)[1:-1, 1:-1]


def columns(pos: np.ndarray, l0: float, film: float, band: float,
            planes: Sequence[str] = (), floor: Optional[float] = None,
            extent: Optional[float] = None) -> FilmColumns:
    """Classify the floor's columns for fluid particles ``pos`` (N x 3, metres) of a film of
    thickness ``film`` and spacing ``l0``; ``band``: the surface's reach past a false edge.
    ``floor`` (the square floor's side) and ``extent`` (the radius of a trimmed film): the
    film left out beyond it lies at rest and is drawn flat too (``join``)."""
    cell = CELL * l0
    axes = plane_axes(planes)
    xy = pos[:, :2]
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    if floor is not None:
        lo = np.minimum(lo, [0.0 if a in axes else -floor / 2 for a in (0, 1)])
        hi = np.maximum(hi, floor / 2)
    origin = np.floor(lo / cell) * cell
    shape = tuple(int(v) for v in np.floor((hi - origin) / cell).astype(np.int64) + 1)
    ij = np.floor((xy - origin) / cell).astype(np.int64)
    low = pos[:, 2] < film + NEAR * l0
    flat_index = np.ravel_multi_index((ij[:, 0], ij[:, 1]), shape)
    highest = np.full(shape[0] * shape[1], -np.inf)
    np.maximum.at(highest, flat_index[low], pos[low, 2])
    highest = highest.reshape(shape)
    filled = highest > -np.inf
    top_layer = float(np.median(highest[filled])) if filled.any() else film
    level = np.abs(highest - top_layer) <= RAISED * l0
    edge = _edge(filled, axes)
    flat = filled & level & ~edge
    moving = ~flat & filled
    k = int(math.ceil(band / cell))
    near_moving = _grow(moving, KEEP + k)
    in_mesh = _grow(moving, KEEP)
    column_kept = near_moving | ~flat
    keep = column_kept.reshape(-1)[flat_index] | ~low
    cut = flat & ~in_mesh
    left_out = (floor, extent) if floor is not None and extent is not None else None
    return FilmColumns(keep, flat & _grow(cut, 1), cut, origin, cell, top_layer, l0,
                       tuple(planes), left_out)


def join(mesh: SurfaceMesh, cols: FilmColumns) -> SurfaceMesh:
    """The reconstructed ``mesh`` (of the kept particles, mirrored where the run is) with the
    film over the flat columns cut away and drawn as quads at the mesh's own film top."""
    if not cols.flat.any() and cols.left_out is None:
        return mesh
    ij, inside = cols.column_of(mesh.vertices[:, :2])
    over_cut = inside & cols.cut[ij[:, 0], ij[:, 1]]
    low = mesh.vertices[:, 2] < cols.top_layer + 2.0 * cols.l0
    gone = (over_cut & low)[mesh.triangles].all(axis=1)
    tris = mesh.triangles[~gone]
    used, index = used_vertices(tris, mesh.n_vertices)
    kept = SurfaceMesh(mesh.vertices[used], index[tris], mesh.normals[used],
                       {k: v[used] for k, v in mesh.fields.items()})
    # the film top where the mesh keeps flat film: its upward-facing vertices there
    kept_flat = cols.flat & ~cols.cut
    on_kept = inside & kept_flat[ij[:, 0], ij[:, 1]] & low & (mesh.normals[:, 2] > 0.9)
    if on_kept.any():
        top = float(np.median(mesh.vertices[on_kept, 2]))
        values = {k: float(np.median(v[on_kept])) for k, v in mesh.fields.items()}
    else:
        top = cols.top_layer + TOP * cols.l0
        values = {k: 0.0 for k in mesh.fields}
    z = top - SINK * cols.l0
    quads = _quads(cols, z, values)
    if cols.planes:
        quads = mirror(quads, cols.planes)
    if cols.left_out is not None:
        quads = _concatenate(quads, _annulus(*cols.left_out, cols.l0, z, values))
    return _concatenate(kept, quads)


def _facing_up(xy: np.ndarray, tris: np.ndarray, z: float,
               values: Dict[str, float]) -> SurfaceMesh:
    """A flat mesh at height ``z`` over the points ``xy``, facing up, with constant fields."""
    verts = np.c_[xy, np.full(len(xy), z)]
    return SurfaceMesh(verts, tris, np.tile([0.0, 0.0, 1.0], (len(xy), 1)),
                       {k: np.full(len(xy), v) for k, v in values.items()})


def _annulus(floor: float, extent: float, l0: float, z: float,
             values: Dict[str, float]) -> SurfaceMesh:
    """The film left out of a trimmed run, at height ``z``: from EDGE l0 inside the
    simulated film's edge (a circle) out to the square floor's edge, facing up."""
    angle = np.arange(ANNULUS) * (2 * np.pi / ANNULUS)    # a multiple of 8: the corners
    c, s = np.cos(angle), np.sin(angle)
    out = 0.5 * floor / np.maximum(np.abs(c), np.abs(s))
    inner = np.c_[(extent - EDGE * l0) * c, (extent - EDGE * l0) * s]
    a = np.arange(ANNULUS)
    b = (a + 1) % ANNULUS
    tris = np.concatenate([np.c_[a, b + ANNULUS, b], np.c_[a, a + ANNULUS, b + ANNULUS]])
    return _facing_up(np.concatenate([inner, np.c_[out * c, out * s]]), tris, z, values)


def _quads(cols: FilmColumns, z: float, values: Dict[str, float]) -> SurfaceMesh:
    """Two triangles per flat column, at height ``z``, facing up; neighbours' corners are
    the same numbers (one lattice of column edges), so no crack opens between them. The
    quads reach one column under the kept mesh's flat edge: a low eye looking under that
    open edge meets the quads, not the inside of the film's mesh."""
    i, j = np.nonzero(cols.flat)
    nx, ny = cols.flat.shape
    xs = cols.origin[0] + np.arange(nx + 1) * cols.cell
    ys = cols.origin[1] + np.arange(ny + 1) * cols.cell
    corners = np.stack([np.c_[xs[i], ys[j]], np.c_[xs[i + 1], ys[j]],
                        np.c_[xs[i + 1], ys[j + 1]], np.c_[xs[i], ys[j + 1]]], 1)
    base = 4 * np.arange(len(i))[:, None]
    tris = np.concatenate([base + [0, 1, 2], base + [0, 2, 3]])
    return _facing_up(corners.reshape(-1, 2), tris, z, values)


def _concatenate(a: SurfaceMesh, b: SurfaceMesh) -> SurfaceMesh:
    return SurfaceMesh(np.concatenate([a.vertices, b.vertices]),
                       np.concatenate([a.triangles, b.triangles + a.n_vertices]),
                       np.concatenate([a.normals, b.normals]),
                       {k: np.concatenate([a.fields[k], b.fields[k]]) for k in a.fields})


__all__ = ["FilmColumns", "columns", "join", "CELL", "NEAR", "RAISED", "KEEP"]
