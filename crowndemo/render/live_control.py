"""Live mode's logic, with no window: slider values (fall height, film thickness, drop size)
-> ``--set`` overrides of a preset -> a resolved, validated preset (crowndemo.config) -> a
restarted run, stepped a little per displayed frame.

The run is started by one callable, ``start(resolved) -> simulator``: by default
``session_starter()``, which loads the scene into one ``crowndemo.control.Session``, so a
restart with the same compiled model reuses the simulator, its kernels and its fields.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Callable, Dict, List, Optional, Tuple

from .. import config
from ..config import PresetError
from ..core.health import InstabilityError

DEFAULT_PRESET = "quick-2d"     # 2D draft: a few thousand particles, live on a CPU
QUALITY = "draft"
HEIGHT_RANGE = (0.05, 3.0)      # m: the booth's range of fall heights


@dataclass(frozen=True)
class Slider:
    name: str                   # height, film or drop
    key: str                    # the preset key it sets
    label: Dict[str, str]
    lo: float                   # SI
    hi: float
    unit: str                   # shown unit
    scale: float                # shown value = SI value * scale

    def clamp(self, value: float) -> float:
        return min(self.hi, max(self.lo, float(value)))


def session_starter() -> Callable:
    """``start(resolved) -> simulator`` through one control Session (kernels reused)."""
    from ..control import Session
    session = Session()
    return lambda resolved: session.load(resolved.build_scene())


def preset_height(base: config.Resolved) -> float:
    """The fall height of a resolved preset: its scene.height, else U^2 / (2 g) (inf
    without gravity, which live mode refuses)."""
    s, g = base.scene, base.scene["gravity"]
    return s.get("height", s["speed"] ** 2 / (2 * g) if g > 0 else math.inf)


def unstable_advice(e: InstabilityError) -> str:
    """The panel's line for a run that went unstable: when, what broke, and which sliders
    help (a thin film under a big drop from high up threw a splash faster than c at the
    seed's c = 5 U)."""
    return (f"unstable at t = {e.time * 1e3:.3g} ms: {e.what}; try a thicker film, a smaller "
            "drop or a lower fall height")


def sliders_for(base: config.Resolved) -> Tuple[Slider, ...]:
    """The sliders' ranges for a resolved base preset: film and drop at least 3 particle
    spacings across (what the config layer demands), the drop narrower than half the floor."""
    s, l0 = base.scene, base.l0
    # the booth's range of heights, reaching up to the preset's own (3.26 m for 8 m/s)
    height = (HEIGHT_RANGE[0], max(HEIGHT_RANGE[1], preset_height(base)))
    film = (3 * l0, max(4 * s["film"], 6 * l0))
    drop = (max(3 * l0, 0.5 * s["drop"]), min(2 * s["drop"], 0.5 * s["floor"]))
    return (Slider("height", "scene.height", {"en": "fall height", "ja": "落下高さ"},
                   *height, "m", 1.0),
            Slider("film", "scene.film", {"en": "film thickness", "ja": "水膜の厚さ"},
                   *film, "mm", 1e3),
            Slider("drop", "scene.drop", {"en": "drop diameter", "ja": "水滴の直径"},
                   *drop, "mm", 1e3))


def overrides(values: Dict[str, float], sliders: Tuple[Slider, ...]) -> List[str]:
    """The ``--set`` items for slider values (SI); the height replaces the preset's speed."""
    items = ["scene.speed="]                    # empty: removed, so height gives the speed
    items += [f"{s.key}={values[s.name]!r}" for s in sliders]
    return items


class LiveController:
    """Holds the slider values and the live run. ``drop()`` restarts the run with the current
    values; ``advance(seconds)`` steps it for about that much wall time."""

    def __init__(self, preset: str = DEFAULT_PRESET, quality: str = QUALITY,
                 start: Optional[Callable] = None, sets: Optional[List[str]] = None):
        self.preset, self.quality = preset, quality
        self.start = start or session_starter()
        self.sets = list(sets or [])
        self.base = config.load(preset, quality, self.sets)
        self.sliders = sliders_for(self.base)
        g = self.base.scene["gravity"]
        if g <= 0:
            raise PresetError(self.base.label, "scene.gravity", g,
                              "live mode sets a fall height, which needs gravity", "> 0")
        s = self.base.scene
        self.values = {"height": preset_height(self.base),
                       "film": s["film"], "drop": s["drop"]}
        for sl in self.sliders:
            self.values[sl.name] = sl.clamp(self.values[sl.name])
        self.resolved = None
        self.sim = None
        self.runs = 0
        self.status = "press Drop"
        self.error: Optional[str] = None
        self.unstable = False

    def set(self, name: str, value: float) -> float:
        """Set a slider (SI units), clamped to its range; returns the value kept."""
        slider = next((s for s in self.sliders if s.name == name), None)
        if slider is None:
            raise KeyError(f"no slider {name!r}; sliders: "
                           + ", ".join(s.name for s in self.sliders))
        self.values[name] = slider.clamp(value)
        return self.values[name]

    def resolve(self) -> config.Resolved:
        """The preset with the slider values, validated (PresetError on a mistake)."""
        return config.load(self.preset, self.quality,
                           self.sets + overrides(self.values, self.sliders))

    def drop(self, raise_errors: bool = False) -> bool:
        """Restart the run with the current values; False (and ``error`` set) when the
        values are refused, the previous run then going on (or PresetError with
        ``raise_errors``)."""
        try:
            resolved = self.resolve()
        except PresetError as e:
            if raise_errors:
                raise
            self.error = str(e)
            return False
        self.sim = self.start(resolved)
        self.resolved = resolved
        self.runs += 1
        self.error, self.unstable = None, False
        self.status = f"U = {resolved.speed:.3g} m/s"
        return True

    @property
    def time(self) -> float:
        return self.sim.stats.time if self.sim is not None else 0.0

    @property
    def finished(self) -> bool:
        return self.sim is None or self.unstable or \
            self.time >= self.resolved.t_end * (1 - 1e-9)

    def advance(self, seconds: float) -> int:
        """Step the run for about ``seconds`` of wall time (at least one step unless it has
        finished); returns the steps taken."""
        if self.finished:
            return 0
        end, steps = time.perf_counter() + seconds, 0
        try:
            while True:
                self.sim.step(dt_cap=self.resolved.t_end - self.sim.stats.time)
                steps += 1
                if self.finished or time.perf_counter() >= end:
                    break
        except InstabilityError as e:
            self.status, self.error, self.unstable = "unstable", unstable_advice(e), True
        return steps


__all__ = ["LiveController", "Slider", "sliders_for", "overrides", "session_starter",
           "preset_height", "unstable_advice",
           "DEFAULT_PRESET", "HEIGHT_RANGE"]
