"""The seed's milk-crown scene (method.md §6): a drop of diameter D falling at speed U onto a
film of thickness h on a square floor, in 3D or as a 2D cross-section (a cylinder-drop slice).

What the scene does not need is left out, and said so in ``info["left_out"]``: the film beyond
the radius the impact can disturb before the end time (its edge is then a free edge at rest),
the side walls when the liquid cannot reach them, and the surface-tension and viscosity terms
when their coefficients are zero (the compiled model drops them).
"""
from __future__ import annotations

import math
from typing import Optional, Tuple

import numpy as np

from ..core.params import GRAVITY, WATER, Numerics, Physics, with_values
from ..core.lattice import wall_layers
from ..core.symmetry import fraction, plane_names, planes_of
from .base import (Scene, assemble, container_walls, floor_cut, floor_face, lattice_block,
                   particle_faces)


def crown_base_radius(t: float, U: float, D: float, h: float) -> float:
    """Yarin & Weiss (1995): R_c/D = (2/(3 delta))^(1/4) sqrt(tau), tau = t U / D, delta = h/D
    (method.md §7, tau0 = 0)."""
    return D * (2.0 / (3.0 * h / D)) ** 0.25 * math.sqrt(max(t, 0.0) * U / D)


TRIM_REACH = 2.0     # the film kept: out to this many crown base radii at t_end (+ 2 mm)


def reach_radius(t_end: float, U: float, D: float, h: float, gap: float,
                 factor: float = TRIM_REACH) -> float:
    """How far from the axis the liquid can be disturbed by t_end: ``factor`` (2) times the
    crown base radius at the end time (the film ahead of the crown is pushed too), at least
    the drop, plus 2 mm. (Measured in 2D at D/l0 = 100, U = 8 m/s, untrimmed: the film moving
    faster than 1 m/s reached 1.4 R_c at 1 ms and 0.9-1.0 R_c at 3-4 ms, the rest of the film
    jittering at 0.4-0.8 m/s; docs/symmetry.md.)
    Yarin & Weiss's radius grows without bound as h -> 0; a film thinner than D/10 (a dry floor
    included) is taken as D/10, which bounds a lamella spreading on a dry floor (r/D of about
    1.1 sqrt(t U / D), Rioboo et al. 2002) with a margin."""
    t_impact = gap / U
    return max(factor * crown_base_radius(t_end - t_impact, U, D, max(h, 0.1 * D)), D) + 2.0e-3


def film_extent(floor: float, trim: bool, t_end: float, U: float, D: float, h: float,
                gap: float, factor: float = TRIM_REACH) -> Tuple[float, bool]:
    """How far from the axis the film is built, and whether that is a trim: ``reach_radius``
    when ``trim`` is asked and the reach lies inside the floor, else half the floor's side."""
    half = floor / 2.0
    reach = reach_radius(t_end, U, D, h, gap, factor)
    trimmed = bool(trim and reach < half)
    return (reach if trimmed else half), trimmed


def crown(dim: int = 3, l0: float = 5.0e-4, film: float = 1.0e-3, drop: float = 1.0e-2,
          speed: float = 8.0, gap: float = 1.0e-3, floor: float = 0.09, t_end: float = 4.0e-3,
          trim: bool = True, numerics: Optional[Numerics] = None, rho: float = WATER["rho"],
          nu: float = WATER["nu"], sigma: float = WATER["sigma"], gravity: float = GRAVITY,
          sound_speed: Optional[float] = None, re_ratio: float = 2.1,
          symmetry: str = "full", trim_reach: float = TRIM_REACH) -> Scene:
    """Drop on a film. ``floor`` is the side of the square container floor (the width of the
    slice in 2D); the axis of the drop is x = 0 (and y = 0), the floor surface z = 0.
    ``symmetry``: the whole scene (full), or the part x > 0 (half), or x > 0, y > 0 (quarter,
    3D) with mirror planes through the axis (core/symmetry.py). Across the floor the lattice
    lies at +-(k + 1/2) l0 from the axis whatever the symmetry, so that the part's mirror
    images continue it and the whole scene is the mirrored quarter, particle for particle."""
    planes = planes_of(symmetry, dim)
    physics = Physics(dim=dim, l0=l0, v_max=speed, re_ratio=re_ratio, rho=rho, nu=nu,
                      sigma=sigma, gravity=gravity, sound_speed=sound_speed)
    half = floor / 2.0
    extent, trimmed = film_extent(floor, trim, t_end, speed, drop, film, gap, trim_reach)
    # the film: the lattice over the floor, cut to a disc of radius `extent` when trimmed (3D).
    # Across the floor a box of half-width w starts at the plane (0) on a plane's axis, else at
    # -k l0 with k = floor(w / l0): its points +-(k + 1/2) l0 are symmetric about the axis, and
    # film, drop and floor lie on one lattice (the floor's side walls at +-k l0, within l0 of w)
    cells = lambda w: math.floor(w / l0 + 1.0e-9)
    side = lambda w: [0.0 if a in planes else -cells(w) * l0 for a in range(dim - 1)]
    reach = cells(extent) * l0
    film_pts = lattice_block(side(extent) + [0.0], [reach] * (dim - 1) + [film], l0)
    if trimmed and dim == 3:
        film_pts = film_pts[np.linalg.norm(film_pts[:, :2], axis=1) <= extent]
    # the drop: lattice points inside the sphere (disc), its bottom `gap` above the film
    radius = drop / 2.0
    centre_z = film + gap + radius
    across = math.ceil(radius / l0 - 1.0e-9) * l0       # every lattice point within the sphere
    box = lattice_block(side(across) + [centre_z - radius],
                        [across] * (dim - 1) + [centre_z + radius], l0)
    rel = box - np.array([0.0] * (dim - 1) + [centre_z])
    drop_pts = box[np.linalg.norm(rel, axis=1) <= radius]
    fluid = np.concatenate([film_pts, drop_pts])
    vel = np.zeros_like(fluid)
    vel[len(film_pts):, -1] = -speed
    # walls: the floor under the film; side walls only if the liquid can reach them
    layers = wall_layers(re_ratio)
    faces = [floor_face(dim)]
    if not trimmed:
        faces += ["x-", "x+"] + (["y-", "y+"] if dim == 3 else [])
    beyond_planes = {f"{'xy'[a]}-" for a in planes}     # the mirrored side has no wall
    faces = [f for f in faces if f not in beyond_planes]
    faces = particle_faces(faces, dim, numerics)
    wall_top = film + 0.5 * drop
    floor_lo = side(reach + (0 if not trimmed else layers * l0)) + [0.0]
    floor_hi = [reach + (0 if not trimmed else layers * l0)] * (dim - 1) + [wall_top]
    walls = container_walls(floor_lo, floor_hi, l0, layers, faces) if faces else None
    if walls is not None and trimmed and dim == 3:   # the disc under the film, a rim `layers` wide
        keep = np.linalg.norm(walls[0][:, :2], axis=1) <= extent + layers * l0
        walls = (walls[0][keep], walls[1][keep])
    margin = (layers + 1) * l0
    top = centre_z + radius + speed * t_end + 0.05
    domain = floor_cut((tuple([-half - margin] * dim), tuple([half + margin] * (dim - 1) + [top])),
                       l0)
    left_out = []
    if trimmed:
        left_out.append(f"film beyond r = {extent * 1e3:.1f} mm (of {half * 1e3:.0f} mm): the "
                        "impact cannot disturb it before t_end; its edge is free")
        left_out.append("side walls: the liquid cannot reach them before t_end")
    if floor_face(dim) not in faces:
        left_out.append("floor particles: the analytic plane floor stands for them")
    if sigma == 0:
        left_out.append("surface tension term (sigma = 0)")
    if nu == 0:
        left_out.append("viscosity term (nu = 0)")
    info = {"scene": "crown", "film_m": film, "drop_m": drop, "speed_m_s": speed, "gap_m": gap,
            "floor_m": floor, "extent_m": extent, "trimmed": trimmed, "walls": faces,
            "n_film": int(len(film_pts)), "n_drop": int(len(drop_pts)), "left_out": left_out,
            "symmetry": symmetry, "symmetry_planes": plane_names(planes),
            "simulated_fraction": fraction(planes)}
    if planes:
        across = " and ".join(f"{a} = 0" for a in plane_names(planes))
        left_out.append(f"the mirror images across {across}: one {symmetry} of the scene is "
                        "simulated (counts are of that part)")
    numerics = with_values(numerics or Numerics(), mirror_planes=planes)
    return assemble("crown", physics, numerics, fluid, vel, walls, domain, t_end, info,
                    floor=True)
