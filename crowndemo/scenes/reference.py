"""Reference scenes with known answers (method.md §7), in 2D and 3D: hydrostatic tank,
dam break (column a x 2a), and a free square patch of liquid without gravity."""
from __future__ import annotations

import math
from typing import Optional

import numpy as np

from ..core.params import GRAVITY, WATER, Numerics, Physics
from ..core.lattice import wall_layers
from .base import Scene, assemble, container_walls, lattice_block, particle_faces


def _walls_faces(dim: int) -> list:
    """Floor and side walls of an open-top container."""
    return ["x-", "x+", "y-"] if dim == 2 else ["x-", "x+", "y-", "y+", "z-"]


def hydrostatic_tank(dim: int = 2, l0: float = 1.0e-3, width: float = 0.04, depth: float = 0.04,
                     nu: float = WATER["nu"], t_end: float = 0.5,
                     numerics: Optional[Numerics] = None,
                     **physics) -> Scene:
    """A column of water of height ``depth`` at rest in a container ``width`` wide (square
    floor in 3D); P(z) = rho g (H - z). v_max = sqrt(2 g H) sets c = 5 v_max (S8)."""
    g = physics.pop("gravity", GRAVITY)
    v_max = physics.pop("v_max", math.sqrt(2.0 * g * depth))
    ph = Physics(dim=dim, l0=l0, v_max=v_max, gravity=g,
                 **{**WATER, "sigma": 0.0, "nu": nu, **physics})
    # walls reach above the surface: the start from zero pressure sloshes the surface up
    inner_hi = [width] * (dim - 1) + [depth + max(4 * l0, 0.25 * depth)]
    fluid = lattice_block([0.0] * dim, [width] * (dim - 1) + [depth], l0)
    layers = wall_layers(ph.re_ratio)
    faces = particle_faces(_walls_faces(dim), dim, numerics)
    walls = container_walls([0.0] * dim, inner_hi, l0, layers, faces)
    margin = (layers + 1) * l0
    domain = (tuple([-margin] * dim), tuple([width + margin] * (dim - 1) + [3.0 * depth]))
    info = {"scene": "hydrostatic tank", "width_m": width, "depth_m": depth,
            "walls": faces, "wall_top_m": inner_hi[-1]}
    return assemble("tank", ph, numerics or Numerics(), fluid, None, walls, domain, t_end, info)


def dam_break(dim: int = 2, a: float = 0.05, l0: float = 2.0e-3, length: float = 4.0,
              channel: float = 1.0, t_end: float = 0.2, numerics: Optional[Numerics] = None,
              **physics) -> Scene:
    """A water column a wide and 2a high at the left end of a tank ``length`` a long (and
    ``channel`` a wide in 3D); Martin & Moyce's surge front z/a against t sqrt(2g/a)."""
    g = physics.pop("gravity", GRAVITY)
    v_max = physics.pop("v_max", math.sqrt(2.0 * g * 2.0 * a))
    ph = Physics(dim=dim, l0=l0, v_max=v_max, gravity=g, **{**WATER, "sigma": 0.0, **physics})
    across = [channel * a] * (dim - 2)
    fluid = lattice_block([0.0] * dim, [a] + across + [2.0 * a], l0)
    inner_hi = [length * a] + across + [2.5 * a]
    layers = wall_layers(ph.re_ratio)
    faces = particle_faces(_walls_faces(dim), dim, numerics)
    walls = container_walls([0.0] * dim, inner_hi, l0, layers, faces)
    margin = (layers + 1) * l0
    domain = (tuple([-margin] * dim),
              tuple([length * a + margin] + [channel * a + margin] * (dim - 2) + [6.0 * a]))
    info = {"scene": "dam break", "a_m": a, "length_a": length, "channel_a": channel,
            "walls": faces, "wall_top_m": inner_hi[-1]}
    return assemble("dam-break", ph, numerics or Numerics(), fluid, None, walls, domain, t_end,
                    info)


def square_patch(dim: int = 2, side: float = 2.0e-3, l0: float = 1.0e-4,
                 sigma: float = WATER["sigma"],
                 nu: float = 1.0e-4, v_max: float = 1.0, t_end: float = 0.03,
                 numerics: Optional[Numerics] = None, **physics) -> Scene:
    """A square (cube) of liquid at rest without gravity: surface tension rounds it up and the
    inside pressure tends to the Laplace jump sigma/R (2D), 2 sigma/R (3D). No walls."""
    ph = Physics(dim=dim, l0=l0, v_max=v_max, gravity=0.0,
                 **{**WATER, "sigma": sigma, "nu": nu, **physics})
    half = side / 2.0
    fluid = lattice_block([-half] * dim, [half] * dim, l0)
    domain = (tuple([-3.0 * side] * dim), tuple([3.0 * side] * dim))
    info = {"scene": "square patch", "side_m": side, "walls": []}
    return assemble("patch", ph, numerics or Numerics(), fluid, None, None, domain, t_end, info)


def equivalent_radius(n_fluid: int, dim: int, l0: float) -> float:
    """Radius of the circle (sphere) with the fluid's volume n l0^d."""
    vol = n_fluid * l0 ** dim
    return math.sqrt(vol / math.pi) if dim == 2 else (3.0 * vol / (4.0 * math.pi)) ** (1 / 3)


def circularity(pos: np.ndarray, l0: float) -> float:
    """R_eq / R_out: 1 for a disc (ball), sqrt(2/pi) = 0.80 for a square; R_out is the
    distance from the centroid to the outermost particles (mean of the outer 2 %) + l0/2."""
    dim = pos.shape[1]
    r = np.linalg.norm(pos - pos.mean(axis=0), axis=1)
    outer = np.sort(r)[-max(3, len(r) // 50):].mean() + 0.5 * l0
    return equivalent_radius(len(pos), dim, l0) / outer
