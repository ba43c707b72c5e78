"""The vertex weights of the surface's smoothing, from a coarse grid of particle counts.

splashsurf's weighted Laplacian smoothing (Löschner et al., 2023) smooths a vertex in
proportion to how much liquid is around it, so that the crown's wall is smoothed and its
droplets keep their size (unweighted, 5 iterations shrink the spray of a booth frame away).
splashsurf computes the weight from each particle's distance-weighted neighbour count
(sum of 1 - r^2/h^2 over the kernel's support h), interpolated to the vertices by SPH and
mapped by smoothstep(min(1, count / 13)); at booth quality that takes half of the
reconstruction (2.5 s of 5 at 4 ms, BENCHMARKS.md).

Here the count near a vertex comes from the particles binned into cells of CELL l0, read
at the vertex by trilinear interpolation between cell centres, and scaled to splashsurf's
count by COUNT_PER_PARTICLE. That constant was fitted on the vertices of the booth 3m-drop
at 4 ms (1.1 M vertices), against the weights splashsurf computed for the same mesh
(``output_mesh_smoothing_weights``): mean |difference| 0.049, the share of vertices at full
weight 0.44 against 0.43, and below 0.1 0.35 against 0.40 (tests/test_surface.py compares
the two on a crown of its own). It costs 0.2 s there instead of 2.5 s.

The cells' faces lie on whole multiples of the cell side from the origin, so on the symmetry
planes x = 0 and y = 0: a mirror-symmetric set of particles then gives mirror-symmetric
weights, and a vertex on a plane stays on it through the smoothing (surface.mirror welds
the copies of such vertices; a grid placed from the particles' extent left vertices 1e-11 l0
off a plane and 4 open edges in the mirrored quarter of ``quick``).
"""
from __future__ import annotations

import numpy as np

CELL = 3.0                  # cell side / l0 (2 and 4 l0 fitted worse: 0.089, 0.065)
COUNT_PER_PARTICLE = 2.09   # splashsurf's weighted count per particle counted in a cell
NORMALISATION = 13.0        # splashsurf's count of full weight (its default)


def grid_weights(particles: np.ndarray, vertices: np.ndarray, l0: float) -> np.ndarray:
    """Smoothing weights in [0, 1] of ``vertices`` (V x 3) among ``particles`` (N x 3),
    both in metres, of spacing ``l0``."""
    if len(vertices) == 0 or len(particles) == 0:
        return np.zeros(len(vertices))
    cell = CELL * l0
    lo = (np.floor(np.minimum(particles.min(axis=0), vertices.min(axis=0)) / cell) - 2.0) * cell
    ip = np.floor((particles - lo) / cell).astype(np.int64)
    dims = np.maximum(ip.max(axis=0),
                      np.floor((vertices - lo) / cell).astype(np.int64).max(axis=0)) + 3
    counts = np.bincount(np.ravel_multi_index(tuple(ip.T), dims),
                         minlength=int(np.prod(dims))).reshape(dims).astype(np.float32)
    f = (vertices - lo) / cell - 0.5           # in units of cells, from the first centre
    i0 = np.floor(f).astype(np.int64)
    t = f - i0
    count = np.zeros(len(vertices))
    for corner in range(8):
        d = [(corner >> a) & 1 for a in range(3)]
        w = np.prod([t[:, a] if d[a] else 1.0 - t[:, a] for a in range(3)], axis=0)
        count += w * counts[i0[:, 0] + d[0], i0[:, 1] + d[1], i0[:, 2] + d[2]]
    x = np.clip(COUNT_PER_PARTICLE * count / NORMALISATION, 0.0, 1.0)
    return x * x * x * (10.0 - 15.0 * x + 6.0 * x * x)        # smoothstep, as splashsurf


__all__ = ["grid_weights", "CELL", "COUNT_PER_PARTICLE", "NORMALISATION"]
