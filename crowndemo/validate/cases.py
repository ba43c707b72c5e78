"""The reference cases of the validation (method.md §7): each builds its scene at a spacing l0
and measures one figure against its published or exact value.

A case's ``run(l0, numerics)`` returns the measured figure, the reference and the relative
error; the runner (``runner.py``) times it and varies the resolution and the settings.
"""
from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass, field, replace
from typing import Callable, Dict, Iterator, List, Optional, Tuple

import numpy as np

from ..control import Session
from ..core import FLUID, Numerics, simulator_for
from ..core.params import GRAVITY, WATER
from ..scenes import (dam_break, hydrostatic_tank, momentum_deficit, shear_amplitude, shear_wave,
                      sliding_layer)
from ..scenes.crown import crown_base_radius
from ..scenes.drop import oscillating_drop, resting_drop
from . import oscillation
from .observables import fit_time_origin, mechanical_pressure, surge_front
from .crown_metrics import measure as crown_measure

G, RHO = GRAVITY, WATER["rho"]

# Martin & Moyce (1952), column a x 2a: (T = t sqrt(2 g / a), Z = front / a), method.md §7
MARTIN_MOYCE = ((0.832, 1.217), (1.219, 1.474), (1.997, 2.292), (2.547, 2.995), (3.345, 4.134),
                (4.034, 4.944), (4.418, 5.881), (5.091, 6.980), (5.685, 7.945), (6.306, 8.966),
                (6.822, 9.986))


@dataclass
class Outcome:
    measured: float
    reference: float
    error: float                   # relative: |measured / reference - 1| (or as the case says)
    sim: object                    # the simulator, for steps, particles and health
    extra: Dict[str, float] = field(default_factory=dict)


@dataclass
class Case:
    name: str
    dim: int
    quantity: str                  # what is measured, with its unit
    reference: str                 # where the reference comes from
    resolution: str                # how the spacing is given, e.g. "a/l0"
    scales: Tuple[float, ...]      # resolution values, coarse to fine (full suite)
    quick: Tuple[float, ...]       # the subset for `--quick` and the tests: one coarse scale
    l0_of: Callable[[float], float]
    run: Callable[[float, Numerics], Outcome]
    variants: Tuple[str, ...] = ("f64", "safety/2", "gradient=sum", "gradient=seed",
                                 "plane-floor")
    quick_variant: Optional[str] = ""   # the one variant `--quick` runs ("": the first; None:
                                        # none, another case's quick row runs it)
    # the case's own base settings, before a variant's change (the surface-stress drops:
    # that model and the sum form, tension_cases.py)
    base: Callable[[Numerics], Numerics] = lambda numerics: numerics

    @property
    def quick_variants(self) -> Tuple[str, ...]:
        """The variants of a quick plan: one (or none, where another case's quick row runs
        the same variant), so that the quick set checks every setting (the full plan runs
        them all)."""
        if not self.variants or self.quick_variant is None:
            return ()
        v = self.quick_variant or self.variants[0]
        if v not in self.variants:
            raise ValueError(f"{self.name}: quick variant {v!r} is not one of its variants "
                             f"({', '.join(self.variants)})")
        return (v,)


# ---- compiled simulators shared between runs -----------------------------------------------
_shared: Optional[Session] = None


@contextlib.contextmanager
def sharing(session: Optional[Session]) -> Iterator[Optional[Session]]:
    """Within it the cases take their simulators from ``session`` (None: a new one per run).

    A ``control.Session`` keeps one compiled simulator per model (what is compiled in:
    dimension, terms, gradient form, floor), as for presets: a run whose model an earlier run
    compiled reuses that simulator, reconfigured and reloaded, when the scene fits in it (on
    one thread the same result bit for bit as a fresh simulator, tests/test_control.py; the
    cell limit follows the scene's particles, and the step loops over the particles, not the
    capacity), instead of compiling the kernels again (20-60 s for a 3D model on 2 cores); a
    bigger scene gets a bigger simulator, compiled once. A session is valid while the backend
    runs: a restart (another precision) needs a new one."""
    global _shared
    before, _shared = _shared, session
    try:
        yield session
    finally:
        _shared = before


def simulator(scene):
    """A simulator loaded with ``scene``: from the session of ``sharing``, else a new one."""
    return _shared.load(scene) if _shared is not None else simulator_for(scene)


# ---- hydrostatic pressure ------------------------------------------------------------------
def fluid_pressure_profile(sim, width: float, depth: float, l0: float) -> Tuple[float, float]:
    """Least-squares P = P0 - k z over fluid particles 3 l0 away from the walls and 4 l0 below
    the free surface (the surface layer is held at P = 0 by M3); returns (k, P0)."""
    sim.refresh_pressure()
    s = sim.snapshot()
    p, P, kind = s["pos"], s["pressure"], s["kind"]
    inner = (kind == FLUID) & np.all((p[:, :-1] > 3 * l0) & (p[:, :-1] < width - 3 * l0), axis=1)
    inner &= (p[:, -1] > 3 * l0) & (p[:, -1] < depth - 4 * l0)
    slope, p0 = np.polyfit(p[inner, -1], P[inner], 1)
    return -float(slope), float(p0)


def _hydrostatic(dim: int) -> Case:
    width, depth = (0.04, 0.04) if dim == 2 else (0.036, 0.06)

    def run(l0: float, numerics: Numerics) -> Outcome:
        # nu = 1e-3 m^2/s damps the start-up waves (the tank starts at zero pressure); the
        # hydrostatic answer does not depend on it
        scene = hydrostatic_tank(dim=dim, l0=l0, width=width, depth=depth, nu=1.0e-3,
                                 numerics=numerics)
        sim = simulator(scene)
        # the column, started at zero pressure, still breathes by a few per cent at 0.25 s:
        # the profile averaged over 0.15-0.3 s (7 frames)
        fits: List[Tuple[float, float]] = []
        sim.run(0.3, frame_times=list(np.linspace(0.15, 0.3, 7)),
                on_frame=lambda s, i: fits.append(fluid_pressure_profile(s, width, depth, l0)))
        k, p0 = (float(v) for v in np.mean(fits, axis=0))
        ref = RHO * G * depth
        return Outcome(p0, ref, abs(p0 / ref - 1), sim, {"slope_over_rho_g": k / (RHO * G)})

    return Case(f"hydrostatic-{dim}d", dim, "floor pressure P(0) [Pa] from the fluid profile",
                "rho g H (method.md §7)", "H/l0",
                (20, 40, 80) if dim == 2 else (20, 30, 40), (20,),
                lambda s: depth / s, run)


# ---- dam break -----------------------------------------------------------------------------
def dam_break_fronts(sim, a: float, T_last: float, every: float = 0.05
                     ) -> Tuple[np.ndarray, np.ndarray]:
    """Run a dam break of column width ``a`` to T_last (T = t sqrt(2 g / a)) and sample the
    surge front Z = z/a every ``every`` in T, dense enough to fit a time origin: the leading
    edge of the connected liquid (particles thrown ahead of it are spray, not the front
    Martin & Moyce photographed). Returns (T, Z)."""
    scale = math.sqrt(2 * G / a)
    grid = np.arange(0.0, T_last + 1e-9, every)
    front: List[float] = []

    def sample(s, i):
        snap = s.snapshot()
        front.append(surge_front(snap["pos"][snap["kind"] == FLUID], s.physics.l0) / a)

    sim.run(grid[-1] / scale, frame_times=list(grid / scale), on_frame=sample)
    return grid, np.array(front)


def _dam_break(dim: int) -> Case:
    a = 0.05 if dim == 2 else 0.03
    points = [(T, Z) for T, Z in MARTIN_MOYCE if T <= 3.0]

    def run(l0: float, numerics: Numerics) -> Outcome:
        scene = dam_break(dim=dim, a=a, l0=l0, numerics=numerics)
        sim = simulator(scene)
        grid, front = dam_break_fronts(sim, a, points[-1][0])
        T_ref = np.array([T for T, _ in points])
        Z_ref = np.array([Z for _, Z in points])
        fit = fit_time_origin(grid, front, T_ref, Z_ref)
        ratios = fit["ratios"]
        worst = int(np.argmax(np.abs(ratios - 1)))
        extra = {f"Z/Z_ref at T={T:g}": float(r) for T, r in zip(T_ref, ratios)}
        extra["time origin dT"] = fit["shift"]
        extra["worst without dT"] = fit["worst_unshifted"]
        return Outcome(float(ratios[worst] * Z_ref[worst]), float(Z_ref[worst]),
                       float(abs(ratios[worst] - 1)), sim, extra)

    return Case(f"dam-break-{dim}d", dim,
                "surge front Z = z/a, worst point for T <= 3, time origin fitted (dT <= 0.4)",
                "Martin & Moyce 1952 (method.md §7)", "a/l0",
                (12.5, 25, 50) if dim == 2 else (8, 12, 16), (12.5,) if dim == 2 else (8,),
                lambda s: a / s, run)


# ---- drop oscillation ------------------------------------------------------------------------
def _oscillation(dim: int) -> Case:
    R, nu, periods = 1.0e-3, 1.0e-5, 3.0

    def run(l0: float, numerics: Numerics) -> Outcome:
        scene = oscillating_drop(dim=dim, radius=R, l0=l0, nu=nu, periods=periods,
                                 numerics=numerics)
        sim = simulator(scene)
        ts, ss = [], []

        def sample(s, i):
            ts.append(s.stats.time)
            ss.append(oscillation.deformation(s.snapshot()["pos"]))
        sim.run(scene.t_end, frame_times=np.linspace(0, scene.t_end, int(40 * periods) + 1),
                on_frame=sample)
        omega, decay = oscillation.fit(ts, ss)
        ref, ref_decay = scene.info["omega_rad_s"], scene.info["decay_1_s"]
        err = abs(omega / ref - 1) if math.isfinite(omega) else math.inf
        return Outcome(omega, ref, err, sim, {"decay_1_s": decay, "decay_ref_1_s": ref_decay,
                                              "decay_exact_1_s": scene.info["decay_exact_1_s"]})

    return Case(f"drop-oscillation-{dim}d", dim, "mode-2 angular frequency [rad/s]",
                "Rayleigh-Lamb (method.md §7)", "R/l0",
                (8, 12, 16) if dim == 2 else (5, 6, 8), (8,) if dim == 2 else (5,),
                lambda s: R / s, run,
                variants=("f64", "safety/2", "gradient=sum", "gradient=seed"))   # no floor


# ---- Laplace pressure ------------------------------------------------------------------------
def _laplace(dim: int) -> Case:
    R = 1.0e-3

    def run(l0: float, numerics: Numerics) -> Outcome:
        # the virial pressure needs pair forces: the 'sum' gradient form (observables.py)
        numerics = replace(numerics, pressure_gradient="sum")
        scene = resting_drop(dim=dim, radius=R, l0=l0, nu=1.0e-4, t_end=0.02,
                             numerics=numerics)
        sim = simulator(scene)
        virial: List[float] = []
        eos: List[float] = []
        lat, ph = sim.lattice, sim.physics

        def sample(s, i):
            snap = s.snapshot()
            p = snap["pos"].astype(float)
            inner = np.linalg.norm(p - p.mean(axis=0), axis=1) < 0.5 * R
            dt = min(s.numerics.acoustic * l0 / ph.c, s.numerics.capillary * math.sqrt(
                ph.rho * l0 ** 3 / (2 * math.pi * ph.sigma)))
            mech = mechanical_pressure(p, l0, lat.re, lat.n0, ph.rho, lat.C, lat.mass,
                                       ph.c ** 2, s.numerics.free_surface_beta(dim), dt)
            virial.append(float(mech[inner].mean()))
            s.refresh_pressure()
            eos.append(float(s.snapshot()["pressure"][inner].mean()))
        sim.run(scene.t_end, frame_times=np.linspace(0.5 * scene.t_end, scene.t_end, 6),
                on_frame=sample)
        ref = (dim - 1) * ph.sigma / R
        p_in = float(np.mean(virial))
        return Outcome(p_in, ref, abs(p_in / ref - 1), sim,
                       {"eos_pressure_Pa": float(np.mean(eos))})

    return Case(f"laplace-{dim}d", dim, "virial pressure inside a resting drop (r < R/2) [Pa]",
                "sigma/R (2D), 2 sigma/R (3D) (method.md §7)", "R/l0",
                (8, 11, 16) if dim == 2 else (4, 5, 6), (8,) if dim == 2 else (4,),
                lambda s: R / s, run, variants=("f64", "safety/2"))


# ---- viscous decay of a shear wave --------------------------------------------------------
def _shear_wave(dim: int) -> Case:
    wavelength = 2.0e-3

    def run(l0: float, numerics: Numerics) -> Outcome:
        scene = shear_wave(dim=dim, wavelength=wavelength, l0=l0, numerics=numerics)
        sim = simulator(scene)
        snap = sim.snapshot()
        a0 = shear_amplitude(snap["pos"], snap["vel"], wavelength, l0)
        sim.run(scene.t_end)
        snap = sim.snapshot()
        a1 = shear_amplitude(snap["pos"], snap["vel"], wavelength, l0)
        ref = scene.info["decay_1_s"]
        rate = -math.log(a1 / a0) / scene.t_end if a1 > 0 else math.inf
        return Outcome(rate, ref, abs(rate / ref - 1), sim)

    return Case(f"shear-wave-{dim}d", dim, "decay rate of a free layer's shear wave [1/s]",
                "nu k^2, exact Navier-Stokes solution (scenes/reference.py)", "lambda/l0",
                (10, 20, 40) if dim == 2 else (10, 20, 30), (20,) if dim == 2 else (10,),
                lambda s: wavelength / s, run,
                variants=("f64", "safety/2", "gradient=sum", "gradient=seed"))   # no floor


# ---- a layer sliding over a floor at rest (Stokes's first problem) ------------------------
def _sliding_layer(dim: int) -> Case:
    delta = 1.0e-3

    def run(l0: float, numerics: Numerics) -> Outcome:
        scene = sliding_layer(dim=dim, delta=delta, l0=l0, numerics=numerics)
        sim = simulator(scene)
        sim.run(scene.t_end)
        snap, info = sim.snapshot(), scene.info
        deficit = momentum_deficit(snap["pos"], snap["vel"], snap["kind"], info["speed_m_s"],
                                   info["length_m"], info["depth_m"], l0)
        ref = info["deficit_m2_s"]
        return Outcome(deficit, ref, abs(deficit / ref - 1), sim)

    return Case(f"sliding-layer-{dim}d", dim,
                "momentum deficit / rho of a layer stopped by the floor [m^2/s]",
                "U delta / sqrt(pi), Stokes's first problem (scenes/reference.py)", "delta/l0",
                (5, 10, 20) if dim == 2 else (5, 7, 10), (10,) if dim == 2 else (5,),
                lambda s: delta / s, run, variants=("f64", "plane-floor"))


# ---- crown base radius -----------------------------------------------------------------------
def crown_case(preset: str = "quick", t_end: Optional[float] = None,
               refine: Tuple[float, ...] = (1.0, 0.8, 0.6),
               variants: Tuple[str, ...] = ("untrimmed", "safety/2", "gradient=sum",
                                            "plane-floor", "relative-courant")) -> Case:
    """The crown base radius of a 3D crown preset against Yarin & Weiss's sqrt(t) law, over the
    frames after the crown has formed (tau = t U / D > 0.25 after contact)."""
    from .. import config

    base = config.load(preset, "draft")

    def run(l0: float, numerics: Numerics, trim: bool = True) -> Outcome:
        kw = base.crown_kwargs()
        kw.update(l0=l0, numerics=numerics, trim=trim)
        if t_end is not None:
            kw["t_end"] = t_end
        from ..scenes import crown
        scene = crown(**kw)
        sim = simulator(scene)
        U, D, h, gap = kw["speed"], kw["drop"], kw["film"], kw["gap"]
        t_contact = gap / U
        frames = np.linspace(0, kw["t_end"], 9)[1:]
        ratios: List[float] = []

        def sample(s, i):
            t = s.stats.time - t_contact
            if t * U / D <= 0.25:
                return
            snap = s.snapshot()
            m = crown_measure(snap["pos"][snap["kind"] == FLUID], s.stats.time, h, D, l0)
            ratios.append(m.base_radius / crown_base_radius(t, U, D, h))
        sim.run(kw["t_end"], frame_times=frames, on_frame=sample)
        r = float(np.mean(ratios)) if ratios else math.nan
        return Outcome(r, 1.0, abs(r - 1), sim, {"frames": len(ratios)})

    l0 = base.l0      # the draft's spacing: the coarsest that keeps 3 particles across the film
    return Case(f"crown-base-{preset}", 3, "crown base radius / Yarin-Weiss, mean over frames",
                "Yarin & Weiss 1995 (method.md §7)", "D/l0",
                tuple(round(base.scene["drop"] / (f * l0), 2) for f in refine),
                (round(base.scene["drop"] / l0, 2),),
                lambda s: base.scene["drop"] / s, run, variants=variants)


# The variant each case runs in `--quick`. Between them the quick set runs every variant of the
# reference cases once (f64 on a small 2D case: it restarts the backend, which compiles
# again); the 3D cases take safety/2 where they have it, which changes no compiled term, so
# the run reuses the base run's compiled simulator (a 3D model compiles in 15-18 s on 2 cores
# even with --fast-compile). None: no variant, where its only variants would compile a model
# again for a setting another row checks (plane-floor: hydrostatic-2d; f64: shear-wave-2d),
# which kept a first `--quick` (an empty Taichi cache) past 5 minutes (issue 26). Not in the
# quick set: the crown's untrimmed film (11 times the particles) and its Courant limit on
# relative speeds (another 3D model; the stability suite's -relative cases run it in 2D), and
# the 3D stress drops' lattice start (another minute of 3D drop; the full suite runs it), the
# oscillating drops' viscosity=laplacian (another model; tests/test_viscosity.py holds
# the member), and the stress drops' re=3.1 (another model; tests/test_stress_neighbourhoods.py
# runs the 2D resting drop there).
QUICK_VARIANT = {"hydrostatic-2d": "plane-floor", "hydrostatic-3d": "safety/2",
                 "dam-break-2d": "gradient=sum", "dam-break-3d": "safety/2",
                 "drop-oscillation-2d": "gradient=seed", "drop-oscillation-3d": "safety/2",
                 "laplace-2d": None, "laplace-3d": "safety/2",
                 "shear-wave-2d": "f64", "shear-wave-3d": "safety/2",
                 "sliding-layer-2d": None, "sliding-layer-3d": None,
                 "crown-base-quick": "safety/2",
                 # the surface-stress model's drops (tension_cases.py): the quick set checks
                 # one other gradient form, on the free drop (each form compiles a model)
                 "stress-laplace-2d": None, "stress-laplace-3d": None,
                 "stress-drop-oscillation-2d": None, "stress-drop-oscillation-3d": None,
                 "stress-free-drop-2d": "gradient=pmin", "stress-free-drop-3d": None}


def all_cases(full: bool = True) -> Dict[str, Case]:
    cases = [make(d) for make in (_hydrostatic, _dam_break, _oscillation, _laplace, _shear_wave,
                         _sliding_layer)
             for d in (2, 3)]
    cases.append(crown_case("quick"))
    from .tension_cases import tension_cases
    cases += tension_cases()
    cases = [replace(c, quick_variant=QUICK_VARIANT.get(c.name, "")) for c in cases]
    if full:
        # the seed's first run, to 1 ms (the drafts' 2 ms at the finest spacing would take
        # most of an hour on 2 cores); its settings variants are those of crown-base-quick
        cases.append(crown_case("3m-drop", t_end=1.0e-3, refine=(1.0, 0.85, 0.7), variants=()))
    return {c.name: c for c in cases}


def variant_scene(variant: str) -> Dict[str, object]:
    """The keyword arguments a settings variant passes to its case's run (its scene): the
    crown's film not trimmed (``untrimmed``), the surface-stress drops on the lattice
    (``lattice``; tension_cases.DISORDER) or at re = X l0 (``re=X``; tension_cases.WIDE)."""
    if variant.startswith("re="):      # another neighbourhood re/l0 (the stress drops)
        return {"re_ratio": float(variant.split("=", 1)[1])}
    return {"untrimmed": {"trim": False}, "lattice": {"disorder": 0.0}}.get(variant, {})


def variant_numerics(variant: str, numerics: Numerics) -> Numerics:
    """The Numerics of a settings variant (its precision: the runner; its scene: variant_scene)."""
    if variant == "safety/2":
        return replace(numerics, courant=numerics.courant / 2, acoustic=numerics.acoustic / 2)
    if variant.startswith("gradient="):
        return replace(numerics, pressure_gradient=variant.split("=", 1)[1])
    if variant.startswith("viscosity="):   # the viscosity member (core/viscosity.py)
        return replace(numerics, viscosity=variant.split("=", 1)[1])
    if variant == "surface-pairs":      # the stress member's surface pairs (C3b), corrected form
        return replace(numerics, stress_pairs="surface", pressure_gradient="corrected")
    if variant == "plane-floor":        # the analytic floor instead of its particle layers
        return replace(numerics, wall_model="plane")
    if variant == "relative-courant":   # the crown presets' Courant limit (core/terms.py)
        return replace(numerics, courant_speed="relative")
    return numerics
