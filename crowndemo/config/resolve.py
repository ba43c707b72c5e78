"""From a validated preset and a quality to what runs: the keywords of
``crowndemo.scenes.crown(...)``, the Numerics, and the checks that relate several values
(speed or height, the drop against the container, l0 against the film and the drop, the time
step the speed leaves). Nothing here starts Taichi."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Dict, List, Optional, Tuple

from ..core import timestep
from ..core.health import starts_too_fast
from ..core.params import Model, Numerics, ParameterError, Physics
from .errors import MISSING, PresetError
from .loader import Document
from .merge import DEFAULT_SOURCE
from .schema import LIQUIDS, QUALITIES, SCENE_KEYS, dotted, validate
from .sound_speed import FACTOR_RANGE, sound_speed
from ..core.symmetry import planes_of

if TYPE_CHECKING:
    from ..scenes.base import Scene

SPEED_MAX = 50.0        # m/s: beyond this the explicit step is not meant to serve
DT_FLOOR = 1.0e-8       # s: a time step below this is refused (billions of steps)
MIN_ACROSS = 3          # particles across the film and across the drop
MAX_FRAMES = 100_000    # frames a run may plan: an hour of video at 30 frames/s
SAFETY_LIMITS = ("courant", "approach", "acoustic", "viscous", "capillary")   # dt ~ the number
# estimate.rough_total is 0.84-1.03 of the scene's particle count (every preset at every
# quality, 2026-11-23): past this many times the limit a scene is refused before it is built
ROUGH_MARGIN = 1.1


@dataclass
class Resolved:
    """One preset at one quality, ready to build: every value and where it came from."""
    doc: Document
    quality: str
    values: dict                      # the validated document, defaults filled in
    dim: int
    l0: float
    scene: dict                       # floor, film, drop, speed, height, gap, gravity, t_end, ...
    liquid: dict                      # name, rho, nu, sigma
    numerics: Numerics
    physics: Physics
    model: Model
    where: Dict[str, Tuple[str, str]] = field(default_factory=dict)  # value -> (key, source)

    @property
    def name(self) -> str:
        return self.doc.name

    @property
    def label(self) -> str:
        return self.doc.label

    @property
    def title(self) -> dict:
        return self.values["title"]

    @property
    def description(self) -> dict:
        return self.values.get("description", {})

    @property
    def speed(self) -> float:
        return self.scene["speed"]

    @property
    def t_end(self) -> float:
        return self.scene["t_end"]

    def crown_kwargs(self) -> dict:
        """The keywords of ``crowndemo.scenes.crown`` (numerics included)."""
        s = self.scene
        return dict(dim=self.dim, l0=self.l0, film=s["film"], drop=s["drop"], speed=s["speed"],
                    gap=s["gap"], floor=s["floor"], t_end=s["t_end"], trim=s["trim"],
                    numerics=self.numerics, rho=self.liquid["rho"], nu=self.liquid["nu"],
                    sigma=self.liquid["sigma"], gravity=s["gravity"],
                    sound_speed=s.get("sound_speed"), re_ratio=s["re_ratio"],
                    symmetry=s["symmetry"], trim_reach=s["trim_reach"])

    def build_scene(self, l0: Optional[float] = None) -> Scene:
        """The particles (numpy only); ``l0`` builds the same scene at another spacing."""
        from ..scenes import crown
        kw = self.crown_kwargs()
        if l0 is not None:
            kw["l0"] = l0
        if l0 is None:      # far too many particles: say so before numpy builds them
            from .estimate import rough_total
            rough = rough_total(self)
            if rough > ROUGH_MARGIN * self.max_particles():
                self.check_size(int(rough), about=True)
        scene = crown(**kw)
        if l0 is None:
            self.check_size(len(scene.pos))
        return scene

    def max_particles(self) -> int:
        from ..core.step import max_particles
        return max_particles(self.model)

    def check_size(self, particles: int, about: bool = False) -> None:
        """PresetError on the l0 key when the scene has more particles than one simulator
        holds (``core.step.max_particles``: Taichi's 32-bit field indices), before any kernel
        runs."""
        limit = self.max_particles()
        if particles > limit:
            key, source = self.where["l0"]
            need = self.l0 * (particles / limit) ** (1.0 / self.dim)
            raise PresetError(source, key, self.l0,
                              f"the scene would hold {'about ' if about else ''}{particles:,} "
                              f"particles, more than the {limit:,} that one simulator holds "
                              f"in {self.dim}D (Taichi indexes a field with 32-bit integers)",
                              f">= {'about ' if about else ''}{need * 1.001:.4g} m")

    def frame_times(self) -> List[float]:
        """Frame times strictly inside (0, t_end], every frame_interval; [] without one."""
        fi = self.scene.get("frame_interval")
        if not fi:
            return []
        n = int(math.floor(self.t_end / fi + 1e-9))
        return [k * fi for k in range(1, n + 1)]

    def limits(self, speed: Optional[float] = None) -> Dict[str, float]:
        return timestep.limits(self.physics, self.numerics, self.model,
                               self.speed if speed is None else speed)

    def dt(self) -> Tuple[float, str]:
        return timestep.choose(self.physics, self.numerics, self.model, self.speed)


def resolve(doc: Document, quality: str) -> Resolved:
    """Validate the document and resolve it at ``quality``; PresetError on the first mistake."""
    values = validate(doc)
    where: Dict[str, Tuple[str, str]] = {}

    def fail(name: str, value, why: str, allowed: str):
        key, source = where.get(name, (name, DEFAULT_SOURCE))
        if source == DEFAULT_SOURCE:      # nobody set it: the fix goes into this file
            source = doc.label
        raise PresetError(source, key, value, why, allowed)

    def note(name: str, path) -> None:
        where[name] = (dotted(path), doc.writer_of(path))

    rungs = values["quality"]
    if quality not in rungs:
        defined = [q for q in QUALITIES if q in rungs]
        why = ("this preset defines no quality rung" if not defined else
               "this preset defines no such quality rung")
        allowed = (", ".join(defined) if defined else
                   "add quality: {draft: {l0: ...}} (rungs: " + ", ".join(QUALITIES) + ")")
        raise PresetError(doc.missing_source(("quality", quality)), f"quality.{quality}",
                          MISSING, why, allowed)
    rung = rungs[quality]
    rpath = ("quality", quality)

    # scene values, then the rung's where it is at least as specific as the scene's
    scene = dict(values["scene"])
    for k in scene:
        note(k, ("scene", k))
    for k in ("t_end", "frame_interval", "symmetry", "trim_reach"):
        if k in rung and doc.rank_of(rpath + (k,)) >= doc.rank_of(("scene", k)):
            scene[k] = rung[k]
            note(k, rpath + (k,))
    num = dict(values.get("numerics", {}))
    for k in num:
        note("numerics." + k, ("numerics", k))
    for k, v in rung.get("numerics", {}).items():
        if doc.rank_of(rpath + ("numerics", k)) >= doc.rank_of(("numerics", k)):
            num[k] = v
            note("numerics." + k, rpath + ("numerics", k))
    l0 = rung["l0"]
    note("l0", rpath + ("l0",))
    dim = values["dim"]

    # speed or height
    if "speed" in scene and "height" in scene:
        fail("height", scene["height"], "give scene.speed or scene.height, not both",
             f"one of them (scene.speed = {scene['speed']:g} m/s is also given)")
    if "height" in scene:
        H, g = scene["height"], scene["gravity"]
        if g <= 0:
            fail("height", H, "a fall height needs gravity (U = sqrt(2 g H)) but "
                 "scene.gravity = 0", "scene.speed instead, or scene.gravity > 0")
        U = math.sqrt(2.0 * g * H)
        if U > SPEED_MAX:
            fail("height", H, f"gives U = sqrt(2 g H) = {U:.4g} m/s, faster than the explicit "
                 "step is meant to serve", f"<= {SPEED_MAX ** 2 / (2 * g):.4g} m "
                 f"(U <= {SPEED_MAX:g} m/s)")
        scene["speed"] = U
        where["speed"] = where["height"]
    elif "speed" not in scene:
        raise PresetError(_speed_source(doc), "scene.speed", MISSING, "no impact speed: give "
                          "scene.speed [m/s] or scene.height [m]", SCENE_KEYS["speed"].allowed())

    # geometry
    if scene["drop"] >= scene["floor"]:
        fail("drop", scene["drop"], "the drop is wider than the container floor",
             f"< scene.floor = {scene['floor']:g} m")
    if scene.get("frame_interval") is not None and scene["frame_interval"] > scene["t_end"] * (
            1 + 1e-9):
        fail("frame_interval", scene["frame_interval"], "longer than the run",
             f"<= t_end = {scene['t_end']:g} s")
    if scene.get("frame_interval") and scene["t_end"] / scene["frame_interval"] > MAX_FRAMES:
        fi, t_end = scene["frame_interval"], scene["t_end"]
        fail("frame_interval", fi, f"{t_end:g} s / {fi:g} s would plan {t_end / fi:.3g} "
             f"frames, more than {MAX_FRAMES:,}", f">= t_end / {MAX_FRAMES:,} = "
             f"{t_end / MAX_FRAMES * 1.0001:.4g} s")
    for what, name, size in (("film", "film", scene["film"]), ("drop", "drop", scene["drop"])):
        across = size / l0
        if math.floor(across + 1e-9) < MIN_ACROSS:
            sym = "h" if name == "film" else "D"
            fail("l0", l0, f"too coarse: {across:.3g} particles across the {what} "
                 f"({sym} = {size:g} m), at least {MIN_ACROSS} are needed",
                 f"<= {sym}/{MIN_ACROSS} = {size / MIN_ACROSS:.4g} m")

    # liquid
    liq = dict(values["scene"]["liquid"])
    name = liq.pop("name", "water")
    liquid = {"name": name, **LIQUIDS[name], **liq}

    # the sound speed: c = k v_max (S8), k = scene.sound_speed_factor (config/sound_speed.py),
    # v_max the scene's largest speed scale: U, or the fall or capillary speed of a slow drop
    derived = None        # c given; else what k multiplies: "speed", "fall" or "capillary"
    k = scene["sound_speed_factor"]
    if scene.get("sound_speed") is None:
        floor, which = slow_speed_floor(dim, l0, scene, liquid)
        if floor > scene["speed"]:
            scene["sound_speed"] = sound_speed(k, floor)
            scene["sound_speed_source"] = (f"{k:g} x the {which} speed {floor:.3g} m/s, above "
                                           f"U = {scene['speed']:.3g} m/s")
            where["sound_speed"] = where["speed"]
        else:
            scene["sound_speed"] = sound_speed(k, scene["speed"])
            scene["sound_speed_source"] = f"{k:g} x speed"
            where["sound_speed"] = where["sound_speed_factor"]
        derived = which if floor > scene["speed"] else "speed"

    # symmetry planes through the drop's axis (core/symmetry.py): 2D has the plane x = 0 only
    try:
        planes = planes_of(scene["symmetry"], dim)
    except ValueError:
        fail("symmetry", scene["symmetry"], f"a {dim}D scene has {dim - 1} symmetry plane(s) "
             "through the drop's axis", "full or half" + (" or quarter" if dim == 3 else ""))

    # the core's own checks (the schema's ranges make these pass; kept as a safety net)
    try:
        numerics = Numerics(**num, mirror_planes=planes).validate()
    except ParameterError as e:
        fail("numerics." + e.key, e.value, "refused by the solver", e.allowed)
    physics_keys = {"l0": "l0", "v_max": "speed", "re_ratio": "re_ratio",
                    "sound_speed": "sound_speed", "gravity": "gravity"}
    try:
        physics = Physics(dim=dim, l0=l0, v_max=scene["speed"], re_ratio=scene["re_ratio"],
                          rho=liquid["rho"], nu=liquid["nu"], sigma=liquid["sigma"],
                          gravity=scene["gravity"],
                          sound_speed=scene.get("sound_speed")).validate()
    except ParameterError as e:
        if e.key in physics_keys and physics_keys[e.key] in where:
            fail(physics_keys[e.key], e.value, "refused by the solver", e.allowed)
        raise PresetError(doc.label, f"scene.liquid.{e.key}", e.value, "refused by the solver",
                          e.allowed) from None
    try:
        model = Model.of(physics, numerics)
    except ParameterError as e:      # the stress member at an re it has no constants for
        if e.key == "stress_pairs":  # or its surface pairs (C3b)
            fail("numerics.stress_pairs", e.value, "the stress model's surface pairs (C3b) "
                 "are calibrated at one neighbourhood only (method.md §4c)", e.allowed)
        fail(e.key, e.value, "the stress model's constants (C4's factor, C5's delta) are "
             "measured at two neighbourhoods only (method.md §4c)", e.allowed)
    _check_mach(scene, numerics, physics, fail, where, derived)

    # the time step
    lim = timestep.limits(physics, numerics, model, scene["speed"])
    dt_name = min(lim, key=lim.get)
    dt = lim[dt_name]
    if dt < DT_FLOOR and numerics.fixed_dt is None:
        why = (f"the time step would be {dt:.3g} s (bound by the {dt_name} limit), below "
               f"{DT_FLOOR:g} s")
        given = getattr(numerics, dt_name, None) if dt_name in SAFETY_LIMITS else None
        default = getattr(Numerics(), dt_name, None)
        if "numerics." + dt_name in where and given and dt * default / given >= DT_FLOOR:
            # the preset's own safety number is what shrinks dt (each limit is linear in it)
            fail("numerics." + dt_name, given, why, f">= {given * DT_FLOOR / dt * 1.001:.4g} "
                 f"here (default {default:g})")
        if dt_name in ("courant", "approach"):
            fail("speed", scene.get("height", scene["speed"]), why,
                 f"U <= {getattr(numerics, dt_name) * l0 / DT_FLOOR:.4g} m/s at l0 = {l0:g} m")
        elif dt_name == "acoustic" and derived in ("fall", "capillary"):
            # c from the slow drop's floor: the capillary speed falls as 1/sqrt(l0)
            c = scene["sound_speed"]
            need = (DT_FLOOR * c / numerics.acoustic if derived == "fall" else
                    (DT_FLOOR * c * math.sqrt(l0) / numerics.acoustic) ** (2.0 / 3.0))
            fail("l0", l0, f"{why}; c = {scene['sound_speed_source']}",
                 f">= {need * 1.001:.4g} m")
        elif dt_name == "acoustic" and derived is None:
            fail("sound_speed", scene["sound_speed"], why,
                 f"<= {numerics.acoustic * l0 / DT_FLOOR:.4g} m/s at l0 = {l0:g} m")
        elif dt_name == "acoustic":
            k_max = numerics.acoustic * l0 / (scene["speed"] * DT_FLOOR)
            if k_max >= FACTOR_RANGE[0]:
                fail("sound_speed_factor", k, why, f"<= {k_max:.4g} at U = "
                     f"{scene['speed']:.4g} m/s and l0 = {l0:g} m (c = k U)")
            u_max = numerics.acoustic * l0 / (k * DT_FLOOR)
            fail("speed", scene.get("height", scene["speed"]), why,
                 f"U <= {u_max:.4g} m/s at l0 = {l0:g} m (c = {k:g} U)")
        elif dt_name == "viscous":
            need = timestep.l0_at_dt("viscous", physics, numerics, DT_FLOOR)
            fail("l0", l0, why, f">= {need:.3g} m at nu = {liquid['nu']:g} m^2/s")
        elif dt_name == "capillary":
            need = timestep.l0_at_dt("capillary", physics, numerics, DT_FLOOR)
            fail("l0", l0, why, f">= {need:.3g} m at sigma = {liquid['sigma']:g} N/m")
        else:
            fail("numerics.dt_max", numerics.dt_max, why, f">= {DT_FLOOR:g} s")
    try:
        timestep.check_fixed_dt(physics, numerics, model)
    except ParameterError as e:
        fail("numerics.fixed_dt", e.value, "breaks a time-step limit", e.allowed)

    return Resolved(doc, quality, values, dim, l0, scene, liquid, numerics, physics, model, where)


def slow_speed_floor(dim: int, l0: float, scene: dict, liquid: dict) -> Tuple[float, str]:
    """The speeds a drop on a film reaches whatever its impact speed U (m/s), which c = 5 U
    would not cover when U is small: the fall, sqrt(2 g (gap + D)) (a drop let go at the
    gap, its top falling a diameter more as it lands), and the capillary speed
    sqrt(P_coh / rho) of the surface-tension potential, whose cohesive stress P_coh
    (2.25 sigma/l0 in 2D at re = 2.1 l0) the equation of state must balance inside the
    liquid. With c = 5 U alone a 0.5 m/s drop at l0 = 0.1 mm (c = 2.5 m/s) was compressed
    26 % by that stress and went unstable at its 6th step. No shipped preset reaches this
    floor (tests/test_presets.py), so their c stays k U. Returns the larger and its name."""
    from ..core.lattice import LatticeConstants, lattice_cohesion_pressure
    fall = math.sqrt(2.0 * scene["gravity"] * (scene["gap"] + scene["drop"]))
    capillary = 0.0
    if liquid["sigma"] > 0:
        lat = LatticeConstants.compute(dim, l0, scene["re_ratio"], liquid["rho"],
                                       liquid["sigma"])
        cohesion = -lattice_cohesion_pressure(dim, l0, lat.re, lat.C)
        capillary = math.sqrt(max(cohesion, 0.0) / liquid["rho"])
    return max((fall, "fall"), (capillary, "capillary"))


def _speed_source(doc: Document) -> str:
    """Whom to name when there is no impact speed: whoever removed speed or height."""
    for key in ("speed", "height"):
        source = doc.missing_source(("scene", key))
        if source != doc.label:
            return source
    return doc.label


def _check_mach(scene: dict, numerics: Numerics, physics: Physics, fail, where: dict,
                derived: Optional[str] = None) -> None:
    """The run stops as soon as a particle is faster than max_mach * c (core.health), and the
    drop starts at U and gains speed as it falls: max_mach * c must exceed U. ``derived``:
    None when scene.sound_speed gives c, else what scene.sound_speed_factor multiplies."""
    U, c, mach = scene["speed"], physics.c, numerics.max_mach
    if not starts_too_fast(U, c, mach):
        return
    why = (f"the run would stop at its first step: it stops when a particle is faster than "
           f"numerics.max_mach * c = {mach:g} x {c:.4g} m/s, and the drop starts at "
           f"U = {U:.4g} m/s")
    if derived is None:
        fail("sound_speed", c, why, f"> U / max_mach = {U / mach:.4g} m/s")
    k = scene["sound_speed_factor"]
    if derived == "speed" and "numerics.max_mach" not in where and \
            1.0 / mach <= FACTOR_RANGE[1]:     # the preset's own k is too small: name it
        fail("sound_speed_factor", k, why, f"> 1 / max_mach = {1.0 / mach:.4g} (c = k U)")
    fail("numerics.max_mach", mach, why,
         f"> U / c = {U / c:.4g} (c = scene.sound_speed_factor x U unless scene.sound_speed "
         "is set or U is below the fall and capillary speeds)")


__all__ = ["Resolved", "resolve", "slow_speed_floor", "SPEED_MAX", "DT_FLOOR", "MIN_ACROSS"]
