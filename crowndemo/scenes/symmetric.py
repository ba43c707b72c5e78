"""One half or one quarter of a mirror-symmetric scene, for a run with symmetry planes
(core/symmetry.py): the scene moved so that its planes pass through 0, and cut to x > 0
(and y > 0)."""
from __future__ import annotations

from dataclasses import replace
from typing import Sequence

import numpy as np

from ..core.params import with_values
from ..core.symmetry import cut, fraction, plane_names, symmetry_name
from .base import Scene


def halve(scene: Scene, planes: Sequence[int], centre: Sequence[float]) -> Scene:
    """The part of ``scene`` beyond its symmetry planes x_a = centre[a] (a in ``planes``),
    moved by -centre so that the planes are x_a = 0; ValueError if the scene is not mirror
    symmetric about them (core/symmetry.cut). ``centre`` has one entry per axis."""
    planes = tuple(planes)
    shift = np.zeros(scene.dim)
    shift[list(planes)] = [centre[a] for a in planes]
    pos = scene.pos - shift
    keep = cut(pos, planes, tol=1.0e-3 * scene.physics.l0)
    lo = tuple(np.asarray(scene.domain[0]) - shift)
    hi = tuple(np.asarray(scene.domain[1]) - shift)
    info = dict(scene.info, symmetry=symmetry_name(planes), symmetry_planes=plane_names(planes),
                simulated_fraction=fraction(planes), moved_by_m=[float(x) for x in -shift])
    return replace(scene, pos=pos[keep], vel=scene.vel[keep], kind=scene.kind[keep],
                   domain=(lo, hi), numerics=with_values(scene.numerics, mirror_planes=planes),
                   info=info)


__all__ = ["halve"]
