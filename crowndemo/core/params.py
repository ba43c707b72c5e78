"""Parameters of one simulation: the liquid and resolution (Physics) and the numerics.

Values are SI units. ``Model`` is the compile-time part (which terms exist); everything else is
passed to the kernels at run time, so changing a value never recompiles.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Any, Optional, Tuple, TypeVar

# (S11) with P_j - P_i; P_j - Pmin_i; P_j + P_i; P_i L_i + P_j L_j, L the fabric's (M2, M2c)
GRADIENT_FORMS = ("seed", "pmin", "sum", "corrected")
WALL_MODELS = ("particles", "plane")       # the floor: wall + dummy particles, or tables
COURANT_SPEEDS = ("absolute", "relative")  # the speed of the Courant limit (S5; terms.py)
# the surface-tension family (core/surface_tension/): the seed's potential (S22-S24) or the
# continuum surface stress (method.md §4c) or the curvature-based pressure boundary condition
# P = sigma kappa (Tsujimura et al. 2023; experimental)
SURFACE_TENSION_MODELS = ("potential", "stress", "curvature")
# the viscosity family (core/viscosity.py): the seed's Laplacian (S12) or the central pair form
# (method.md V1), whose dissipation at a free surface is the Navier-Stokes equations'
VISCOSITY_MODELS = ("laplacian", "central")
# each member's stiffness: the viscous limit nu dt / l0^2 <= C_nu / stiffness (timestep.py).
# The central form is nu (lap u + 2 grad div u): 3 nu k^2 on a sound wave against lap u's
# nu k^2; on the lattice the largest eigenvalue of its pair sum is 2.80 (3D) / 2.87 (2D)
# times the Laplacian's (tests/test_viscosity.py)
VISCOUS_STIFFNESS = {"laplacian": 1.0, "central": 3.0}
# the surface stress's neighbourhoods (method.md §4c), re/l0 -> its measured constants:
# - "pair_support": H/l0 per dimension, the reach of C3's divergence pair kernel: beyond re,
#   so its walk is the grid's wide one (grid.py); 3 l0 at 2.1 l0; at 3.1 l0 4.1 l0 (re + l0)
#   in 3D, so that C3's pairs cover the colour gradient's whole neighbourhood, and 3 l0 in 2D,
#   where 4.1 l0 read the mode 6.4 % fast (VALIDATION.md, "re = 3.1 l0 with C3's pairs to
#   4.1 l0");
# - "c4_factor": C4's F, the free surface's own normal stress F rho l0 a.g/|g|, per dimension;
#   "lattice": the flat lattice face's balance n0/(2 d G l0) at that re
#   (lattice.face_balance_factor: 1.160 / 1.187 in 2D / 3D at 3.1 l0); 1 at 2.1 l0, where the
#   balance is 1.016 / 1.011, and in 3D at 3.1 l0 (with the pairs to 4.1 l0 the balance read
#   the mode 4.7 % slow at R/l0 = 10 with delta 0.80, and the larger delta lowers it more);
# - "tolman": C5's curvature correction sigma (1 - delta H), delta in l0 per dimension; the
#   surface of tension sits inside the liquid's surface (VALIDATION.md, "The curvature
#   correction"); 0 compiles it out. 0.80 in 3D at 2.1 l0: the value at which the resting
#   drop's error falls with resolution (VALIDATION.md, "C5's H from the normals' tangential
#   change"; 0.92, set at R/l0 = 12 alone, over-corrected at 16); at 3.1 l0 0.9 in 2D, where
#   without it the drop read high ("re = 3.1 l0 completed"), and 1.25 in 3D, where C3's wider
#   pairs pull deeper.
# 2.1 l0 is the seed's neighbourhood, the crowns'; at 3.1 l0 the 3D drops' Laplace and mode-2
# frequency errors fall with resolution and the decay is 1.0-1.16 times Lamb's rate at R/l0 =
# 10-16 (VALIDATION.md, "re = 3.1 l0 with C3's pairs to 4.1 l0"; 1.17-1.32 with H = 3 l0),
# 1.5-1.9 times it at 2.1 l0 (a 3D particle has 122 lattice neighbours within re against 32).
# The constants are measured, not derived: another re is refused.
# C5's s_i follows its step's value through a first-order lag of this many capillary times
# sqrt(rho / (sigma |H|^3)) (about 1.6 periods of mode 2 of a drop of radius 1/|H|; method.md
# §4c): a tension that followed the mode's own bending damped a 3D drop's oscillation
# (VALIDATION.md, "C5's own damping", "C5 lagged in the surface's capillary time")
STRESS_TOLMAN_LAG = 3.5
STRESS_NEIGHBOURHOODS = {2.1: {"pair_support": {2: 3.0, 3: 3.0}, "c4_factor": {2: 1.0, 3: 1.0},
                               "tolman": {2: 0.0, 3: 0.80},
                               "surface_pairs": {"factor": {2: 1.22, 3: 1.34},
                                                 "tolman": {2: 0.0, 3: 0.0},
                                                 "torque_free": {2: True, 3: False}}},
                         3.1: {"pair_support": {2: 3.0, 3: 4.1},
                               "c4_factor": {2: "lattice", 3: 1.0},
                               "tolman": {2: 0.9, 3: 1.25}}}
SEED_NEIGHBOURHOOD = 2.1
# C3's pairs (method.md §4c, stress.py): "all" weighs every pair of the divergence alike (the
# member as it was to 2026-12-08); "surface" weighs each by the mean of its two particles'
# band weights clamp((1 - n/n0) / STRESS_SURFACE_BAND, 0, 1), so the pull lands on the surface
# layer rather than a spacing under it and the layer stays full (VALIDATION.md, "The mean
# weight's unsteady pressure"). Its constants are a neighbourhood's "surface_pairs": a factor
# on the tension measured on the drops with pressure_gradient: corrected, C5's delta (0: off),
# and whether each T_i goes through its L_i (stress.py, 2b), which takes the weighted pairs'
# torque out: in 2D, where without it free drops turned 0.06-0.14 rad in 10 periods at R/l0
# = 8 and 16, not in 3D, where the drops held still without it and with it the mode decayed
# at 0.65 of the viscous rate (VALIDATION.md "C3's surface pairs"). Only the neighbourhoods
# that have them admit it.
STRESS_PAIRS = ("all", "surface")
# the band: a flat lattice face (deficit 0.27 / 0.32 in 3D / 2D) weighs 1, the layer under it
# 0.014 / 0.031 (C1's band 2 (1 - beta) = 0.04 / 0.06 made a particle a spacing in half a
# surface particle as soon as its n fell 2-3 % under n0)
STRESS_SURFACE_BAND = 0.25


def _neighbourhood_key(re_ratio: float) -> Optional[float]:
    """The key of STRESS_NEIGHBOURHOODS that ``re_ratio`` is (within 1e-9), or None."""
    for key in STRESS_NEIGHBOURHOODS:
        if _finite(re_ratio) and abs(re_ratio - key) < 1e-9:
            return key
    return None


def stress_neighbourhood(re_ratio: float, source: str = "parameters") -> float:
    """The key of STRESS_NEIGHBOURHOODS that ``re_ratio`` is (within 1e-9), or a
    ParameterError naming re_ratio and the calibrated values."""
    key = _neighbourhood_key(re_ratio)
    if key is None:
        raise ParameterError("re_ratio", re_ratio,
                             " or ".join(f"{k:g}" for k in STRESS_NEIGHBOURHOODS)
                             + " with surface_tension: stress", source)
    return key


def stress_surface_pairs(re_ratio: float, source: str = "parameters") -> dict:
    """The "surface_pairs" constants of the neighbourhood ``re_ratio``, or a ParameterError
    naming stress_pairs where it has none."""
    own = STRESS_NEIGHBOURHOODS[stress_neighbourhood(re_ratio, source)]
    if "surface_pairs" not in own:
        with_pairs = [f"{k:g}" for k, v in STRESS_NEIGHBOURHOODS.items() if "surface_pairs" in v]
        raise ParameterError("stress_pairs", "surface", "all, or surface at re_ratio "
                             + " or ".join(with_pairs) + f" (re_ratio is {re_ratio:g})",
                             source)
    return own["surface_pairs"]


def stress_pair_support(dim: int, re_ratio: float) -> float:
    """C3's pair support H/l0 in ``dim`` at ``re_ratio``: its neighbourhood's, or the seed
    neighbourhood's where it has none (the other members, which compile as at 2.1 l0)."""
    key = _neighbourhood_key(re_ratio)
    own = STRESS_NEIGHBOURHOODS[SEED_NEIGHBOURHOOD if key is None else key]
    return float(own["pair_support"][dim])


# M2c (pressure.py) and C3b (stress.py): L_i = I where the fabric is degenerate, det M_i <
# FABRIC_DET_MIN (tr M_i / d)^d (a particle with its neighbours on a line or a plane; a
# half-space's face reads 0.86 in 3D)
FABRIC_DET_MIN = 0.05

# the seed's water (method.md §6) and gravity, the defaults wherever a liquid is not given
WATER = {"rho": 998.0, "nu": 1.0e-6, "sigma": 0.0728}     # kg/m^3, m^2/s, N/m
GRAVITY = 9.81                                            # m/s^2
SOUND_SPEED_FACTOR = 5.0    # c = 5 v_max (method.md S8): Mach 0.2, density varies ~(v/c)^2 = 4 %


class ParameterError(ValueError):
    """A parameter out of its allowed range, reported before any kernel runs."""

    def __init__(self, key: str, value, allowed: str, source: str = "parameters"):
        self.key, self.value, self.allowed, self.source = key, value, allowed, source
        super().__init__(f"{source}: {key} = {value!r} is out of range; allowed: {allowed}")


@dataclass(frozen=True)
class Physics:
    dim: int
    l0: float                       # initial particle spacing [m]
    v_max: float                    # expected maximum speed of the scene [m/s] (S5-S8)
    re_ratio: float = 2.1           # re / l0 (S10)
    rho: float = WATER["rho"]       # density [kg/m^3]
    nu: float = WATER["nu"]         # kinematic viscosity [m^2/s]
    sigma: float = WATER["sigma"]   # surface tension [N/m]
    gravity: float = GRAVITY        # along minus the last axis [m/s^2]
    sound_speed: Optional[float] = None   # None: c = 5 v_max (S8)

    @property
    def c(self) -> float:
        return (self.sound_speed if self.sound_speed is not None
                else SOUND_SPEED_FACTOR * self.v_max)

    @property
    def re(self) -> float:
        return self.re_ratio * self.l0

    def validate(self, source: str = "parameters") -> "Physics":
        def need(cond: bool, key: str, allowed: str):
            if not cond:
                raise ParameterError(key, getattr(self, key), allowed, source)
        need(self.dim in (2, 3), "dim", "2 or 3")
        need(_finite(self.l0) and self.l0 > 0, "l0", "> 0 m")
        need(_finite(self.v_max) and self.v_max > 0, "v_max", "> 0 m/s")
        need(_finite(self.re_ratio) and 1.5 <= self.re_ratio <= 4.5, "re_ratio", "1.5 .. 4.5")
        need(_finite(self.rho) and self.rho > 0, "rho", "> 0 kg/m^3")
        need(_finite(self.nu) and self.nu >= 0, "nu", ">= 0 m^2/s")
        need(_finite(self.sigma) and self.sigma >= 0, "sigma", ">= 0 N/m")
        need(_finite(self.gravity), "gravity", "a finite number (m/s^2)")
        need(self.sound_speed is None or (_finite(self.sound_speed) and self.sound_speed > 0),
             "sound_speed", "> 0 m/s, or unset for 5 v_max")
        return self


@dataclass(frozen=True)
class Numerics:
    courant: float = 0.2            # velocity Courant v dt / l0 (S5)
    # v in the Courant limit: the largest particle speed (the seed's S5), or the largest speed
    # of a particle relative to its neighbours, walls at rest (terms.py), which
    # brings in the approach limit too: every particle moves at most ``approach`` l0 a step
    courant_speed: str = "absolute"
    approach: float = 0.5           # |u| dt / l0 with courant_speed relative
    acoustic: float = 1.0           # acoustic Courant c dt / l0 (S6)
    viscous: float = 0.15           # nu dt / l0^2 (M1)
    capillary: float = 1.0          # fraction of sqrt(rho l0^3 / (2 pi sigma)) (M1)
    dt_max: float = math.inf        # cap, e.g. the frame interval [s]
    fixed_dt: Optional[float] = None
    allow_unsafe_dt: bool = False   # only for tests that force an unstable run
    pressure_gradient: str = "pmin"
    surface_tension: str = "potential"   # SURFACE_TENSION_MODELS; compiled in when sigma > 0
    stress_pairs: str = "all"       # STRESS_PAIRS: C3's pairs with surface_tension: stress
    viscosity: str = "laplacian"    # VISCOSITY_MODELS; compiled in when nu > 0
    beta: Optional[float] = None    # free-surface threshold n < beta n0 (M3); None: 0.97/0.98
    max_density_excess: float = 0.5  # abort when n/n0 - 1 exceeds this
    max_mach: float = 1.0           # abort when a speed exceeds max_mach * c
    max_out_fraction: float = 0.05  # abort when more fluid than this has left the domain
    reorder_every: int = 1          # physical re-sort of particles by cell every N steps
    # particle collision model (not in method.md; Koshizuka et al. 1998, Lee et al. 2011):
    # pairs closer than collision * l0 that approach exchange momentum inelastically
    # (restitution e). It stops free-surface particles (P = 0 by M3, so no pressure repels
    # them) from collapsing onto each other; 0 turns it off (not compiled in). 0.5 l0: the
    # quick crown runs to its end with any frame schedule at 0.5 as at 0.85, and loses 11 %
    # of its energy by 1 ms in the 2m-drop and 3m-drop drafts against 19-23 % at 0.85 (10 %
    # without collisions).
    collision: float = 0.5          # collision distance / l0 (0: off; < 1 keeps the lattice free)
    restitution: float = 0.2        # e: the approach speed after a collision is e times before
    # implementation choices (results equal to float rounding; BENCHMARKS.md has their cost):
    neighbour_list: bool = True     # the density pass lists each fluid particle's neighbours
    #                                 for the pressure gradient (core/neighbours.py)
    cells_per_re: int = 2           # cells of side re/k, a walk within (2k + 1)^d cells (grid.py)
    # the predictor's pairs (S12, S22, the collision model) at r^k taken from the density
    # pass's list of the step before (at r*, then moved by the corrector's dt^2 a', S20)
    # instead of a grid build and cell walk of their own (terms.py: what it misses)
    predictor_list: bool = True
    # the floor (z = 0): layers of wall and dummy particles, or the analytic plane floor
    # (core/plane_floor.py: their contributions tabulated against the height; no particles)
    wall_model: str = "particles"
    # mirror symmetry planes through the scene's axis (core/symmetry.py): axes 0 (x = 0) and/or
    # 1 (y = 0); set by a scene built as one half or quarter (scenes/symmetric.py), () whole
    mirror_planes: Tuple[int, ...] = ()

    def validate(self, source: str = "parameters") -> "Numerics":
        def need(cond: bool, key: str, allowed: str):
            if not cond:
                raise ParameterError(key, getattr(self, key), allowed, source)
        for key in ("courant", "acoustic", "viscous", "capillary", "approach"):
            need(_finite(getattr(self, key)) and 0 < getattr(self, key) <= 2.0, key, "0 < x <= 2")
        need(self.dt_max > 0, "dt_max", "> 0 s")
        need(self.fixed_dt is None or (_finite(self.fixed_dt) and self.fixed_dt > 0),
             "fixed_dt", "> 0 s, or unset for adaptive")
        need(self.pressure_gradient in GRADIENT_FORMS, "pressure_gradient",
             " | ".join(GRADIENT_FORMS))
        need(self.surface_tension in SURFACE_TENSION_MODELS, "surface_tension",
             " | ".join(SURFACE_TENSION_MODELS))
        need(self.viscosity in VISCOSITY_MODELS, "viscosity", " | ".join(VISCOSITY_MODELS))
        need(self.stress_pairs in STRESS_PAIRS, "stress_pairs", " | ".join(STRESS_PAIRS))
        need(self.beta is None or 0.5 <= self.beta < 1.0, "beta", "0.5 <= beta < 1")
        need(self.max_density_excess > 0, "max_density_excess", "> 0")
        need(self.max_mach > 0, "max_mach", "> 0")
        need(0 <= self.max_out_fraction <= 1, "max_out_fraction", "0 .. 1")
        need(_finite(self.collision) and 0 <= self.collision < 1, "collision",
             "0 <= x < 1 (a fraction of l0; 0: off)")
        need(_finite(self.restitution) and 0 <= self.restitution <= 1, "restitution", "0 .. 1")
        need(isinstance(self.neighbour_list, bool), "neighbour_list", "true or false")
        need(isinstance(self.predictor_list, bool), "predictor_list", "true or false")
        need(self.wall_model in WALL_MODELS, "wall_model", " | ".join(WALL_MODELS))
        need(self.courant_speed in COURANT_SPEEDS, "courant_speed", " | ".join(COURANT_SPEEDS))
        need(isinstance(self.cells_per_re, int) and not isinstance(self.cells_per_re, bool)
             and 1 <= self.cells_per_re <= 3, "cells_per_re", "1, 2 or 3")
        need(isinstance(self.reorder_every, int) and self.reorder_every >= 0, "reorder_every",
             "an integer >= 0 (0: never)")
        need(self.pressure_gradient != "corrected" or (self.wall_model == "particles"
                                                       and self.mirror_planes == ()),
             "pressure_gradient", "seed | pmin | sum, or corrected with wall_model: particles "
             "and no mirror_planes (its fabric L_i sums particles only, method.md M2c)")
        need(isinstance(self.mirror_planes, tuple)
             and self.mirror_planes in ((), (0,), (1,), (0, 1)), "mirror_planes",
             "(), (0,), (1,) or (0, 1): the planes x = 0 (0) and y = 0 (1)")
        return self

    def free_surface_beta(self, dim: int) -> float:
        return self.beta if self.beta is not None else (0.97 if dim == 2 else 0.98)


@dataclass(frozen=True)
class Model:
    """What is compiled into the step; a term that is off costs no work and no kernel."""
    dim: int
    viscosity: bool
    surface_tension: bool
    gravity: bool
    pressure_gradient: str
    collision: bool = False
    neighbour_list: bool = True
    cells_per_re: int = 2
    plane_floor: bool = False
    relative_courant: bool = False   # the relative speed measured (terms.py)
    mirror_planes: Tuple[int, ...] = ()   # symmetry planes (symmetry.py)
    predictor_list: bool = False     # the predictor's pairs from the last list (terms.py)
    surface_tension_model: str = "potential"   # the family member (core/surface_tension/)
    wide_walk: float = 1.0           # the grid's wide walk over re (grid.py; stress C3)
    viscosity_model: str = "laplacian"   # the family member (core/viscosity.py)
    # re/l0 whose constants the stress member compiles in (STRESS_NEIGHBOURHOODS); the seed's
    # 2.1 for the other members, so a simulator of theirs serves any re (control.Session)
    stress_re_ratio: float = Physics.re_ratio
    stress_pairs: str = "all"        # C3's pairs (STRESS_PAIRS), "all" for the other members

    @classmethod
    def of(cls, physics: Physics, numerics: Numerics) -> "Model":
        """What ``physics`` and ``numerics`` compile in; a ParameterError (re_ratio, or
        stress_pairs) where the stress member, or its surface pairs, is chosen at a
        neighbourhood it has no constants for."""
        stress = physics.sigma > 0 and numerics.surface_tension == "stress"
        model = cls(physics.dim, physics.nu > 0, physics.sigma > 0, physics.gravity != 0,
                   numerics.pressure_gradient, numerics.collision > 0, numerics.neighbour_list,
                   numerics.cells_per_re, numerics.wall_model == "plane",
                   numerics.courant_speed == "relative", tuple(numerics.mirror_planes),
                   numerics.predictor_list and numerics.neighbour_list,
                   numerics.surface_tension,
                   max(1.0, stress_pair_support(physics.dim, physics.re_ratio)
                       / physics.re_ratio)
                   if stress else 1.0,
                   numerics.viscosity,
                   stress_neighbourhood(physics.re_ratio) if stress else Physics.re_ratio,
                   numerics.stress_pairs if stress else "all")
        if model.stress_pairs == "surface":
            stress_surface_pairs(physics.re_ratio)      # refused where it has no constants
        return model

    def describe(self) -> dict:
        return {"viscosity": self.viscosity, "surface_tension": self.surface_tension,
                "gravity": self.gravity, "pressure_gradient": self.pressure_gradient,
                "collision": self.collision, "neighbour_list": self.neighbour_list,
                "cells_per_re": self.cells_per_re, "plane_floor": self.plane_floor,
                "relative_courant": self.relative_courant,
                "mirror_planes": list(self.mirror_planes),
                "predictor_list": self.predictor_list,
                "surface_tension_model": self.surface_tension_model,
                "viscosity_model": self.viscosity_model, "stress_pairs": self.stress_pairs}


def _finite(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


_Params = TypeVar("_Params", Physics, Numerics)


def with_values(obj: _Params, **changes: Any) -> _Params:
    """A copy of a Physics/Numerics with some values replaced (names checked)."""
    names = {f.name for f in fields(obj)}
    unknown = set(changes) - names
    if unknown:
        raise KeyError(f"unknown parameter(s) {sorted(unknown)}; known: {sorted(names)}")
    return replace(obj, **changes)


__all__ = ["Physics", "Numerics", "Model", "ParameterError", "GRADIENT_FORMS", "WALL_MODELS",
           "COURANT_SPEEDS", "SURFACE_TENSION_MODELS", "STRESS_PAIRS", "VISCOSITY_MODELS",
           "VISCOUS_STIFFNESS", "with_values"]
