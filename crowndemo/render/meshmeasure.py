"""Measures of a triangle mesh (numpy): area, enclosed volume, open edges, Euler characteristic,
connected pieces; what the surface tests and the summary state about a reconstruction."""
from __future__ import annotations

import numpy as np


def area(vertices: np.ndarray, triangles: np.ndarray) -> float:
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    return float(0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum())


def volume(vertices: np.ndarray, triangles: np.ndarray) -> float:
    """Enclosed volume of a closed, outward-wound mesh (divergence theorem)."""
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def _edges(triangles: np.ndarray) -> np.ndarray:
    e = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    return np.sort(e, axis=1)


def open_edges(triangles: np.ndarray) -> int:
    """Edges not shared by exactly two triangles (0 for a closed manifold mesh)."""
    if len(triangles) == 0:
        return 0
    _, counts = np.unique(_edges(triangles), axis=0, return_counts=True)
    return int((counts != 2).sum())


def euler(triangles: np.ndarray) -> int:
    """V - E + F over the vertices in use: 2 per closed piece without handles."""
    if len(triangles) == 0:
        return 0
    n_edges = len(np.unique(_edges(triangles), axis=0))
    return int(len(np.unique(triangles)) - n_edges + len(triangles))


def pieces(n_vertices: int, triangles: np.ndarray) -> int:
    """How many connected pieces the triangles form (union-find over their edges)."""
    if len(triangles) == 0:
        return 0
    parent = np.arange(n_vertices)
    edges = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]]])
    while True:                                 # hook roots, then compress, until stable
        a, b = parent[edges[:, 0]], parent[edges[:, 1]]
        low = np.minimum(a, b)
        changed = False
        for x in (a, b):
            m = low < parent[x]
            if m.any():
                np.minimum.at(parent, x[m], low[m])
                changed = True
        while True:
            grand = parent[parent]
            if np.array_equal(grand, parent):
                break
            parent = grand
        if not changed:
            break
    return int(len(np.unique(parent[np.unique(triangles)])))


__all__ = ["area", "volume", "open_edges", "euler", "pieces"]
