"""Continuum surface stress (CSS): surface tension as the divergence of the capillary stress
tensor (Lafaurie et al., J. Comput. Phys. 113, 1994; in SPH Hu & Adams, J. Comput. Phys. 213,
2006), method.md §4c:

    T = sigma (|g| I - g g^T / |g|),   a_st = (1/rho) div T                           (C2)

with g the gradient of the liquid's colour (1 in the liquid, 0 outside). T is a tension along
the surface layer with no normal component: on a flat surface its divergence vanishes, on a
curved one it sums to sigma kappa n over the layer, the Young-Laplace jump, with no curvature
needed (in 3D, C5 below corrects the tension by one). Two neighbour passes at r*, after the
number density (S17), the free surface's pressure and, in 3D, a curvature correction:

1. the colour gradient (C1), g_i = omega_i K sum_j r_ij f(r_ij) over every neighbour kind,
   f(r) = (1 - r/re)^3 (a Wendland C2 kernel's gradient: bounded where the MPS w/r^2 is not;
   with w/r^2 a closing pair's g grew as 1/r^2 and pulled the pair together), K = d / sum_j
   r^2 f on the lattice. The missing neighbours of a surface particle make it point into the
   liquid; the plane floor's wall and dummy layers add their share, so a wall is no surface.
   omega_i = clamp((1 - n_i/n0) / (2 (1 - beta)), 0, 1) keeps it to the free surface (n <
   n0): inside a disordered liquid g is not zero, and without omega that noise made an
   isotropic tension that raised a resting drop's pressure to 1.8 sigma/R at R/l0 = 16;
   then T_i = sigma a (|g_i| I - g_i g_i^T / |g_i|), a the lattice normaliser that makes a
   flat lattice surface carry exactly sigma (lattice.stress_normaliser);
2. the divergence in the sum form (C3),
   a_i = (K_d / rho) sum_j (T_i + T_j) r_ij f_d(r_ij),  f_d(r) = (1 - (r/H)^4)^2, H = 3 l0,
   T_j = 0 for wall and dummy particles, K_d = d / sum_j r^2 f_d (each T times C5's s). Each
   pair's terms are equal and opposite (for a fluid j), so the model conserves momentum
   exactly: a free drop cannot drift by its own surface tension. f_d is zero with zero slope
   at H, beyond the lattice's pairs at 2 l0, so the tension a surface carries hardly depends
   on how closely its outer layer sits (within 5 % over 0.95-1.15 l0; the first member's
   1 - (r/re)^4, support re,
   had its edge at the lattice's 2 l0 pairs and carried 1.40 sigma when the layer packed to
   0.85 l0, 0.75 sigma stretched to 1.05 l0: VALIDATION.md, "The pair kernel's edge"). This
   pass walks to H beyond re (the grid's wide walk, grid.py). The pair force r f_d(r) grows
   with r up to 0.58 H = 1.74 l0, so the tension along the surface pulls two surface particles
   less as they close; with a pair weight that peaks closer in (f, w/r^2, or this one with H =
   re: 1.21 l0) the surface layer clumped. Below l0, where no lattice pair lies (the
   normalisations do not see it), f_d is multiplied by (r/l0 - 0.75)/0.25, so the tension
   turns into a repulsion for pairs closer than 0.75 l0: without the core two surface
   particles pulled together met no pressure until n > n0, then a third one's arrival kicked
   one out of a resting drop at 0.2-0.4 m/s. The idea is the repulsive core of the seed's
   potential (S22, r < l0) and Monaghan's (2000) cure for the tensile instability;
2b. with ``numerics.stress_pairs: surface`` (C3b), each pair's term times the mean of its
   particles' band weights, w_ij = (omega_i + omega_j)/2, omega = clamp((1 - n/n0)/B, 0, 1),
   B = params.STRESS_SURFACE_BAND = 0.25 (0 for walls and dummies): (s_i T_i + s_j T_j) r_ij
   w_ij f_d, a times the flat lattice face's ratio of its plain cut sum to its weighted one
   (lattice.surface_pairs_ratio: 1.32 / 1.29 in 2D / 3D) and the factor measured on drops
   with the corrected gradient form (params.STRESS_NEIGHBOURHOODS' "surface_pairs"; C5 off).
   A flat face weighs 1, the layer under it 0.03 / 0.014, so the pull lands on the surface
   layer (with C3 a quarter of it lands a spacing under it, where it reads the inside
   pressure high and restores a mode weakly); with C1's narrower band 2 (1 - beta) a particle
   a spacing in turned half a surface particle as soon as its n fell 2-3 % under n0, the
   surface layer emptied and the inside pressure swung by a sawtooth (VALIDATION.md, "The
   mean weight's unsteady pressure", "C3's surface pairs"). The pair's weight is its own, so
   the pairs stay antisymmetric; but the weighted pairs see mostly the surface layer, a
   fabric far from isotropic, and on a rough surface T_i M_i (M_i = sum_j w_ij f_d r_ij
   r_ij^T) is not symmetric: the pairs exert a torque, which turned a free 2D drop by 0.06 /
   0.14 rad in 10 periods at R/l0 = 8 (sum / corrected form) and 0.057 at 16 (corrected). In
   2D (the neighbourhood's "torque_free") each T_i goes through L_i = M_i^-1 (d - 1) /
   tr_t(M_i^-1), tr_t the trace in T_i's tangent plane (M_i summed in pass 1, which then
   walks to H where omega_i > 0; I where M_i is degenerate), so that T_i L_i M_i is symmetric
   (the idea of M2c and of Bonet & Lok's 1999 corrected gradient) and L_i's mean gain along
   the surface is 1: the pairs exert no torque and the free drops hold still. Not in 3D,
   whose free drop held still without it: there with it the stress fed the mode, which
   decayed at 0.65 of the viscous rate, 5 % slow (the class attribute ``torque_free`` sets
   either for a study);
3. the free surface's pressure (C4): a fluid particle that S17/M3 left at P = 0 and that has a
   colour gradient takes the normal stress its own tension carries,
   P_i = F rho l0 max(0, a_i . g_i/|g_i|),
   the force a_i pulls it in with, over the area l0^(d-1) it holds. With P = 0 on the surface
   only the liquid a spacing inside carried the inside pressure (60-83 % of a 3D drop's volume
   at R/l0 = 8-16, the virial, VALIDATION.md), and the first member's 3D drops read 42-59 %
   high; with C4 the surface layer carries it. F is the flat lattice face's balance: the sum
   form's push of a uniform pressure on a face particle, 2 P G/n0 d, equals its own pull at
   F = n0/(2 d G) (lattice.face_balance_factor): 1.016 (2D) / 1.011 (3D) at 2.1 l0, where the
   member takes 1; 1.160 / 1.187 at 3.1 l0. It needs no pass: a_i is pass 2's;
4. the curvature correction (C5): particle i's tension T_i is taken s_i = clamp(1 - delta l0
   H_i, 1/2, 3/2) times, H_i the mean curvature from the tangential divergence of the unit
   normals n = g/|g| over its neighbours within re, H_i = -sum_j n_j . r_t f / sum_j |r_t|^2 f
   (r_t: r_ij's part in i's tangent plane, so n_j . r_t = (n_j - n_i) . r_t; for radial normals
   the neighbours' 1/r, 1/r on a sphere or circle of radius r; the whole (n_j - n_i) . r_ij,
   the form to 2026-12-06, added the normals' second-order turn along the depth and read a
   rough surface's scatter as curvature, VALIDATION.md). In a 3D
   drop the pull lands about a spacing inside the liquid's surface and the inside pressure
   read 2 sigma/(R - 0.9 l0) (+17 / +8 / +5 % at R/l0 = 8 / 12 / 16), and the mode-2
   frequency as high: a surface of tension delta inside the liquid's, as Tolman's (1949) for a
   real liquid, sigma (1 - delta H) moving it back out. delta (l0): 0.80 in 3D, where the
   resting drop's error falls with resolution (+4.1 / +0.5 / -0.2 % at R/l0 = 8 / 12 / 16;
   the error without C5 times 1 - delta/(R/l0 - 0.6); 0.92, which cancelled the +8.27 % at
   12 alone, over-corrected at 16); in 2D 0 at 2.1 l0 (compiled out), whose drops read
   +4 / +2 / 0 % without it, and 0.9 at 3.1 l0. H_i is summed in pass 2's walk and used in
   the next step's pass 2 (a carried field, so no third pass); the pairs stay antisymmetric,
   as (s_i T_i + s_j T_j) r_ij f_d. s_i follows its step's value through a first-order lag
   of TOLMAN_LAG = 3.5 capillary times sqrt(rho / (sigma |H|^3)) (about 1.6 periods of mode 2
   of a drop of radius 1/|H|): a tension that followed the mode's own bending pulled the
   surface toward its stiffer parts (a Marangoni stress) and damped a 3D drop's oscillation
   1.4-1.5 times as fast as Lamb's rate at re = 3.1 l0; lagged, C5 corrects the surface of
   tension's static offset alone (VALIDATION.md, "C5's own damping", "C5 lagged in the
   surface's capillary time").

F, delta and C3's pair support H are the neighbourhood's (params.STRESS_NEIGHBOURHOODS: re =
2.1 l0, the seed's, H = 3 l0, or 3.1 l0, H = 4.1 l0 in 3D, where the 3D drops' errors fall with
resolution and their decay is 1.0-1.16 times Lamb's rate; another re is refused, its
constants unmeasured). The acceleration is applied in the corrector with the pressure gradient
(S18-S20), at r*.
``_pair_weight`` and ``_surface_pressure`` are the member's two choices (C3's f_d, C4), each a
method, so a study (tools/stress_surface_study.py) can swap one without restating a pass.
Only fluid particles carry tension; with symmetry planes, images carry their sources' mirrored
g (``_sync_images``).
"""
import taichi as ti

from ..coefficients import Coefficients
from ..grid import CellGrid
from .. import params
from ..lattice import stress_constants, stress_pairs_scale
from ..params import FABRIC_DET_MIN, Model
from ..pressure import surface_weight
from ..state import FLUID, GONE, field_nbytes

CORE = 0.75     # f_d changes sign at CORE l0 (C3): closer surface pairs repel (module docstring)
TOLMAN_CLAMP = (0.5, 1.5)    # s_i's range (C5): a lone or spray particle's H is no curvature
TOLMAN_LAG = params.STRESS_TOLMAN_LAG     # C5's lag in capillary times (params.py)
# C5's normals: of particles with |g| l0 above this (a flat lattice face's outer layer: 0.50,
# the next 3e-5); below it omega ~ 0 and g can be float rounding, its direction noise
NORMAL_MIN = 0.1
UNSET = 0.0     # a carried s_i (C5) before its particle's first step: outside TOLMAN_CLAMP


@ti.func
def stress_kernel(r, re):
    """f(r) = (1 - r/re)^3 (C1; lattice.stress_kernel): bounded, zero at re."""
    q = 1.0 - r / re
    return q * q * q


@ti.func
def stress_pair_kernel(r, h, l0):
    """f_d(r) = (1 - (r/h)^4)^2 for r < h (C3; lattice.stress_pair_kernel), times (r/l0 -
    CORE)/(1 - CORE) below l0 (the core: no lattice pair lies there)."""
    q = ti.min(r / h, 1.0)
    f = 1.0 - q * q * q * q
    f *= f
    if r < l0:
        f *= (r / l0 - CORE) / (1.0 - CORE)
    return f


@ti.func
def band_weight(n, n0):
    """C3b's omega = clamp((1 - n/n0) / B, 0, 1), B = params.STRESS_SURFACE_BAND
    (lattice.surface_band_weight)."""
    return ti.min(ti.max((1.0 - n / n0) / params.STRESS_SURFACE_BAND, 0.0), 1.0)


@ti.func
def stress_times(g, r):
    """(|g| I - g g^T/|g|) r without forming the tensor; 0 where g = 0."""
    out = ti.Vector.zero(float, r.n)
    gl = g.norm()
    if gl > 0.0:
        out = gl * r - g * (g.dot(r) / gl)
    return out


@ti.func
def normal_divergence_terms(ni, nj, rij, w):
    """A pair's share of C5's curvature sums: [n_j . r_t w, |r_t|^2 w], r_t r_ij's part in i's
    tangent plane (unit normals n_i, n_j); H_i = -(first sum)/(second sum). n_j . r_t is the
    normals' change (n_j - n_i) along r_t: the whole (n_j - n_i) . r_ij would add (1 - n_i . n_j)
    r_ij . n_i, the normals' turn to second order along the depth, which on a rough surface's
    scattered normals reads as curvature (module docstring, C5)."""
    rt = rij - rij.dot(ni) * ni
    return ti.Vector([nj.dot(rt) * w, rt.dot(rt) * w])     # (n_j - n_i) . r_t = n_j . r_t


@ti.func
def tolman_factor(sums, delta_l0):
    """C5's s_i = clamp(1 - delta l0 H_i, TOLMAN_CLAMP) from the summed ``sums``
    (normal_divergence_terms), H_i = -sums[0]/sums[1]; 1 where i has no such neighbours."""
    s = 1.0
    if sums[1] > 0.0:
        lo, hi = ti.static(TOLMAN_CLAMP)
        s = ti.min(ti.max(1.0 + delta_l0 * sums[0] / sums[1], lo), hi)
    return s


@ti.data_oriented
class StressTension:
    name = "stress"
    pair_term = False          # acts in the corrector (``corrector_term``), not the predictor
    corrector_term = True
    # C4's factor F and C5's delta (l0): None takes the neighbourhood's own
    # (params.STRESS_NEIGHBOURHOODS, lattice.stress_constants: at 2.1 l0 F = 1, the flat
    # lattice face's balance n0/(2 d G l0) rounded, 1.011 in 3D); a study sets another
    # (tools/stress_surface_study.py --c4-factor, --tolman)
    c4_factor = None
    tolman_delta = None
    tolman_lag = None          # C5's lag in capillary times: None takes TOLMAN_LAG, 0 none
    # C3b's pairs torque-free, each T_i through L_i (module docstring, 2b): None takes the
    # neighbourhood's (params.STRESS_NEIGHBOURHOODS' "surface_pairs": 2D yes, 3D no), a study
    # sets it (tools/stress_surface_study.py --torque-free yes|no)
    torque_free = None

    def __init__(self, model: Model, grid: CellGrid, coef: Coefficients):
        self.model, self.grid, self.coef, self.state = model, grid, coef, grid.state
        self.dim = model.dim
        cap = self.state.capacity
        self.colour = ti.Vector.field(self.dim, float, cap)   # g_i (C1) [1/m]
        self.accel = ti.Vector.field(self.dim, float, cap)    # a_i (C3) [m/s^2]
        self.floor = None        # the analytic plane floor, where the model has one
        factor, delta = stress_constants(self.dim, model.stress_re_ratio, model.stress_pairs)
        # C3's pairs: all alike, or weighted by the surface band (C3b); a times the lattice
        # face's factor and the measured one with the latter (lattice.stress_pairs_scale)
        self.surface_pairs = model.stress_pairs == "surface"
        self.pairs_scale = stress_pairs_scale(self.dim, model.stress_re_ratio, model.stress_pairs)
        self.fabric = None
        torque_free = self.torque_free
        if self.surface_pairs and torque_free is None:
            torque_free = params.stress_surface_pairs(model.stress_re_ratio)["torque_free"][
                self.dim]
        self.torque_pairs = self.surface_pairs and bool(torque_free)
        if self.torque_pairs:      # C3b's L_i, pass 1's (I where T_i = 0)
            self.fabric = ti.Matrix.field(self.dim, self.dim, float, cap)
        self.colour_sums = ti.types.struct(g=ti.types.vector(self.dim, float),
                                           m=ti.types.matrix(self.dim, self.dim, float))
        # C3's pair support H / l0, the neighbourhood's (compiled in)
        self.pair_support = params.stress_pair_support(self.dim, model.stress_re_ratio)
        self.surface_factor = factor if self.c4_factor is None else float(self.c4_factor)
        # C5: sigma (1 - delta H), delta in l0; s_i lagged in capillary time (_followed)
        self.delta = delta if self.tolman_delta is None else float(self.tolman_delta)
        self.lag = TOLMAN_LAG if self.tolman_lag is None else float(self.tolman_lag)
        self.tolman = self.tolman_next = None
        if self.delta > 0.0:
            # s_i, lagged; 0 until i's first step sets it (UNSET: 1 is used till then)
            self.tolman = self.state.carry("stress_tolman", ti.field(float, cap), UNSET)
            self.tolman_next = ti.field(float, cap)            # this step's value, pass 2's
        self.pass_sums = ti.types.struct(a=ti.types.vector(self.dim, float),
                                         h=ti.types.vector(2, float))   # pass 2's: a_i, C5's H_i
        self.symmetry = None     # the mirror planes, where the scene has them

    def attach(self, floor, symmetry) -> None:
        """The simulator's plane floor and symmetry planes (None where it has none)."""
        self.floor, self.symmetry = floor, symmetry

    def nbytes(self) -> int:
        own = [self.colour, self.accel] + ([self.tolman, self.tolman_next] if self.delta > 0.0
                                           else []) + ([self.fabric] if self.fabric is not None
                                                       else [])
        return sum(field_nbytes(f) for f in own)

    def boundary_pressure(self, dt: float = 0.0) -> None:
        """The two passes (module docstring), then the free surface's pressure (C4) and C5's
        s_i for the next step, its lag advanced by ``dt`` (0: output, nothing advances)."""
        if self.surface_pairs and self.symmetry is not None:
            self.symmetry.sync_pressure()     # C3b weighs images by their n: theirs now
        if self.fabric is not None:
            self._colour_fabric()
        else:
            self._colour()
        if self.symmetry is not None:
            self._sync_images()
        self._divergence()
        self._surface_pressure(dt)

    @ti.func
    def _colour_pair(self, i, j, rij, r2, acc: ti.template()):
        if self.state.kind[j] != GONE:
            acc += rij * stress_kernel(ti.sqrt(r2), self.coef.re[None])

    @ti.kernel
    def _colour(self):
        """Pass 1: g_i for fluid particles (0 for the others: walls carry no tension)."""
        for at in range(self.state.n[None]):
            i = self.state.spread(at)
            g = ti.Vector.zero(float, self.dim)
            if self.state.kind[i] == FLUID:
                self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                             self._colour_pair, g)
                if ti.static(self.model.plane_floor):
                    g[self.dim - 1] += self.floor.colour_at(self.state.pos[i][self.dim - 1])
            self.colour[i] = self._surface_weight(i) * self.coef.stress_K[None] * g

    @ti.func
    def _band(self, j):
        """C3b's omega_j (band_weight of its number density), 0 for walls and dummies."""
        return ti.select(self.state.kind[j] == FLUID,
                         band_weight(self.state.density[j], self.coef.n0[None]), 0.0)

    @ti.func
    def _colour_fabric_pair(self, i, j, rij, r2, acc: ti.template()):
        """C1's term within re, and C3b's weighted fabric over pass 2's own pairs to H."""
        if self.state.kind[j] != GONE:
            r = ti.sqrt(r2)
            if r2 < self.coef.re2[None]:
                acc.g += rij * stress_kernel(r, self.coef.re[None])
            acc.m += (0.5 * (self._band(i) + self._band(j)) * self._pair_weight(r)
                      ) * rij.outer_product(rij)

    @ti.kernel
    def _colour_fabric(self):
        """Pass 1 with C3b: g_i as ``_colour`` (walked only where omega_i > 0: elsewhere g_i
        = 0), and L_i = M_i^-1 (d - 1) / tr_t(M_i^-1) of the weighted fabric M_i = sum_j w_ij
        f_d r_ij r_ij^T over pass 2's pairs, tr_t the trace in T_i's tangent plane (I where M_i
        is degenerate or T_i = 0), so that T_i L_i M_i is symmetric (the pairs exert no
        torque) and L_i's mean gain along the surface is 1 (T_i's size unchanged)."""
        reach2 = (self.pair_support * self.coef.l0[None]) ** 2
        for at in range(self.state.n[None]):
            i = self.state.spread(at)
            acc = self.colour_sums(g=ti.Vector.zero(float, self.dim),
                                   m=ti.Matrix.zero(float, self.dim, self.dim))
            correction = ti.Matrix.identity(float, self.dim)
            omega = 0.0
            if self.state.kind[i] == FLUID:
                omega = self._surface_weight(i)
            if omega > 0.0:
                self.grid.for_each_wide(i, self.state.pos[i], reach2, self._colour_fabric_pair,
                                        acc)
                if ti.static(self.model.plane_floor):   # (the floor's pairs not in M_i)
                    acc.g[self.dim - 1] += self.floor.colour_at(self.state.pos[i][self.dim - 1])
                iso = acc.m.trace() / self.dim
                gl = acc.g.norm()
                if (gl > 0.0 and iso > 0.0
                        and acc.m.determinant() > FABRIC_DET_MIN * iso ** self.dim):
                    inv = acc.m.inverse()
                    n = acc.g / gl                  # T_i's normal
                    along = inv.trace() - n.dot(inv @ n)      # tr of M^-1 in the tangent plane
                    correction = ((self.dim - 1) / along) * inv
            self.colour[i] = omega * self.coef.stress_K[None] * acc.g
            self.fabric[i] = correction

    @ti.func
    def _surface_weight(self, i):
        """omega_i = clamp((1 - n_i/n0) / (2 (1 - beta)), 0, 1) (C1): 1 on the free surface's
        outer layer (n ~ 0.5-0.75 n0), 1/2 at the free-surface threshold beta n0 (M3), 0 at
        n >= n0, so the colour gradient's noise inside a disordered liquid carries no tension."""
        return surface_weight(self.state.density[i], self.coef.n0[None], self.coef.beta[None])

    @ti.kernel
    def _sync_images(self):
        """Images take their sources' g, reflected across their planes, and their s (C5)."""
        n = self.state.n[None]
        for s in range(n, n + self.state.n_images[None]):
            self.colour[s] = self.symmetry._mirrored(self.colour[self.symmetry.source[s]], s)
            if ti.static(self.delta > 0.0):
                self.tolman[s] = self.tolman[self.symmetry.source[s]]
            if ti.static(self.torque_pairs):     # R L R, R the reflection (diagonal)
                sign = self.symmetry._mirrored(ti.Vector.one(float, self.dim), s)
                self.fabric[s] = self.fabric[self.symmetry.source[s]] * sign.outer_product(sign)

    @ti.func
    def _pair_weight(self, r):
        """f_d(r) with its core (C3)."""
        l0 = self.coef.l0[None]
        return stress_pair_kernel(r, self.pair_support * l0, l0)   # H (compile time)

    @ti.func
    def _through(self, i, r):
        """L_i r with C3b's torque-free pairs, r otherwise."""
        out = r
        if ti.static(self.torque_pairs):
            out = self.fabric[i] @ r
        return out

    @ti.func
    def _pair_tension(self, i, j, gi, gj, rij):
        """(s_i T_i L_i + s_j T_j L_j) r_ij (C3, C5; L = I but with C3b's torque-free pairs),
        T_j = 0 for walls and dummies."""
        f = stress_times(gi, self._through(i, rij)) * self._tension(i)
        if self.state.kind[j] == FLUID:
            f += stress_times(gj, self._through(j, rij)) * self._tension(j)
        return f

    @ti.func
    def _divergence_pair(self, i, j, rij, r2, acc: ti.template()):
        kind_j = self.state.kind[j]
        if kind_j != GONE:
            r = ti.sqrt(r2)
            gi, gj = self.colour[i], self.colour[j]
            f = self._pair_tension(i, j, gi, gj, rij) * self._pair_weight(r)
            if ti.static(self.surface_pairs):      # C3b: the pairs weighted
                f *= 0.5 * (self._band(i) + self._band(j))
            acc.a += f
            if ti.static(self.delta > 0.0):
                g_min = NORMAL_MIN / self.coef.l0[None]
                if r < self.coef.re[None] and gj.norm() > g_min and gi.norm() > g_min:
                    acc.h += normal_divergence_terms(   # C5: the divergence of n = g/|g|
                        gi.normalized(), gj.normalized(), rij, stress_kernel(r, self.coef.re[None]))

    @ti.func
    def _tension(self, i):
        """s_i of C5 (1 where the correction is compiled out or i has yet to set it)."""
        s = 1.0
        if ti.static(self.delta > 0.0):
            s = ti.select(self.tolman[i] > UNSET, self.tolman[i], 1.0)
        return s

    @ti.func
    def _followed(self, i, dt):
        """C5's s_i for the next step: pass 2's s_now through a first-order lag of time tau =
        lag sqrt(rho / (sigma |H|^3)), the capillary time of the curvature, |H| the larger of
        the lagged and the present one's (s = 1 - delta l0 H), so the correction follows the
        surface's mean curvature but not a mode's oscillation about it; s_now at i's first
        step; unchanged where dt = 0."""
        s, s_now = self.tolman[i], self.tolman_next[i]
        if dt > 0.0:
            if s <= UNSET:
                s = s_now
            else:
                rate = 1.0
                if ti.static(self.lag > 0.0):
                    h = ti.max(ti.abs(1.0 - s), ti.abs(1.0 - s_now)) / (
                        self.delta * self.coef.l0[None])
                    rate = 1.0 - ti.exp(-dt * ti.sqrt(self.coef.sigma[None] * h * h * h / (
                        self.coef.rho[None])) / self.lag)
                s += rate * (s_now - s)
        return s

    @ti.kernel
    def _divergence(self):
        """Pass 2: a_i = (K_d / rho) sum_j (T_i + T_j) r_ij f_d(r_ij) (C3), T = sigma a (|g| I -
        g g^T/|g|) (C2), T_j = 0 for walls and dummies (the plane floor's layers: d_floor)."""
        scale = self.coef.stress_Kd[None] * self.coef.sigma[None] * self.coef.stress_a[None] / (
            self.coef.rho[None]) * self.pairs_scale
        reach2 = (self.pair_support * self.coef.l0[None]) ** 2    # H^2: the wide walk
        for at in range(self.state.n[None]):
            i = self.state.spread(at)
            s_next = 1.0
            if self.state.kind[i] == FLUID:
                acc = self.pass_sums(a=ti.Vector.zero(float, self.dim),
                                     h=ti.Vector.zero(float, 2))
                self.grid.for_each_wide(i, self.state.pos[i], reach2, self._divergence_pair, acc)
                if ti.static(self.model.plane_floor):
                    ez = ti.Vector.zero(float, self.dim)
                    ez[self.dim - 1] = self.floor.divergence_at(self.state.pos[i][self.dim - 1])
                    floor_share = stress_times(self.colour[i], self._through(i, ez)) * (
                        self._tension(i))
                    if ti.static(self.surface_pairs):     # C3b: the layers weigh 0
                        floor_share *= 0.5 * self._band(i)
                    acc.a += floor_share
                self.accel[i] = scale * acc.a
                if ti.static(self.delta > 0.0):
                    s_next = tolman_factor(acc.h, self.delta * self.coef.l0[None])      # C5
            if ti.static(self.delta > 0.0):
                self.tolman_next[i] = s_next

    @ti.kernel
    def _surface_pressure(self, dt: float):
        """C4: P_i = rho l0 max(0, a_i . g_i/|g_i|) for the fluid particles S17/M3 left at
        P = 0 that have a colour gradient (the free surface: omega_i > 0); C5's next s_i."""
        scale = self.surface_factor * self.coef.rho[None] * self.coef.l0[None]
        for at in range(self.state.n[None]):
            i = self.state.spread(at)
            g = self.colour[i]
            gl = g.norm()
            if self.state.kind[i] == FLUID and self.state.pressure[i] <= 0.0 and gl > 0.0:
                self.state.pressure[i] = scale * ti.max(self.accel[i].dot(g) / gl, 0.0)
            if ti.static(self.delta > 0.0):
                self.tolman[i] = self._followed(i, dt)      # C5: the next step's s_i

    @ti.func
    def acceleration(self, i):
        """a_i of the last ``boundary_pressure``, for the corrector (S18)."""
        return self.accel[i]
