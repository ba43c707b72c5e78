"""Pressure (method.md §3 steps 3-5): number density at r*, the equation of state (S17, M3)
and the pressure-gradient corrector (S18-S20) in one of three forms (M2):

- ``seed``: (P_j - P_i), the gradient model (S11) as printed in the seed;
- ``pmin``: (P_j - Pmin_i), Pmin_i the least pressure among i and its neighbours (repulsive);
- ``sum``:  (P_j + P_i), the momentum-conserving form of explicit MPS papers.
"""

import taichi as ti

from .coefficients import Coefficients
from .grid import CellGrid
from .operators import gradient_pair, weight
from .params import Model
from .state import DUMMY, FLUID, WALL


@ti.func
def equation_of_state(n, n0, c2, rho, beta):
    """P = c^2 rho (n - n0)/n0 (S17), clamped at 0, and 0 on the free surface n < beta n0 (M3)."""
    p = 0.0
    if n >= beta * n0:
        p = ti.max(c2 * rho * (n - n0) / n0, 0.0)
    return p


@ti.data_oriented
class Pressure:
    def __init__(self, model: Model, grid: CellGrid, coef: Coefficients):
        self.model, self.grid, self.coef, self.state = model, grid, coef, grid.state
        self.dim = model.dim

    @ti.func
    def _density_pair(self, i, j, rij, r2, acc: ti.template()):
        acc += weight(ti.sqrt(r2), self.coef.re[None])

    @ti.kernel
    def density_and_pressure(self):
        """n (S9) and P (S17) for fluid and wall particles; dummies only count in n."""
        n0, c2, rho, beta = self.coef.n0[None], self.coef.c2[None], self.coef.rho[None], \
            self.coef.beta[None]
        for i in range(self.state.n[None]):
            k = self.state.kind[i]
            if k == FLUID or k == WALL:
                acc = 0.0
                self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                             self._density_pair, acc)
                self.state.density[i] = acc
                self.state.pressure[i] = equation_of_state(acc, n0, c2, rho, beta)

    @ti.func
    def _pmin_pair(self, i, j, rij, r2, acc: ti.template()):
        if self.state.kind[j] != DUMMY:
            acc = ti.min(acc, self.state.pressure[j])

    @ti.func
    def _gradient_pair(self, i, j, rij, r2, acc: ti.template()):
        if self.state.kind[j] != DUMMY:
            acc += gradient_pair(self.state.pressure[j] - self.state.scratch_float[i], rij, r2,
                                 weight(ti.sqrt(r2), self.coef.re[None]))

    @ti.kernel
    def correct(self, dt: float):
        """a' = -(1/rho) <grad P> (S18); u += dt a' (S19); r += dt^2 a' (S20)."""
        for i in range(self.state.n[None]):       # the pressure each i subtracts: P_i, Pmin_i or -P_i
            if self.state.kind[i] == FLUID:
                p_ref = self.state.pressure[i]
                if ti.static(self.model.pressure_gradient == "pmin"):
                    self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                                 self._pmin_pair, p_ref)
                elif ti.static(self.model.pressure_gradient == "sum"):
                    p_ref = -p_ref
                self.state.scratch_float[i] = p_ref
        for i in range(self.state.n[None]):
            if self.state.kind[i] == FLUID:
                acc = ti.Vector.zero(float, self.dim)
                self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                             self._gradient_pair, acc)
                self.state.scratch_vec[i] = -self.dim / (self.coef.n0[None] * self.coef.rho[None]) * acc
        for i in range(self.state.n[None]):
            if self.state.kind[i] == FLUID:
                self.state.vel[i] += dt * self.state.scratch_vec[i]
                self.state.pos[i] += dt * dt * self.state.scratch_vec[i]


__all__ = ["Pressure", "equation_of_state"]
