"""The largest speed of a fluid particle relative to its neighbours (walls at rest), for the
velocity Courant limit (S5) in its relative form (``numerics.courant_speed: relative``), for
a model without viscosity and surface tension: with either, the predictor's walk measures it
at the start of each step (terms.py, same pairs), and this pass is not allocated.

Every force of the step depends on relative positions and velocities only (S9-S13, S22, the
collision model), so the configuration changes, per step, by dt times the relative speed of
neighbouring particles, not by dt times the absolute speed: a spray droplet flying at 3 U
changes nothing around it. The pairs are those of the pressure gradient: each fluid
particle's non-dummy neighbours within re, from the neighbour list of the density pass (the
cell walk where the list does not hold them all, or without a list). A particle within re of
the analytic plane floor's wall layer counts its own speed (the floor is at rest).

A particle that has no neighbour yet is bound by the approach limit instead (timestep.py):
|u| dt <= C_a l0 for every particle, so two particles closing head-on from beyond re end a
step at least re - 2 C_a l0 = 1.1 l0 apart (C_a = 0.5, re = 2.1 l0): a pair is in range, and
in the relative limit, before it can come closer than the lattice spacing.
"""

from typing import Optional

import taichi as ti

from .coefficients import Coefficients
from .grid import CellGrid
from .neighbours import NeighbourList
from .plane_floor import FLOOR_V, PlaneFloor
from .state import DUMMY, FLUID

BLOCK = 1024        # particles per block of the two-level reduction


@ti.data_oriented
class RelativeSpeed:
    def __init__(self, grid: CellGrid, coef: Coefficients,
                 neighbours: Optional[NeighbourList], floor: Optional[PlaneFloor]):
        self.grid, self.coef, self.state = grid, coef, grid.state
        self.neighbours, self.floor = neighbours, floor
        self.has_list, self.has_floor = neighbours is not None, floor is not None
        self.dim = self.state.dim
        self.block_max = ti.field(float, (self.state.capacity + BLOCK - 1) // BLOCK)
        self.result = ti.field(float, shape=())

    def nbytes(self) -> int:
        from .state import field_nbytes
        return field_nbytes(self.block_max)

    def measure(self) -> float:
        """max |u_j - u_i| over the neighbour pairs, in m/s (0 with no pair)."""
        self._reduce()
        return float(self.result[None]) ** 0.5

    @ti.func
    def _pair(self, i, j, rij, r2, acc: ti.template()):
        if self.state.kind[j] != DUMMY:
            du = self.state.vel[j] - self.state.vel[i]
            acc = ti.max(acc, du.dot(du))    # noqa: F841 (template: written through)

    @ti.kernel
    def _reduce(self):
        for at in range(self.state.n[None]):
            i = self.state.spread(at)
            if self.state.kind[i] == FLUID:
                u_i = self.state.vel[i]
                acc = 0.0
                walk = True
                if ti.static(self.has_list):
                    if self.neighbours.fits(i):
                        walk = False
                        for m in range(self.neighbours.count[i]):
                            du = self.state.vel[self.neighbours.index[i, m]] - u_i
                            acc = ti.max(acc, du.dot(du))
                if walk:
                    self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                                 self._pair, acc)
                if ti.static(self.has_floor):
                    if self.floor.at(self.state.pos[i][self.dim - 1])[FLOOR_V] > 0.0:
                        acc = ti.max(acc, u_i.dot(u_i))
                self.state.scratch_float[i] = acc
        fluid_max(self.state, self.state.scratch_float, self.block_max, self.result)


@ti.func
def fluid_max(state: ti.template(), values: ti.template(), blocks: ti.template(),
              out: ti.template()):
    """out[None] = the largest values[i] >= 0 over the fluid particles: per block of particles,
    then over the blocks (no contended atomics). Called at a kernel's top level."""
    n = state.n[None]
    for b in range((n + BLOCK - 1) // BLOCK):
        top = 0.0
        for i in range(b * BLOCK, ti.min(n, (b + 1) * BLOCK)):
            if state.kind[i] == FLUID:
                top = ti.max(top, values[i])
        blocks[b] = top
    for _ in range(1):
        top = 0.0
        for b in range((n + BLOCK - 1) // BLOCK):
            top = ti.max(top, blocks[b])
        out[None] = top


__all__ = ["RelativeSpeed", "fluid_max", "BLOCK"]
