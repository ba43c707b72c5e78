"""Pressure (method.md §3 steps 3-5): number density at r*, the equation of state (S17, M3)
and the pressure-gradient corrector (S18-S20) in one of four forms (M2, M2c):

- ``seed``: (P_j - P_i), the gradient model (S11) as printed in the seed;
- ``pmin``: (P_j - Pmin_i), Pmin_i the least pressure among i and its neighbours (repulsive);
- ``sum``:  (P_j + P_i), the momentum-conserving form of explicit MPS papers;
- ``corrected``: (P_i L_i + P_j L_j), the sum form with each particle's pressure taken through
  its fabric's corrective matrix L_i = (tr M_i / d) M_i^-1, M_i = sum_j w r_ij r_ij^T / r^2
  (M2c, method.md): still antisymmetric in i, j, and its pair forces do no work on any
  uniform shear and exert no torque, so a pressure, a background one included, acts on
  volume change alone (a particle set's fabric anisotropy is no shear stress).
"""

from typing import Any, Optional

import taichi as ti

from .coefficients import Coefficients
from .grid import CellGrid
from .neighbours import NeighbourList
from .operators import gradient_pair, make_density_task, weight
from .params import FABRIC_DET_MIN, Model
from .plane_floor import FLOOR_G, FLOOR_N, PlaneFloor
from .state import DUMMY, FLUID, WALL



@ti.func
def equation_of_state(n, n0, c2, rho, beta):
    """P = c^2 rho (n - n0)/n0 (S17), clamped at 0, and 0 on the free surface n < beta n0 (M3).
    With beta < 1 the free-surface rule changes nothing (n < beta n0 < n0 is clamped to 0
    already); it is kept as the seed's method states it."""
    p = 0.0
    if n >= beta * n0:
        p = ti.max(c2 * rho * (n - n0) / n0, 0.0)
    return p


@ti.func
def surface_weight(n, n0, beta):
    """omega = clamp((1 - n/n0) / (2 (1 - beta)), 0, 1) (C1, method.md §4c): 1 on the free
    surface's outer layer, 1/2 at the free-surface threshold beta n0 (M3), 0 at n >= n0; the
    stress member's colour gradient and M2c's corrective matrix fade in and out with it."""
    return ti.min(ti.max((1.0 - n / n0) / (2.0 * (1.0 - beta)), 0.0), 1.0)


def _gradient_sums(dim: int):
    return ti.types.struct(pg=ti.types.vector(dim, float), g=ti.types.vector(dim, float),
                           pmin=float)


def _density_sums():
    return ti.types.struct(n=float, count=ti.i32)


@ti.data_oriented
class Pressure:
    def __init__(self, model: Model, grid: CellGrid, coef: Coefficients,
                 floor: Optional[PlaneFloor] = None, surface: Optional[Any] = None):
        self.model, self.grid, self.coef, self.state = model, grid, coef, grid.state
        self.floor = floor          # the analytic plane floor when the model has one
        # the surface-tension member, whose boundary_pressure follows S17 (a no-op for the
        # potential, P = sigma kappa on the surface for the curvature model)
        self.surface = surface
        self.dim = model.dim
        self.sums = _gradient_sums(self.dim)
        self.density_sums = _density_sums()
        self._density_pair = make_density_task(coef)
        # not allocated when the model does without (a scene pays for what it uses)
        self.neighbours = NeighbourList(self.state) if model.neighbour_list else None
        # M2c's corrective matrices, one per particle (I for walls), refreshed each step; not
        # with the plane floor or symmetry planes (Numerics.validate refuses those)
        self.corrected = model.pressure_gradient == "corrected"
        if self.corrected:
            self.fabric = ti.Matrix.field(self.dim, self.dim, float, self.state.capacity)

    def nbytes(self) -> int:
        from .state import field_nbytes
        own = field_nbytes(self.fabric) if self.corrected else 0
        return own + (self.neighbours.nbytes() if self.neighbours is not None else 0)

    @property
    def _surface_in_corrector(self) -> bool:
        """The surface-tension member adds an acceleration at r* to the corrector's."""
        return self.surface is not None and getattr(self.surface, "corrector_term", False)

    @ti.func
    def _density_listing_pair(self, i, j, rij, r2, acc: ti.template()):
        """The number density's term (S9), and j in i's list unless it is a dummy (the
        pressure gradient skips dummies, method.md §5). With the predictor's pairs from the
        list (terms.py) dummies are listed too: the collision model keeps fluid particles off
        them, and the corrector skips them."""
        acc.n += weight(ti.sqrt(r2), self.coef.re[None])
        listed = True
        if ti.static(not self.model.predictor_list):
            listed = self.state.kind[j] != DUMMY
        if listed:
            acc.count = self.neighbours.add(i, j, acc.count)

    @ti.func
    def _floor_density(self, z) -> float:
        return self.floor.at(z)[FLOOR_N]

    def density_and_pressure(self, dt: float = 0.0) -> None:
        """n (S9) and P (S17, M3), then the surface-tension member's boundary pressure; ``dt``
        the step's (what a member carries from step to step advances by it; 0 for output)."""
        self._density_and_pressure()
        if self.corrected:
            self._corrective_matrices()
        if self.surface is not None:
            self.surface.boundary_pressure(dt)

    @ti.kernel
    def _density_and_pressure(self):
        """n (S9) and P (S17) for fluid and wall particles; dummies only count in n. With the
        neighbour list, each fluid particle's neighbours are listed on the way (dummies only
        for the predictor's pairs from the list)."""
        n0, c2, rho, beta = self.coef.n0[None], self.coef.c2[None], self.coef.rho[None], \
            self.coef.beta[None]
        if ti.static(self.model.neighbour_list):
            self.neighbours.overflow[None] = 0
        for at in range(self.state.n[None]):
            i = self.state.spread(at)
            k = self.state.kind[i]
            if k == FLUID or k == WALL:
                n = 0.0
                if ti.static(self.model.neighbour_list):
                    if k == FLUID:
                        acc = self.density_sums(n=0.0, count=0)
                        self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                                     self._density_listing_pair, acc)
                        self.neighbours.count[i] = acc.count
                        if acc.count > ti.static(self.neighbours.slots):
                            self.neighbours.overflow[None] = 1     # the same value from all
                        n = acc.n
                    else:
                        self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                                     self._density_pair, n)
                else:
                    self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                                 self._density_pair, n)
                if ti.static(self.model.plane_floor):
                    # the floor's wall and dummy layers (plane_floor.py), for fluid particles
                    n += ti.select(k == FLUID,
                                   self._floor_density(self.state.pos[i][self.dim - 1]), 0.0)
                self.state.density[i] = n
                self.state.pressure[i] = equation_of_state(n, n0, c2, rho, beta)

    @ti.func
    def _fabric_pair(self, i, j, rij, r2, acc: ti.template()):
        """M_i's term w r_ij r_ij^T / r^2 over the gradient's neighbours (dummies skipped)."""
        if self.state.kind[j] != DUMMY:
            acc += (weight(ti.sqrt(r2), self.coef.re[None]) / r2) * rij.outer_product(rij)

    @ti.kernel
    def _corrective_matrices(self):
        """M2c: L_i = (tr M_i / d) M_i^-1 (I on a lattice), taken to I on the free surface as
        C1's omega_i = clamp((1 - n_i/n0) / (2 (1 - beta)), 0, 1) rises: L_i = omega_i I +
        (1 - omega_i) (tr M_i / d) M_i^-1, a polynomial in M_i, so M_i L_i stays symmetric and
        the pairs exert no torque; the free surface's push (C4's balance) is the sum form's."""
        n0, beta = self.coef.n0[None], self.coef.beta[None]
        for at in range(self.state.n[None]):
            i = self.state.spread(at)
            correction = ti.Matrix.identity(float, self.dim)
            if self.state.kind[i] == FLUID:
                m = ti.Matrix.zero(float, self.dim, self.dim)
                self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                             self._fabric_pair, m)
                iso = m.trace() / self.dim
                omega = surface_weight(self.state.density[i], n0, beta)
                if omega < 1.0 and iso > 0.0:
                    if m.determinant() > FABRIC_DET_MIN * iso ** self.dim:
                        correction = omega * correction + (1.0 - omega) * iso * m.inverse()
            self.fabric[i] = correction

    @ti.func
    def _gradient_pair(self, i, j, rij, r2, acc: ti.template()):
        """Accumulates, in one walk, sum P_j g_ij, sum g_ij (g_ij = r_ij w / r^2) and the least
        neighbour pressure, so every form of (M2) needs a single neighbour pass:
        sum (P_j - P_ref) g_ij = sum P_j g_ij - P_ref sum g_ij."""
        if self.state.kind[j] != DUMMY:
            self._gradient_term(j, rij, r2, acc)

    @ti.func
    def _gradient_term(self, j, rij, r2, acc: ti.template()):
        p_j = self.state.pressure[j]
        g = gradient_pair(1.0, rij, r2, weight(ti.sqrt(r2), self.coef.re[None]))
        if ti.static(self.corrected):
            acc.pg += p_j * (self.fabric[j] @ g)         # M2c: P_j L_j g_ij
        else:
            acc.pg += p_j * g
        acc.g += g
        if ti.static(self.model.pressure_gradient == "pmin"):
            acc.pmin = ti.min(acc.pmin, p_j)

    @ti.kernel
    def correct(self, dt: float):
        """a' = -(1/rho) <grad P> (S18), plus the surface stress's divergence (C3) with that
        member; u += dt a' (S19); r += dt^2 a' (S20).
        P_ref, the pressure each i subtracts: P_i (seed), Pmin_i (pmin) or -P_i (sum); the
        corrected form adds P_i L_i sum_j g_ij to sum_j P_j L_j g_ij (M2c).
        The neighbours come from the list of ``density_and_pressure`` (same positions) where
        it holds them all, else from the cell walk."""
        for at in range(self.state.n[None]):
            i = self.state.spread(at)
            if self.state.kind[i] == FLUID:
                p_i = self.state.pressure[i]
                xi = self.state.pos[i]
                acc = self.sums(pg=ti.Vector.zero(float, self.dim),
                                g=ti.Vector.zero(float, self.dim), pmin=p_i)
                walk = True
                if ti.static(self.model.neighbour_list):
                    if self.neighbours.fits(i):
                        walk = False
                        for m in range(self.neighbours.count[i]):
                            j = self.neighbours.index[i, m]
                            rij = self.state.pos[j] - xi
                            used = True
                            if ti.static(self.model.predictor_list):   # dummies listed
                                used = self.state.kind[j] != DUMMY
                            if used:
                                self._gradient_term(j, rij, rij.dot(rij), acc)
                if walk:
                    self.grid.for_each_neighbour(i, xi, self.coef.re2[None],
                                                 self._gradient_pair, acc)
                if ti.static(self.model.plane_floor):
                    # the floor's wall layer (S11 summed in plane_floor.py) at the pressure of a
                    # hydrostatic mirror: P_i + rho g (depth of the layer below i)
                    z = xi[self.dim - 1]
                    g = ti.Vector.zero(float, self.dim)
                    g[self.dim - 1] = self.floor.at(z)[FLOOR_G]
                    p_wall = p_i
                    if ti.static(self.model.gravity):
                        p_wall -= self.coef.rho[None] * self.coef.gravity[None][self.dim - 1] * (
                            z + self.floor.wall_depth[None])
                    acc.pg += p_wall * g
                    acc.g += g
                p_ref = p_i
                if ti.static(self.model.pressure_gradient == "pmin"):
                    p_ref = acc.pmin
                elif ti.static(self.model.pressure_gradient == "sum"):
                    p_ref = -p_i
                own = -p_ref * acc.g          # i's own pressure over sum_j g_ij
                if ti.static(self.corrected):
                    own = p_i * (self.fabric[i] @ acc.g)      # M2c: P_i L_i sum_j g_ij
                grad = self.dim / self.coef.n0[None] * (acc.pg + own)
                a = -grad / self.coef.rho[None]
                if ti.static(self._surface_in_corrector):
                    a += self.surface.acceleration(i)      # the surface stress (C3) at r*
                self.state.scratch_vec[i] = a
        for at in range(self.state.n[None]):
            i = self.state.spread(at)
            if self.state.kind[i] == FLUID:
                self.state.vel[i] += dt * self.state.scratch_vec[i]
                self.state.pos[i] += dt * dt * self.state.scratch_vec[i]


__all__ = ["Pressure", "equation_of_state", "surface_weight"]
