"""What colour a particle gets: the colour fields, their fixed scales, the colour map.

Scales are fixed for a whole run (not stretched frame by frame) so that a colour means the same
thing in every frame: speed over [0, U], height over [0, h + D], pressure over [0, rho U^2];
``milk`` is a white-ish colour, slightly brighter with height, that the lighting shades.
The caption's colour key (render/captions.py) shows the scale's ends.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MODES = ("speed", "height", "pressure", "milk")
MODE_CODE = {m: i for i, m in enumerate(MODES)}
DEFAULT_MODE = "speed"

# colour map stops, low -> high: blue, cyan, green, yellow, red (bright ends on a dark ground)
COLOUR_MAP = np.array([[0.15, 0.35, 0.85], [0.10, 0.70, 0.90], [0.35, 0.85, 0.45],
                       [0.98, 0.80, 0.20], [0.90, 0.25, 0.10]], dtype=np.float32)
MILK_LOW = (0.86, 0.85, 0.81)      # milk at the floor
MILK_HIGH = (1.00, 0.99, 0.95)     # milk at the top of the height scale
UNITS = {"speed": "m/s", "height": "m", "pressure": "Pa", "milk": "m"}
FIELD_MODES = ("speed", "pressure")   # modes read from a field interpolated to the vertices


def fields_read(mode: str) -> tuple:
    """The particle fields a surface coloured by ``mode`` needs at its vertices: height and
    milk read the vertices' own height, so none (interpolating the two fields took ~40 % of
    a booth frame's reconstruction, BENCHMARKS.md)."""
    return (mode,) if mode in FIELD_MODES else ()


@dataclass(frozen=True)
class ColourScale:
    mode: str
    lo: float
    hi: float

    @property
    def code(self) -> int:
        return MODE_CODE[self.mode]

    @classmethod
    def for_scene(cls, mode: str, speed: float, film: float, drop: float,
                  rho: float) -> "ColourScale":
        if mode not in MODES:
            raise ValueError(f"colour {mode!r} is not one of {', '.join(MODES)}")
        hi = {"speed": speed, "height": film + drop, "pressure": rho * speed ** 2,
              "milk": film + drop}[mode]
        return cls(mode, 0.0, hi)


def colour_map(t: np.ndarray) -> np.ndarray:
    """The colour map at t in [0, 1] (clipped), numpy; the kernel does the same."""
    t = np.clip(np.asarray(t, float), 0.0, 1.0) * (len(COLOUR_MAP) - 1)
    i = np.minimum(t.astype(int), len(COLOUR_MAP) - 2)
    f = (t - i)[..., None]
    return COLOUR_MAP[i] * (1 - f) + COLOUR_MAP[i + 1] * f


def vertex_colours(scale: ColourScale, height: np.ndarray, fields: dict) -> np.ndarray:
    """Per-vertex colours (V x 3 float32) of a surface: the mode's value from the fields
    interpolated to the vertices (speed, pressure) or the vertices' ``height``."""
    value = np.asarray(fields[scale.mode] if scale.mode in FIELD_MODES else height,
                       float)
    span = scale.hi - scale.lo
    t = (value - scale.lo) / span if span > 0 else np.zeros_like(value)
    if scale.mode == "milk":
        t = np.clip(t, 0.0, 1.0)[:, None]
        return (np.float32(MILK_LOW) * (1 - t) + np.float32(MILK_HIGH) * t).astype(np.float32)
    return colour_map(t).astype(np.float32)


__all__ = ["MODES", "DEFAULT_MODE", "FIELD_MODES", "fields_read", "COLOUR_MAP", "MILK_LOW",
           "MILK_HIGH", "ColourScale", "colour_map", "vertex_colours"]
