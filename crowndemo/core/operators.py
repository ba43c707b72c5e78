"""MPS discrete operators (method.md §2): weight (S10), number density (S9), gradient (S11),
Laplacian (S12). The pair functions here are the only place these formulas are written; the
step's fused passes call them, and the stand-alone kernels below apply them to any field."""

from typing import Any, Callable

import taichi as ti

from .coefficients import Coefficients
from .grid import CellGrid
from .state import DUMMY, FLUID, GONE


@ti.func
def weight(r, re):
    """w(r) = re/r - 1 for r < re (S10); callers pass only pairs with r < re."""
    return re / r - 1.0


@ti.func
def gradient_pair(dphi, rij, r2, w):
    """One term of (S11) without the d/n0 factor: dphi / r^2 * rij * w."""
    return dphi / r2 * w * rij


@ti.func
def laplacian_pair(dphi, w):
    """One term of (S12) without the 2d/(lambda0 n0) factor."""
    return dphi * w


def make_density_task(coef: Coefficients) -> Callable[..., Any]:
    """The neighbour task of the number density (S9): acc += w(r_ij), every kind counted."""
    @ti.func
    def task(i, j, rij, r2, acc: ti.template()):
        acc += weight(ti.sqrt(r2), coef.re[None])
    return task


@ti.data_oriented
class Operators:
    """Stand-alone operators over all live particles (used by tests, diagnostics and n0 checks).

    The gradient and Laplacian sum over fluid and wall neighbours; dummies only count in the
    number density (method.md §5)."""

    def __init__(self, grid: CellGrid, coef: Coefficients):
        self.grid, self.coef, self.state = grid, coef, grid.state
        self.dim = grid.dim
        self._density_task = make_density_task(coef)

    @ti.kernel
    def number_density(self, out: ti.template()):
        """out_i = sum_j w(|r_ij|) (S9), all kinds counted."""
        for at in range(self.state.n[None]):
            i = self.state.spread(at)
            if self.state.kind[i] != GONE:
                acc = 0.0
                self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                             self._density_task, acc)
                out[i] = acc

    @ti.kernel
    def gradient(self, phi: ti.template(), out: ti.template()):
        """out_i = d/n0 sum_j (phi_j - phi_i)/r^2 r_ij w (S11), for fluid particles."""
        for at in range(self.state.n[None]):
            i = self.state.spread(at)
            if self.state.kind[i] == FLUID:
                acc = ti.Vector.zero(float, self.dim)
                self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                             ti.static(self._make_gradient_task(phi)), acc)
                out[i] = self.dim / self.coef.n0[None] * acc

    def _make_gradient_task(self, phi):
        re = self.coef.re
        kind = self.state.kind

        @ti.func
        def task(i, j, rij, r2, acc: ti.template()):
            if kind[j] != DUMMY:
                acc += gradient_pair(phi[j] - phi[i], rij, r2, weight(ti.sqrt(r2), re[None]))
        return task

    def _make_laplacian_task(self, phi):
        re = self.coef.re
        kind = self.state.kind

        @ti.func
        def task(i, j, rij, r2, acc: ti.template()):
            if kind[j] != DUMMY:
                acc += laplacian_pair(phi[j] - phi[i], weight(ti.sqrt(r2), re[None]))
        return task

    @ti.kernel
    def laplacian(self, phi: ti.template(), out: ti.template()):
        """out_i = 2d/(lambda0 n0) sum_j (phi_j - phi_i) w (S12), for fluid particles."""
        for at in range(self.state.n[None]):
            i = self.state.spread(at)
            if self.state.kind[i] == FLUID:
                acc = phi[i] * 0.0
                self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                             ti.static(self._make_laplacian_task(phi)), acc)
                out[i] = 2.0 * self.dim / (self.coef.lambda0[None] * self.coef.n0[None]) * acc
