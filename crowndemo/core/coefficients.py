"""Run-time constants of the step, held in 0-D fields so that changing them never recompiles."""

from typing import Sequence

import taichi as ti

from .lattice import LatticeConstants
from .params import Numerics, Physics


@ti.data_oriented
class Coefficients:
    def __init__(self, dim: int):
        self.dim = dim
        s = lambda: ti.field(float, shape=())
        self.l0, self.re, self.re2, self.n0, self.lambda0 = s(), s(), s(), s(), s()
        self.rho, self.nu, self.c2, self.mass = s(), s(), s(), s()
        self.st_over_m = s()          # C / m of the potential model (S24)
        self.sigma = s()              # surface tension (the curvature model's P = sigma kappa)
        self.stress_a = s()           # the surface-stress model's lattice normaliser a (C2)
        self.stress_K = s()           # its colour gradient's normalisation K (C1)
        self.stress_Kd = s()          # its divergence's normalisation K_d (C3)
        self.beta = s()               # free-surface threshold (M3)
        self.col_r2 = s()             # (collision distance)^2 of the collision model
        self.col_e = s()              # its restitution coefficient
        self.floor_z = s()            # the floor's wall-layer plane, -l0/2: the collision
        #                               model's on the particle floor (terms.py)
        self.gravity = ti.Vector.field(dim, float, shape=())
        self.domain_lo = ti.Vector.field(dim, float, shape=())
        self.domain_hi = ti.Vector.field(dim, float, shape=())

    def set(self, physics: Physics, numerics: Numerics, lattice: LatticeConstants,
            domain_lo: Sequence[float], domain_hi: Sequence[float], floor: bool = False) -> None:
        """``floor``: the scene stands on a floor at z = 0 (scenes/base.py Scene.floor); else
        the collision model's floor plane lies out of reach."""
        self.l0[None] = physics.l0
        self.re[None] = lattice.re
        self.re2[None] = lattice.re ** 2
        self.n0[None] = lattice.n0
        self.lambda0[None] = lattice.lambda0
        self.rho[None] = physics.rho
        self.nu[None] = physics.nu
        self.c2[None] = physics.c ** 2
        self.mass[None] = lattice.mass
        self.st_over_m[None] = lattice.C / lattice.mass
        self.sigma[None] = physics.sigma
        self.stress_a[None] = lattice.stress_a
        self.stress_K[None] = lattice.stress_K
        self.stress_Kd[None] = lattice.stress_Kd
        self.beta[None] = numerics.free_surface_beta(physics.dim)
        self.col_r2[None] = (numerics.collision * physics.l0) ** 2
        self.col_e[None] = numerics.restitution
        self.floor_z[None] = -0.5 * physics.l0 if floor else -1e30
        g = [0.0] * self.dim
        g[-1] = -physics.gravity
        self.gravity[None] = g
        self.domain_lo[None] = list(domain_lo)
        self.domain_hi[None] = list(domain_hi)
