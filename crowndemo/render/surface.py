"""The liquid surface: fluid particles -> a triangle mesh with pysplashsurf (splashsurf's SPH
colour-field reconstruction and marching cubes), with per-vertex normals and colour fields.
No GGUI here, so tests and export use it without a window.

Parameters (SurfaceParams) were chosen by measurement on lattices of spacing l0, the particle
radius being l0/2 (tests/test_surface.py holds the geometric checks):
- smoothing length 3.0 radii (kernel support 3 l0): a sheet two particles thick with its
  particles pulled 2 l0 apart in the plane and jittered by 0.15 l0 stays one closed sheet
  from 2.875 up (at 2.0 it falls into 90 blobs); droplets 3 l0 apart stay apart up to 3.125;
- cube size 1.5 radii (0.75 l0) and 5 smoothing iterations: a ball of R = 10 l0 comes out at
  +0.5 % volume and +0.4 % area, at half the time of 1.0 radius (10 iterations: +1.1 %,
  +0.9 %); at 2.0 radii droplets 3 l0 apart merge, and more iterations shrink the ball
  (1.5 radii, 25 iterations: -12.5 % volume);
- iso-surface 0.6 (splashsurf's default): a film of 3 l0 reads 3.18 l0 thick;
- 15 smoothing iterations of the normals, chosen by looking at ``quick``'s frames: the
  crown wall shades as one smooth sheet instead of facets (0.08 s a frame there);
- the vertex smoothing weighted as splashsurf weights it (droplets are not smoothed away),
  with the weights from a grid of particle counts (smoothing_weights.py: the same frames
  within 1 % of the pixels, at half the booth's reconstruction time); ``weights="splashsurf"``
  keeps the library's own.
- with the grid's weights only splashsurf's marching cubes run (``reconstruct_surface``; its
  ``reconstruction_pipeline`` takes twice as long for the same mesh at booth 4 ms); the colour
  fields are interpolated here as the pipeline does (SPH, normalised by the interpolated unity).

A run with symmetry planes (x = 0 and/or y = 0, through the drop's axis) is reconstructed once
from its part plus a band of mirror images across each plane (wide enough that the smoothing
near a plane sees both sides), cut at the planes, and the mesh mirrored into the whole
(``mirror``): the copies share their vertices on the planes, no seam.
A 2D slice (x, z) is extruded into a few layers along y, so that it reads as a thin slab.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field, replace
from typing import Dict, Mapping, Optional, Sequence, Tuple

import numpy as np

from .smoothing_weights import grid_weights

AXES = {"x": 0, "y": 1}
SLICE_LAYERS = 3            # layers (l0 apart along y) a 2D slice is extruded into
WEIGHTS = ("grid", "splashsurf")
SNAP_CUBES = 1.0e-6         # a vertex this close to a plane (in cubes) lies on it (rounding)


@dataclass(frozen=True)
class SurfaceParams:
    smoothing: float = 3.0       # SPH smoothing length / particle radius (radius = l0 / 2)
    cube: float = 1.5            # marching-cubes cube edge / particle radius
    iso: float = 0.6             # iso value of the normalised colour field
    smoothing_iters: int = 5     # weighted Laplacian smoothing of the vertices
    normal_iters: int = 15       # Laplacian smoothing of the normals: a smooth sheet
    weights: str = "grid"        # the smoothing's vertex weights: "grid" (smoothing_weights.py,
                                 # 0.2 s) or "splashsurf" (its own, 2.5 s at booth 4 ms)

    def __post_init__(self):
        if self.weights not in WEIGHTS:
            raise ValueError(f"weights {self.weights!r}: allowed: {', '.join(WEIGHTS)}")

    def support(self, l0: float) -> float:
        """The kernel's compact support radius, metres (twice the smoothing length)."""
        return 2.0 * self.smoothing * 0.5 * l0

    def cube_size(self, l0: float) -> float:
        return self.cube * 0.5 * l0

    def band(self, l0: float) -> float:
        """How far beyond a symmetry plane mirror images are needed: the kernel's reach, and
        the reach of the smoothing (one cube a iteration) from the band's own false edge."""
        iters = max(self.smoothing_iters, self.normal_iters) + 2
        return self.support(l0) + iters * self.cube_size(l0)


@dataclass
class SurfaceMesh:
    """Triangles over vertices, with unit normals and per-vertex scalar fields."""
    vertices: np.ndarray                       # (V, 3) float64, metres
    triangles: np.ndarray                      # (T, 3) int64, counter-clockwise seen outside
    normals: np.ndarray                        # (V, 3) float64
    fields: Dict[str, np.ndarray] = field(default_factory=dict)   # name -> (V,)

    @property
    def n_vertices(self) -> int:
        return len(self.vertices)

    @property
    def n_triangles(self) -> int:
        return len(self.triangles)

    @classmethod
    def empty(cls, names: Sequence[str] = ()) -> "SurfaceMesh":
        return cls(np.zeros((0, 3)), np.zeros((0, 3), np.int64), np.zeros((0, 3)),
                   {n: np.zeros(0) for n in names})


def plane_axes(names: Optional[Sequence[str]]) -> Tuple[int, ...]:
    """Axis names as metadata.json states them (['x', 'y']; None: none) -> axis indices."""
    try:
        return tuple(sorted({AXES[str(n)] for n in (names or ())}))
    except KeyError as e:
        raise ValueError(f"symmetry plane {e.args[0]!r}: allowed: x, y") from None


def limit_threads(threads: Optional[int] = None) -> None:
    """Give splashsurf's thread pool (rayon) as many threads as Taichi's CPU backend has
    (``threads``, else Taichi's setting), unless RAYON_NUM_THREADS is set; rayon reads it at
    the first reconstruction. The two never run at once (the step waits for the frame), so
    they take turns on the same cores instead of fighting over them."""
    if threads is None:
        import sys
        ti, threads = sys.modules.get("taichi"), os.cpu_count() or 1
        if ti is not None and ti.lang.impl.get_runtime().prog is not None:   # initialised
            threads = int(ti.lang.impl.current_cfg().cpu_max_num_threads)
    os.environ.setdefault("RAYON_NUM_THREADS", str(max(int(threads), 1)))


def fluid_of(state) -> Tuple[np.ndarray, Dict[str, np.ndarray]]:
    """The fluid particles of a ParticleState as numpy: positions and the colour fields
    (speed, pressure) a surface carries (walls, dummies, mirror images and parked left out)."""
    from ..core.state import FLUID
    n = int(state.n[None])
    keep = state.kind.to_numpy()[:n] == FLUID
    vel = state.vel.to_numpy()[:n][keep]
    return state.pos.to_numpy()[:n][keep], {
        "speed": np.linalg.norm(vel, axis=1), "pressure": state.pressure.to_numpy()[:n][keep]}


def _lift(pos: np.ndarray, l0: float) -> Tuple[np.ndarray, int]:
    """(N, 3) positions: 3D as given; a 2D slice (x, z) extruded into SLICE_LAYERS along y.
    Returns the positions and how many copies of each particle were made."""
    pos = np.asarray(pos, dtype=np.float64)
    if pos.shape[1] == 3:
        return pos, 1
    ys = (np.arange(SLICE_LAYERS) - (SLICE_LAYERS - 1) / 2) * l0
    out = np.concatenate([np.c_[pos[:, 0], np.full(len(pos), y), pos[:, 1]] for y in ys])
    return out, SLICE_LAYERS


def _with_images(pos: np.ndarray, values: Dict[str, np.ndarray], axes: Tuple[int, ...],
                 band: float) -> Tuple[np.ndarray, Dict[str, np.ndarray]]:
    """The particles plus their mirror images across each plane (and across both, for the
    corner) within ``band`` of it: the colour field near a plane is then the whole's."""
    pos_parts, val_parts = [pos], {k: [v] for k, v in values.items()}
    for mask in range(1, 1 << len(axes)):
        flip = [a for b, a in enumerate(axes) if mask >> b & 1]
        near = np.all(pos[:, flip] < band, axis=1)
        img = pos[near].copy()
        img[:, flip] *= -1.0
        pos_parts.append(img)
        for k, v in values.items():
            val_parts[k].append(v[near])
    return np.concatenate(pos_parts), {k: np.concatenate(v) for k, v in val_parts.items()}


def reconstruct(pos: np.ndarray, l0: float, fields: Optional[Mapping[str, np.ndarray]] = None,
                params: SurfaceParams = SurfaceParams(), planes: Sequence[str] = (),
                whole: bool = True) -> SurfaceMesh:
    """The surface of the fluid particles at ``pos`` (N x 2 or N x 3, metres; spacing ``l0``),
    with ``fields`` (name -> N values) interpolated to the vertices. ``planes``: the run's
    symmetry planes (axis names); with ``whole`` the mesh is mirrored into the whole scene,
    else it is the simulated part's, cut at the planes."""
    if "RAYON_NUM_THREADS" not in os.environ:
        limit_threads()
    import pysplashsurf

    values = {k: np.ascontiguousarray(v, dtype=np.float64) for k, v in (fields or {}).items()}
    p, copies = _lift(pos, l0)
    p = np.ascontiguousarray(p)
    if copies > 1:
        values = {k: np.tile(v, copies) for k, v in values.items()}
    axes = plane_axes(planes)
    if p.shape[0] == 0:
        return SurfaceMesh.empty(values)
    if axes:
        p, values = _with_images(p, values, axes, params.band(l0))
    if params.weights == "grid":     # the marching cubes alone; smoothing and normals here
        mesh = _reconstruct_grid(p, l0, values, params)
    else:                             # splashsurf's whole pipeline with its own weights
        out, _ = pysplashsurf.reconstruction_pipeline(
            p, attributes_to_interpolate=values or None, particle_radius=0.5 * l0,
            smoothing_length=params.smoothing, cube_size=params.cube,
            iso_surface_threshold=params.iso, mesh_smoothing_iters=params.smoothing_iters or None,
            compute_normals=True, normals_smoothing_iters=params.normal_iters or None)
        attrs = out.point_attributes
        mesh = SurfaceMesh(np.asarray(out.mesh.vertices, dtype=np.float64),
                           np.asarray(out.mesh.triangles, dtype=np.int64).reshape(-1, 3),
                           np.asarray(attrs["normals"], dtype=np.float64),
                           {k: np.asarray(attrs[k], dtype=np.float64) for k in values})
    if not axes:
        return mesh
    mesh = _cut(mesh, axes, snap=SNAP_CUBES * params.cube_size(l0))
    return mirror(mesh, planes) if whole else mesh


def _reconstruct_grid(p: np.ndarray, l0: float, values: Dict[str, np.ndarray],
                      params: SurfaceParams) -> SurfaceMesh:
    """splashsurf's marching cubes alone (``reconstruct_surface``: half the time of its
    ``reconstruction_pipeline`` for the same mesh, measured at booth 4 ms), then the fields
    interpolated to the raw vertices as the pipeline interpolates them (SPH with the
    reconstruction's densities, normalised by the interpolated unity: the same values,
    tests/test_surface.py), and the smoothing with the grid's weights."""
    import pysplashsurf

    radius = 0.5 * l0
    rec = pysplashsurf.reconstruct_surface(
        p, particle_radius=radius, smoothing_length=params.smoothing, cube_size=params.cube,
        iso_surface_threshold=params.iso)        # lengths in particle radii, as the pipeline's
    tri_mesh = rec.mesh
    fields = {}
    if values:
        # the particle mass scales numerator and unity alike: any positive value will do
        sph = pysplashsurf.SphInterpolator(p, np.asarray(rec.particle_densities),
                                           1000.0 * l0 ** 3, params.support(l0))
        at = np.asarray(tri_mesh.vertices)
        unity = np.asarray(sph.interpolate_quantity(np.ones(len(p)), at))
        unity = np.where(unity > 0.0, unity, 1.0)
        fields = {k: np.asarray(sph.interpolate_quantity(v, at)) / unity
                  for k, v in values.items()}
    normals = _smooth(tri_mesh, p, l0, params)
    return SurfaceMesh(np.asarray(tri_mesh.vertices, dtype=np.float64),
                       np.asarray(tri_mesh.triangles, dtype=np.int64).reshape(-1, 3),
                       normals, fields)


def _smooth(mesh, particles: np.ndarray, l0: float, params: SurfaceParams) -> np.ndarray:
    """splashsurf's post-processing with the grid's weights (smoothing_weights.py): the
    weighted Laplacian smoothing of the vertices of splashsurf's ``mesh`` (in place), then the
    area-weighted vertex normals, smoothed; returns the unit normals."""
    import pysplashsurf

    connectivity = mesh.vertex_vertex_connectivity()
    if params.smoothing_iters:
        weights = grid_weights(particles, np.asarray(mesh.vertices), l0)
        pysplashsurf.laplacian_smoothing_parallel(mesh, connectivity, beta=1.0, weights=weights,
                                                  iterations=params.smoothing_iters)
    normals = np.asarray(mesh.vertex_normals_parallel(), dtype=np.float64)
    if params.normal_iters:
        pysplashsurf.laplacian_smoothing_normals_parallel(normals, connectivity,
                                                          iterations=params.normal_iters)
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    return np.where(length > 0, normals / np.where(length > 0, length, 1.0), 0.0)


def used_vertices(triangles: np.ndarray, n_vertices: int) -> Tuple[np.ndarray, np.ndarray]:
    """The vertices that ``triangles`` use, in order (np.unique's answer, by a mask instead of
    a sort: a tenth of the time on a million triangles), and the map old index -> new (-1:
    unused)."""
    mask = np.zeros(n_vertices, bool)
    mask[triangles.ravel()] = True
    used = np.flatnonzero(mask)
    index = np.full(n_vertices, -1, np.int64)
    index[used] = np.arange(len(used))
    return used, index


def _cut(mesh: SurfaceMesh, axes: Tuple[int, ...], snap: float = 0.0) -> SurfaceMesh:
    """The mesh cut at the planes (as splashsurf's mesh AABB does, but after its smoothing,
    which then saw both sides): vertices within ``snap`` (metres) of a plane put on it (the
    smoothing's rounding), triangles wholly beyond a plane dropped, the vertices of the others
    beyond it moved onto it; on a plane a normal loses its component across it."""
    ax = list(axes)
    near = np.abs(mesh.vertices[:, ax]) <= snap
    if near.any():
        mesh = replace(mesh, vertices=mesh.vertices.copy())
        sub = mesh.vertices[:, ax]
        sub[near] = 0.0
        mesh.vertices[:, ax] = sub
    inside = np.all(mesh.vertices[:, ax] > 0.0, axis=1)
    tris = mesh.triangles[inside[mesh.triangles].any(axis=1)]
    used, index = used_vertices(tris, mesh.n_vertices)
    v, n = mesh.vertices[used].copy(), mesh.normals[used].copy()
    sub = v[:, ax]
    beyond = sub < 0.0
    sub[beyond] = 0.0
    v[:, ax] = sub
    nsub = n[:, ax]
    nsub[beyond | (sub == 0.0)] = 0.0
    n[:, ax] = nsub
    length = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.where(length > 0, n / np.where(length > 0, length, 1.0), mesh.normals[used])
    return SurfaceMesh(v, index[tris], n, {k: f[used] for k, f in mesh.fields.items()})


def mirror(mesh: SurfaceMesh, planes: Sequence[str]) -> SurfaceMesh:
    """A mesh of the part x > 0 (and y > 0) of a symmetric scene, cut at the planes, mirrored
    into the whole: one copy per set of planes, reflected (normals too, winding reversed for
    an odd number of reflections), and the vertices that lie on a plane shared between the
    copies, so that the whole has no seam."""
    axes = plane_axes(planes)
    if not axes or mesh.n_vertices == 0:
        return mesh
    verts, tris, norms = [mesh.vertices], [mesh.triangles], [mesh.normals]
    fields = {k: [v] for k, v in mesh.fields.items()}
    for mask in range(1, 1 << len(axes)):
        flip = [a for b, a in enumerate(axes) if mask >> b & 1]
        v, n = mesh.vertices.copy(), mesh.normals.copy()
        v[:, flip] *= -1.0
        n[:, flip] *= -1.0
        t = mesh.triangles + sum(len(x) for x in verts)
        verts.append(v)
        norms.append(n)
        tris.append(t[:, ::-1] if len(flip) % 2 else t)
        for k in fields:
            fields[k].append(mesh.fields[k])
    whole = SurfaceMesh(np.concatenate(verts), np.concatenate(tris), np.concatenate(norms),
                        {k: np.concatenate(v) for k, v in fields.items()})
    return _weld_planes(whole, axes)


def _weld_planes(mesh: SurfaceMesh, axes: Tuple[int, ...]) -> SurfaceMesh:
    """Merge the vertices on the planes that sit at the same place (the copies of one cut
    vertex); their normals are averaged (the plane's component cancels)."""
    v = mesh.vertices
    on = np.any(v[:, list(axes)] == 0.0, axis=1)
    idx = np.flatnonzero(on)
    _, first, inverse = np.unique(v[idx], axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    remap = np.arange(len(v))
    remap[idx] = idx[first][inverse]
    normals = mesh.normals.copy()
    summed = np.zeros((len(first), 3))
    np.add.at(summed, inverse, mesh.normals[idx])
    length = np.linalg.norm(summed, axis=1, keepdims=True)
    normals[idx[first]] = np.where(length > 0, summed / np.where(length > 0, length, 1.0),
                                   mesh.normals[idx[first]])
    keep = np.ones(len(v), bool)
    keep[idx] = False
    keep[idx[first]] = True
    new_index = np.cumsum(keep) - 1
    tris = new_index[remap[mesh.triangles]]
    return replace(mesh, vertices=v[keep], triangles=tris, normals=normals[keep],
                   fields={k: f[keep] for k, f in mesh.fields.items()})


__all__ = ["SurfaceParams", "SurfaceMesh", "reconstruct", "fluid_of", "mirror", "plane_axes",
           "limit_threads", "AXES", "SLICE_LAYERS"]
