"""Predictor (method.md §3 steps 1-2): viscosity, gravity and surface tension (S14-S16).

The terms a scene does not use are not compiled in (``ti.static`` on the model's flags); if
neither viscosity nor surface tension is on, the predictor is a plain element-wise update with
no neighbour walk.
"""

import taichi as ti

from .coefficients import Coefficients
from .grid import CellGrid
from .operators import laplacian_pair, weight
from .params import Model
from .state import DUMMY, FLUID


@ti.func
def surface_tension_pair(rij, r, l0, re):
    """Minus the gradient of the inter-particle potential (S22) for one pair, per unit C:
    (r - l0)(r - re) r_ij / r with r_ij = r_j - r_i (method.md §4 sign note).
    Times C/m (C <= 0) it attracts for l0 < r < re and repels for r < l0."""
    return (r - l0) * (r - re) / r * rij


@ti.data_oriented
class Predictor:
    def __init__(self, model: Model, grid: CellGrid, coef: Coefficients):
        self.model, self.grid, self.coef, self.state = model, grid, coef, grid.state
        self.dim = model.dim

    @property
    def needs_neighbours(self) -> bool:
        return self.model.viscosity or self.model.surface_tension

    @ti.func
    def _pair(self, i, j, rij, r2, acc: ti.template()):
        kind_j = self.state.kind[j]
        if kind_j != DUMMY:
            r = ti.sqrt(r2)
            if ti.static(self.model.viscosity):
                # nu <lap u> (S12 in S14): walls have u = 0 (no-slip)
                acc += self.coef.nu[None] * (2.0 * self.dim) / (
                    self.coef.lambda0[None] * self.coef.n0[None]) * laplacian_pair(
                    self.state.vel[j] - self.state.vel[i], weight(r, self.coef.re[None]))
            if ti.static(self.model.surface_tension):
                if kind_j == FLUID:      # fluid-fluid potential (S24, sign per method.md §4)
                    acc += self.coef.st_over_m[None] * surface_tension_pair(
                        rij, r, self.coef.l0[None], self.coef.re[None])

    @ti.kernel
    def run(self, dt: float):
        """u* = u + dt a* (S15), r* = r + dt u* (S16), a* from (S14)."""
        if ti.static(self.needs_neighbours):
            for i in range(self.state.n[None]):
                if self.state.kind[i] == FLUID:
                    acc = ti.Vector.zero(float, self.dim)
                    self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None], self._pair,
                                                 acc)
                    if ti.static(self.model.gravity):
                        acc += self.coef.gravity[None]
                    self.state.scratch_vec[i] = self.state.vel[i] + dt * acc
            for i in range(self.state.n[None]):
                if self.state.kind[i] == FLUID:
                    self.state.vel[i] = self.state.scratch_vec[i]
                    self.state.pos[i] += dt * self.state.vel[i]
        else:
            for i in range(self.state.n[None]):
                if self.state.kind[i] == FLUID:
                    if ti.static(self.model.gravity):
                        self.state.vel[i] += dt * self.coef.gravity[None]
                    self.state.pos[i] += dt * self.state.vel[i]
