"""Free drops without gravity for the surface-tension references (method.md §7): a drop set
oscillating in its mode 2 (Rayleigh-Lamb) and a drop at rest (Laplace pressure)."""
from __future__ import annotations

import math
from dataclasses import replace
from typing import Optional

import numpy as np

from ..core.params import WATER, Numerics, Physics
from .base import Scene, assemble, lattice_block
from .drop_modes import lamb_decay, rayleigh_omega, viscous_mode

COMPRESSION = 0.01   # the sound speed keeps the cohesion's compression ~1 % (see drop_sound_speed)
DISORDER_SEED = 1    # the disordered start's random offsets: the same start every run


def mode2_omega(dim: int, radius: float, sigma: float, rho: float) -> float:
    """Angular frequency of the mode-2 oscillation: omega^2 = 8 sigma/(rho R^3) in 3D,
    6 sigma/(rho R^3) in 2D (method.md §7)."""
    return rayleigh_omega(dim, 2, radius, sigma, rho)


def mode2_decay(dim: int, radius: float, nu: float) -> float:
    """Viscous decay rate of the mode-2 amplitude: 5 nu/R^2 (3D), 4 nu/R^2 (2D) (method.md §7)."""
    return lamb_decay(dim, 2, radius, nu)


def disordered(pts: np.ndarray, l0: float, amount: float,
               seed: int = DISORDER_SEED) -> np.ndarray:
    """The points each moved by independent offsets uniform in [-amount, amount] l0 along every
    axis, from a seeded generator (the same start every run). A liquid's particles keep no
    lattice; a ball cut from one is a crystal, whose pairs, pre-stressed by the Laplace
    pressure, resist shear like a solid's and raised the stress model's 3D mode-2 frequency
    6-11 % at R/l0 = 8-12 (VALIDATION.md, "A disordered start for the 3D drops")."""
    if amount <= 0.0:
        return pts
    rng = np.random.default_rng(seed)
    return pts + amount * l0 * rng.uniform(-1.0, 1.0, pts.shape)


def ball(dim: int, radius: float, l0: float, disorder: float = 0.0) -> np.ndarray:
    """The drops' particles: the lattice points within ``radius`` of the centre, moved by
    ``disordered`` when ``disorder`` > 0."""
    pts = lattice_block([-radius] * dim, [radius] * dim, l0)
    return disordered(pts[np.linalg.norm(pts, axis=1) <= radius], l0, disorder)


def drop_sound_speed(l0: float, sigma: float, rho: float) -> float:
    """A sound speed at which the potential model's bulk cohesion, about 3 sigma/l0, compresses
    the liquid by ~COMPRESSION: c^2 rho COMPRESSION = 3 sigma / l0 (S17)."""
    return math.sqrt(3.0 * sigma / (l0 * rho * COMPRESSION))


def oscillating_drop(dim: int = 2, radius: float = 1.0e-3, l0: float = 1.0e-4,
                     amplitude: float = 0.1, periods: float = 2.0,
                     numerics: Optional[Numerics] = None, sound_speed: Optional[float] = None,
                     disorder: float = 0.0, re_ratio: float = 2.1, **liquid) -> Scene:
    """A disc (ball) of radius R released with the velocity of its mode-2 oscillation of
    relative amplitude ``amplitude``: the potential phi = A (x^2 - y^2) in 2D,
    A (z^2 - (x^2 + y^2)/2) in 3D, with A = amplitude omega / 2, so that the surface moves as
    R (1 + amplitude cos(2 theta) sin(omega t)) (P2 in 3D). Runs ``periods`` periods. The
    particles sit on the lattice, or with ``disorder`` > 0 off it (``disordered``); re =
    ``re_ratio`` l0 (S10)."""
    liq = {**WATER, **liquid}
    omega = mode2_omega(dim, radius, liq["sigma"], liq["rho"])
    A = 0.5 * amplitude * omega
    pts = ball(dim, radius, l0, disorder)
    vel = np.zeros_like(pts)
    if dim == 2:
        vel[:, 0], vel[:, 1] = 2 * A * pts[:, 0], -2 * A * pts[:, 1]
    else:
        vel[:, 0], vel[:, 1], vel[:, 2] = -A * pts[:, 0], -A * pts[:, 1], 2 * A * pts[:, 2]
    c = sound_speed or drop_sound_speed(l0, liq["sigma"], liq["rho"])
    physics = Physics(dim=dim, l0=l0, v_max=max(2 * A * radius, 1e-3), gravity=0.0,
                      sound_speed=c, re_ratio=re_ratio, **liq)
    period = 2 * math.pi / omega
    domain = (tuple([-4.0 * radius] * dim), tuple([4.0 * radius] * dim))
    info = {"scene": "oscillating drop", "radius_m": radius, "amplitude": amplitude,
            "disorder_l0": disorder,
            "omega_rad_s": omega, "period_s": period,
            "decay_1_s": mode2_decay(dim, radius, liq["nu"]), "walls": []}
    # the exact viscous mode at this viscosity (Lamb's rate and Rayleigh's frequency are its
    # small-viscosity limits; at the stress cases' nu = 1e-5 it decays at 0.895 / 0.905 times
    # Lamb's rate and oscillates 0.68 / 0.61 % below Rayleigh's, 3D / 2D)
    try:
        info["omega_exact_rad_s"], info["decay_exact_1_s"] = viscous_mode(
            dim, 2, radius, liq["sigma"], liq["rho"], liq["nu"])
    except ArithmeticError:     # far beyond the aperiodic limit: no reference printed (nan)
        info["omega_exact_rad_s"] = info["decay_exact_1_s"] = math.nan
    return assemble("drop-oscillation", physics, numerics or Numerics(), pts, vel, None, domain,
                    periods * period, info)


def resting_drop(dim: int = 2, radius: float = 1.0e-3, l0: float = 1.0e-4, t_end: float = 0.01,
                 numerics: Optional[Numerics] = None, sound_speed: Optional[float] = None,
                 disorder: float = 0.0, re_ratio: float = 2.1, **liquid) -> Scene:
    """A disc (ball) of radius R at rest without gravity: its inside pressure exceeds the
    outside by sigma/R (2D), 2 sigma/R (3D). ``disorder``, ``re_ratio``: as
    ``oscillating_drop``'s."""
    sc = oscillating_drop(dim, radius, l0, amplitude=0.0, numerics=numerics,
                          sound_speed=sound_speed, disorder=disorder, re_ratio=re_ratio,
                          **liquid)
    sc.info["scene"] = "resting drop"
    return replace(sc, name="resting-drop", t_end=t_end)
