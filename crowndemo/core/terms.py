"""Predictor (method.md §3 steps 1-2): viscosity, gravity and surface tension (S14-S16), then
the particle collision model on u* before the positions move.

The terms a scene does not use are not compiled in (``ti.static`` on the model's flags); if
neither viscosity, surface tension, collisions nor the relative Courant limit are on, the
predictor is a plain element-wise update with no neighbour walk.

The relative Courant limit (``numerics.courant_speed: relative``) takes its speed from the
predictor's walk, which reads every u_j - u_i at r^k before dt is chosen: the largest speed of
a fluid particle relative to its non-dummy neighbours within re, walls at rest (a particle
within re of the analytic plane floor's wall layer counts its own speed). Every force of the
step depends on relative positions and velocities only (S9-S13, S22, the collision model), so
the configuration changes, per step, by dt times that speed: a spray droplet flying at 3 U
changes nothing around it. A particle with no neighbour yet is bound by the approach limit
instead (timestep.py): |u| dt <= C_a l0, so two particles closing head-on from beyond re end a
step at least re - 2 C_a l0 = 1.1 l0 apart (C_a = 0.5, re = 2.1 l0), in range and in the
relative limit before they can come closer than the lattice spacing.

The predictor's pairs from the list (``numerics.predictor_list``, the default): a step's
density pass lists each fluid particle's neighbours within re at r* (S17, core/neighbours.py),
and the corrector then moves every particle by dt^2 a' (S20) to r^{k+1}. The next predictor
sums over that list at the new positions, keeping the pairs still within re, instead of
building the grid at r^{k+1} and walking the cells. It misses only the pairs that the
corrector's move brought within re: they lie within dt^2 |a'_i - a'_j| of re, where w
(S10) and the potential's force (S22) vanish, and closer than the collision distance
(0.5 l0) none can be. Dummy particles are listed for it: only the collision model uses them,
and without it fluid driven into a particle floor passes its wall layer (the booth 3m-drop
went unstable at 2.7 ms, a number-density excess of 0.52). After a
load and an output refresh (``Simulator.refresh_pressure``), and after a listing in which
some particle had more neighbours than slots, the step walks the cells as without the option;
a saved state carries the lists (``Simulator.save_state``), so a restored run takes the same
path. Measured: BENCHMARKS.md, "the predictor's pairs from the list".

Why collisions (measured on the ``quick`` crown, 4 mm drop at 8 m/s, l0 = 0.4 mm): particles on
the free surface have P = 0 (M3), so nothing repels two of them that approach; in the splash
pairs closed to 0.1-0.4 l0 before their number density passed beta n0. Then P jumped to
~3-5e5 Pa and the 1/r^2 of the gradient (S11) gave one-step accelerations of 4e6-3e7 m/s^2
(kicks to 30-130 m/s, or with equal pressures in the pmin form no repulsion at all and a
number-density excess of 1.8 as the pair passed through). The collision model of explicit MPS
codes (Koshizuka, Nobe & Oka 1998; Lee et al. 2011, CMAME 200: 1113) removes the approach
velocity of pairs closer than ``collision * l0`` before they collapse. A scene's floor
(``Scene.floor``) is a collision plane at its wall layer, z = -l0/2 (method.md §5): on the
particle floor a particle falling between wall particles, beyond the collision distance from
each, went through the layer (4 of the stability suite's 3D 15 m/s impact, parked at the plane
and counted); the plane takes what approach speed the wall pairs left, and it stops as above a
wall particle (none through since).
"""

from typing import Any, Callable, Optional

import taichi as ti

from .blocks import blocks_for, groups_for
from .coefficients import Coefficients
from .grid import CellGrid
from .neighbours import NeighbourList
from .health import fluid_max
from .operators import weight
from .params import Model
from .plane_floor import FLOOR_V, FLOOR_VN, PlaneFloor
from .state import DUMMY, FLUID, GONE
from .viscosity import member as viscosity_member

CLOSE_SLOTS = 4     # pairs closer than the collision distance listed per particle (rare: the
#                     lattice has none; a splash a few)


@ti.data_oriented
class Predictor:
    def __init__(self, model: Model, grid: CellGrid, coef: Coefficients,
                 floor: Optional[PlaneFloor] = None,
                 neighbours: Optional[NeighbourList] = None, surface: Optional[Any] = None):
        self.model, self.grid, self.coef, self.state = model, grid, coef, grid.state
        # the surface-tension member (core/surface_tension/); its pair term is summed in the
        # walk only when it has one (the curvature model acts through the pressure)
        self.surface = surface
        # the viscosity member (core/viscosity.py): its pair term, factor and floor term
        self.viscous = viscosity_member(model.viscosity_model)
        self.st_pairs = bool(model.surface_tension and surface is not None and surface.pair_term)
        # the density pass's list, for the pairs of ``forces(from_list=1)`` (module docstring)
        self.neighbours = neighbours if model.predictor_list and self._walks else None
        self.floor = floor          # the analytic plane floor when the model has one
        self.dim = model.dim
        self.pair_sums = ti.types.struct(visc=ti.types.vector(self.dim, float),
                                         st=ti.types.vector(self.dim, float), close=ti.i32,
                                         rel2=float)
        # the pairs closer than the collision distance, listed by the viscosity and surface
        # tension walk at the same positions, so the collision pass needs no walk of its own
        # (a particle with more than CLOSE_SLOTS walks the cells; not allocated without it)
        self.close_count = self.close_index = None
        if self.lists_close_pairs:
            self.close_count = ti.field(ti.i32, self.state.capacity)
            self.close_index = ti.field(ti.i32, (self.state.capacity, CLOSE_SLOTS))
        self.block_rel2 = self.group_rel2 = self.rel2 = None  # only with the relative Courant limit
        if self.measures_relative_speed:
            blocks = blocks_for(self.state.capacity)
            self.block_rel2 = ti.field(float, blocks)
            self.group_rel2 = ti.field(float, groups_for(blocks))
            self.rel2 = ti.field(float, shape=())

    @property
    def lists_close_pairs(self) -> bool:
        return self.model.collision and self._walks

    @property
    def measures_relative_speed(self) -> bool:
        """The speed of the relative Courant limit measured by the walk (module docstring)."""
        return self.model.relative_courant

    def relative_speed(self) -> float:
        """max |u_j - u_i| over the pairs of the last ``forces`` (m/s; walls at rest)."""
        return float(self.rel2[None]) ** 0.5

    def nbytes(self) -> int:
        from .state import field_nbytes
        fields = []
        if self.lists_close_pairs:
            fields += [self.close_count, self.close_index]
        if self.measures_relative_speed:
            fields += [self.block_rel2, self.group_rel2, self.rel2]
        return sum(field_nbytes(f) for f in fields)

    @property
    def needs_neighbours(self) -> bool:
        return self._walks or self.model.collision

    @property
    def _walks(self) -> bool:
        """``forces`` walks the neighbours: for viscosity, surface tension or the relative
        speed (the collision pass walks on its own where nothing else does)."""
        return self.model.viscosity or self.st_pairs or self.model.relative_courant

    @ti.func
    def _collision_pair(self, i, j, rij, r2, acc: ti.template()):
        """Inelastic collision of an approaching pair closer than the collision distance:
        the normal relative velocity vn = (u_j - u_i).rij/r < 0 becomes -e vn. i's share is
        m_j/(m_i + m_j) of the change: 1/2 against a fluid particle (the pair's momentum is
        conserved), all of it against a wall or dummy particle (immovable, u = 0)."""
        u_j = ti.Vector.zero(float, self.dim)     # the walk passes r2 < col_r2 only
        share = 1.0
        if self.state.kind[j] == FLUID:
            u_j = self.state.vel[j]
            share = 0.5
        r = ti.sqrt(r2)
        vn = (u_j - self.state.vel[i]).dot(rij) / r
        if vn < 0.0:
            acc += share * (1.0 + self.coef.col_e[None]) * vn / r * rij

    @ti.func
    def _pair(self, i, j, rij, r2, acc: ti.template()):
        """Sums, without their constant factors: the viscosity member's pair term (S12's
        (u_j - u_i) w, or V1's; walls have u = 0, no-slip) and the surface-tension member's
        pair term over fluid j (the potential's (r - l0)(r - re) r_ij / r, S24)."""
        if ti.static(self.lists_close_pairs):
            if r2 < self.coef.col_r2[None]:      # every kind, as the collision walk
                if acc.close < CLOSE_SLOTS:
                    self.close_index[i, acc.close] = j
                acc.close += 1
        kind_j = self.state.kind[j]
        if kind_j != DUMMY:
            r = ti.sqrt(r2)
            du = self.state.vel[j] - self.state.vel[i]
            if ti.static(self.measures_relative_speed):
                acc.rel2 = ti.max(acc.rel2, du.dot(du))
            if ti.static(self.model.viscosity):
                acc.visc += self.viscous.pair(du, rij, r2, weight(r, self.coef.re[None]))
            if ti.static(self.st_pairs):
                if kind_j == FLUID:      # fluid-fluid (the potential's sign per method.md §4)
                    acc.st += self.surface.pair(rij, r)

    def run(self, dt: float, mark: Callable[[str], None] = lambda stage: None,
            sync: Optional[Callable[[], None]] = None, from_list: bool = False) -> None:
        """u* = u + dt a* (S15), a* from ``forces`` (which must have run at these positions),
        the collision model on u* at r^k, r* = r + dt u* (S16). ``mark(stage)`` is called as
        the "predictor" and "collision" stages end (the simulator's stage timer); ``sync()``
        right after u*, before the collision pass reads the neighbours' u* (symmetry.py).
        ``from_list``: as given to ``forces`` (a crowded particle's collision pairs from the
        list, not the cells)."""
        self.accelerate(dt)
        if sync is not None and self.model.collision:
            sync()
        mark("predictor")
        if self.model.collision:
            self.collide(from_list)
            mark("collision")
        self.move(dt)

    @property
    def takes_list(self) -> bool:
        """``forces`` and ``collide`` can take their pairs from the density pass's list."""
        return self.neighbours is not None

    @ti.func
    def _listed(self, i, xi, r2_max, task: ti.template(), acc: ti.template()):
        """``task`` for the listed neighbours j of i (the density pass's list, module
        docstring) with 0 < r2 = |x_j - x_i|^2 < r2_max at the current positions; a j that
        has left the domain since is skipped."""
        for m in range(self.neighbours.count[i]):
            j = self.neighbours.index[i, m]
            rij = self.state.pos[j] - xi
            r2 = rij.dot(rij)
            if r2 < r2_max and r2 > 0.0 and self.state.kind[j] != GONE:
                task(i, j, rij, r2, acc)

    def forces(self, from_list: bool = False) -> None:
        """``_forces``: the predictor's accelerations at r^k (the cell walk's pairs, or with
        ``from_list`` the density pass's list's, module docstring)."""
        self._forces(int(from_list))

    def collide(self, from_list: bool = False) -> None:
        """``_collide``: the collision model on u* at r^k."""
        self._collide(int(from_list))

    @ti.kernel
    def _forces(self, from_list: ti.i32):
        """a* = nu <lap u> (the viscosity member's, S12 or V1) + g + (C/m) sum of minus the
        potential's gradient (S14, S22) at r^k, into scratch_vec (no work without a walk:
        ``accelerate`` adds g alone); the pairs from the cell walk, or with ``from_list``
        from the density pass's list (module docstring). With the relative Courant limit,
        the largest |u_j - u_i| of the pairs: per particle into scratch_float, then reduced
        per block and over the blocks."""
        if ti.static(self._walks):
            visc = self.coef.nu[None] * ti.static(self.viscous.factor(self.dim)) / (
                self.coef.lambda0[None] * self.coef.n0[None])
            for at in range(self.state.n[None]):
                i = self.state.spread(at)
                if self.state.kind[i] == FLUID:
                    acc = self.pair_sums(visc=ti.Vector.zero(float, self.dim),
                                         st=ti.Vector.zero(float, self.dim), close=0, rel2=0.0)
                    listed = False
                    if ti.static(self.takes_list):
                        if from_list:
                            self._listed(i, self.state.pos[i], self.coef.re2[None],
                                         self._pair, acc)
                            listed = True
                    if not listed:
                        self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                                     self._pair, acc)
                    if ti.static(self.lists_close_pairs):
                        self.close_count[i] = acc.close
                    if ti.static(self.model.plane_floor):
                        # the floor's wall layer, u_j = 0 (S12 / V1 summed in plane_floor.py)
                        floor_sums = self.floor.at(self.state.pos[i][self.dim - 1])
                        v_floor = floor_sums[FLOOR_V]
                        if ti.static(self.model.viscosity):
                            acc.visc += self.viscous.floor(self.state.vel[i], v_floor,
                                                           floor_sums[FLOOR_VN])
                        if ti.static(self.measures_relative_speed):
                            if v_floor > 0.0:
                                acc.rel2 = ti.max(acc.rel2, self.state.vel[i].dot(
                                    self.state.vel[i]))
                    if ti.static(self.measures_relative_speed):
                        self.state.scratch_float[i] = acc.rel2
                    a = ti.Vector.zero(float, self.dim)
                    if ti.static(self.model.viscosity):
                        a += visc * acc.visc
                    if ti.static(self.st_pairs):
                        a += self.surface.finish(acc.st)
                    if ti.static(self.model.gravity):
                        a += self.coef.gravity[None]
                    self.state.scratch_vec[i] = a
            if ti.static(self.measures_relative_speed):
                fluid_max(self.state, self.state.scratch_float, self.block_rel2, self.group_rel2,
                          self.rel2)

    @ti.kernel
    def accelerate(self, dt: float):
        """u* = u + dt a* (S15), a* from ``forces``; g alone where it did not walk."""
        if ti.static(self._walks):
            for at in range(self.state.n[None]):
                i = self.state.spread(at)
                if self.state.kind[i] == FLUID:
                    self.state.vel[i] = self.state.vel[i] + dt * self.state.scratch_vec[i]
        elif ti.static(self.model.gravity):
            for at in range(self.state.n[None]):
                i = self.state.spread(at)
                if self.state.kind[i] == FLUID:
                    self.state.vel[i] += dt * self.coef.gravity[None]

    @ti.kernel
    def _collide(self, from_list: ti.i32):
        """The collision model on u* at r^k; Jacobi: every pair sees the u* of both before
        either changes. A particle with more close pairs than CLOSE_SLOTS walks the cells,
        or with ``from_list`` its list (the grid is not at r^k then)."""
        for at in range(self.state.n[None]):
            i = self.state.spread(at)
            if self.state.kind[i] == FLUID:
                du = ti.Vector.zero(float, self.dim)
                xi = self.state.pos[i]
                walk = True
                if ti.static(self.lists_close_pairs):
                    if self.close_count[i] <= CLOSE_SLOTS:   # the list holds them all
                        walk = False
                        for m in range(self.close_count[i]):
                            j = self.close_index[i, m]
                            rij = self.state.pos[j] - xi
                            self._collision_pair(i, j, rij, rij.dot(rij), du)
                if ti.static(self.takes_list):
                    if walk and from_list:
                        self._listed(i, xi, self.coef.col_r2[None], self._collision_pair, du)
                        walk = False
                if walk:
                    self.grid.for_each_near(i, xi, self.coef.col_r2[None],
                                            self._collision_pair, du)
                gap = self.state.pos[i][self.dim - 1]
                vn = self.state.vel[i][self.dim - 1]
                if ti.static(self.model.plane_floor):
                    # against the floor's wall layer (the plane s = -l0/2), as against a wall
                    # particle right below: the whole approach speed changes
                    gap += self.floor.wall_depth[None]
                else:
                    # against the particle floor's wall-layer plane (z = -l0/2; none without
                    # a floor): what approach speed its wall particles' pairs left, so one
                    # falling between them stops as one right above a wall particle does
                    gap -= self.coef.floor_z[None]
                    vn += du[self.dim - 1]
                if gap < ti.sqrt(self.coef.col_r2[None]) and vn < 0.0:
                    du[self.dim - 1] -= (1.0 + self.coef.col_e[None]) * vn
                self.state.scratch_vec[i] = self.state.vel[i] + du
        for at in range(self.state.n[None]):
            i = self.state.spread(at)
            if self.state.kind[i] == FLUID:
                self.state.vel[i] = self.state.scratch_vec[i]

    @ti.kernel
    def move(self, dt: float):
        """r* = r + dt u* (S16)."""
        for at in range(self.state.n[None]):
            i = self.state.spread(at)
            if self.state.kind[i] == FLUID:
                self.state.pos[i] += dt * self.state.vel[i]
