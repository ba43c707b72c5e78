"""What a preset may contain: every key, its type, unit, allowed range and default.

A preset (SI units throughout; lengths in m, times in s, speeds in m/s)::

    title:       {en: ..., ja: ...}        # or one string (English)
    description: {en: ..., ja: ...}
    extends:     OTHER                     # optional; handled by the loader
    dim:         3                         # 3, or 2 for a cross-section (a cylinder-drop slice)
    scene:       {floor, film, drop, speed | height, gap, liquid, gravity, t_end,
                  frame_interval, trim, re_ratio, sound_speed_factor, sound_speed,
                  trim_reach, symmetry}
    numerics:    {courant, acoustic, ...}  # overrides of crowndemo.core.params.Numerics
    quality:     {draft: RUNG, booth: RUNG, seed: RUNG}
    RUNG:        {l0, t_end, frame_interval, symmetry, trim_reach, numerics}

``validate`` checks one value at a time (unknown key, type, missing value, range) and returns
the document with defaults filled in; checks that relate several values live in ``resolve``.
"""
from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from typing import Any, Dict, Iterable, Optional, Tuple

from ..core.params import (COURANT_SPEEDS, GRADIENT_FORMS, GRAVITY, STRESS_PAIRS,
                           SURFACE_TENSION_MODELS, VISCOSITY_MODELS, WALL_MODELS, WATER)
from ..core.symmetry import SYMMETRIES
from .errors import MISSING, PresetError, did_you_mean
from .loader import Document
from .sound_speed import DEFAULT_FACTOR, FACTOR_RANGE

QUALITIES = ("draft", "booth", "seed")
LANGUAGES = ("en", "ja")

# Named liquids. water: the seed's values (docs/method.md §6). milk: typical whole milk
# near 20 C (density 1030 kg/m^3, viscosity about 2 mPa s, surface tension about 0.045 N/m);
# approximate, they vary with fat content and temperature.
LIQUIDS: Dict[str, Dict[str, float]] = {
    "water": dict(WATER),
    "milk": {"rho": 1030.0, "nu": 2.0e-6, "sigma": 0.045},
}


@dataclass(frozen=True)
class Field:
    kind: str                    # number | int | bool | choice | text | liquid | map
    doc: str = ""
    unit: str = ""
    lo: Optional[float] = None
    lo_incl: bool = False        # lo itself allowed?
    hi: Optional[float] = None
    hi_incl: bool = True
    choices: Tuple = ()
    required: bool = False
    default: Any = None
    keys: Optional[Dict[str, "Field"]] = None
    allow_inf: bool = False

    def in_range(self, v: float) -> bool:
        """Whether the number ``v`` lies within lo and hi (each end as the field says)."""
        low = self.lo is not None and (v < self.lo or (v == self.lo and not self.lo_incl))
        high = self.hi is not None and (v > self.hi or (v == self.hi and not self.hi_incl))
        return not (low or high)

    def allowed(self) -> str:
        if self.kind in ("number", "int"):
            parts = []
            if self.lo is not None:
                parts.append(f"{'>=' if self.lo_incl else '>'} {self.lo:g}")
            if self.hi is not None:
                parts.append(f"{'<=' if self.hi_incl else '<'} {self.hi:g}")
            text = " and ".join(parts) or "any finite number"
            if self.kind == "int":
                text = f"an integer {text}"
            if self.unit:
                text += f" {self.unit}"
            if self.allow_inf:
                text += " (.inf: no limit)"
            return text
        if self.kind == "bool":
            return "true or false"
        if self.kind == "choice":
            return " or ".join(str(c) for c in self.choices)
        if self.kind == "text":
            return "a string, or {en: ..., ja: ...}"
        if self.kind == "liquid":
            return (f"a liquid name ({', '.join(LIQUIDS)}) or a mapping "
                    "{name:, rho:, nu:, sigma:}")
        return "a mapping with keys " + ", ".join(self.keys or ())


def number(doc: str, unit: str = "", lo: Optional[float] = None, hi: Optional[float] = None,
           lo_incl: bool = False, hi_incl: bool = True, **kw: Any) -> Field:
    return Field("number", doc, unit, lo, lo_incl, hi, hi_incl, **kw)


TEXT = Field("text", "a text in English (en) and Japanese (ja)")

LIQUID_KEYS = {
    "name": Field("choice", "a named liquid whose values the other keys override",
                  choices=tuple(LIQUIDS), default="water"),
    # liquids (about 700-13,600 kg/m^3); a far lighter one makes the capillary speed, and so
    # the sound speed and time step of a slow drop (config/resolve.py), meaningless
    "rho": number("density", "kg/m^3", 100, 25000, lo_incl=True),
    "nu": number("kinematic viscosity (0: no viscosity term)", "m^2/s", 0, 0.1, lo_incl=True),
    "sigma": number("surface tension (0: no surface-tension term)", "N/m", 0, 1, lo_incl=True),
}

SCENE_KEYS = {
    "floor": number("side of the square container floor (width of the 2D slice)", "m", 0, 1,
                    default=0.09),
    "film": number("film thickness h", "m", 0, 0.1, required=True),
    "drop": number("drop diameter D", "m", 0, 0.1, required=True),
    "speed": number("impact speed U of the drop (or give height)", "m/s", 0, 50),
    "height": number("fall height H (instead of speed): U = sqrt(2 g H), no air drag", "m",
                     0, 1000),
    "gap": number("from the film surface up to the bottom of the drop", "m", 0, 0.1,
                  lo_incl=True, default=1.0e-3),
    "liquid": Field("liquid", "the liquid of the drop and the film", default="water"),
    "gravity": number("gravitational acceleration, along -z", "m/s^2", 0, 100, lo_incl=True,
                      default=GRAVITY),
    "t_end": number("simulated time", "s", 0, 10, required=True),
    "frame_interval": number("time between recorded frames", "s", 0, 10),
    "trim": Field("bool", "leave out the film and walls the impact cannot reach by t_end",
                  default=True),
    "re_ratio": number("influence radius re / l0 (with the stress model 2.1 or 3.1)", "", 1.5,
                       4.5, lo_incl=True, default=2.1),
    "trim_reach": number("with trim: the film kept reaches this many times Yarin & Weiss's "
                         "crown base radius at t_end (at least D), + 2 mm", "", 1, 10,
                         lo_incl=True, default=2.0),
    "symmetry": Field("choice", "the part simulated, with mirror planes through the drop's "
                      "axis (core/symmetry.py): the whole scene, the half x > 0, or the quarter "
                      "x > 0, y > 0 (3D); records, metrics and frames show the whole",
                      choices=tuple(SYMMETRIES), default="full"),
    "sound_speed_factor": number("c / U: the artificial sound speed c is this many times "
                                 "the impact speed U (S8), or the fall or capillary speed of "
                                 "a slower drop (the seed's 5; config/sound_speed.py)", "",
                                 FACTOR_RANGE[0], FACTOR_RANGE[1], lo_incl=True,
                                 default=DEFAULT_FACTOR),
    "sound_speed": number("artificial sound speed c, instead of sound_speed_factor x U; "
                          "above U / max_mach", "m/s", 0, 1.0e5),
}

_C = dict(lo=0, hi=2)
NUMERICS_KEYS = {
    "courant": number("velocity Courant number v dt / l0 (S5)", "", **_C),
    "courant_speed": Field("choice", "v of the Courant limit: the largest particle speed "
                           "(S5), or the largest speed relative to neighbours, walls at rest "
                           "(measured by the predictor's walk, core/terms.py)",
                           choices=COURANT_SPEEDS),
    "approach": number("with courant_speed relative: the most a particle moves in a step, "
                       "a fraction of l0", "", **_C),
    "acoustic": number("acoustic Courant number c dt / l0 (S6)", "", **_C),
    "viscous": number("viscous number nu dt / l0^2 (M1)", "", **_C),
    "capillary": number("fraction of the capillary limit (M1)", "", **_C),
    "dt_max": number("largest time step", "s", 0, None, allow_inf=True),
    "fixed_dt": number("a fixed time step instead of the adaptive one", "s", 1.0e-8, 1.0,
                       lo_incl=True),
    "pressure_gradient": Field("choice", "pressure-gradient form (M2)", choices=GRADIENT_FORMS),
    "surface_tension": Field("choice", "surface-tension model (core/surface_tension/): the "
                             "seed's inter-particle potential (S22-S24), the continuum surface "
                             "stress (stress, method.md §4c; with pressure_gradient: sum), or "
                             "P = sigma kappa on the free surface (curvature; experimental, "
                             "docs/surface_tension_curvature.md)", choices=SURFACE_TENSION_MODELS),
    "stress_pairs": Field("choice", "with surface_tension: stress, the divergence's pairs (C3, "
                          "method.md §4c): all, or surface (weighted by the surface band, "
                          "calibrated with pressure_gradient: corrected; re_ratio 2.1)",
                          choices=STRESS_PAIRS),
    "viscosity": Field("choice", "viscosity model (core/viscosity.py): the seed's Laplacian "
                       "(S12), or the central pair form (method.md V1), which dissipates as "
                       "the Navier-Stokes equations at a free surface", choices=VISCOSITY_MODELS),
    "beta": number("free-surface threshold n < beta n0 (M3); with P clamped at 0 (n < n0 has "
                   "P = 0 anyway) it changes no pressure", "", 0.5, 1.0, lo_incl=True,
                   hi_incl=False),
    "max_density_excess": number("abort when n/n0 - 1 exceeds this", "", 0, 10),
    "max_mach": number("abort when a speed exceeds this times c", "", 0, 10),
    "max_out_fraction": number("abort when more fluid than this has left the domain", "",
                               0, 1, lo_incl=True),
    "collision": number("collision distance of the particle collision model, a fraction of "
                        "l0 (0: off)", "", 0, 1, lo_incl=True, hi_incl=False),
    "restitution": number("restitution coefficient of the collision model", "", 0, 1,
                          lo_incl=True),
    "reorder_every": Field("int", "re-sort particles into cell order every N steps (0: never)",
                           lo=0, lo_incl=True, hi=1_000_000),
    "neighbour_list": Field("bool", "list each fluid particle's neighbours in the density pass "
                            "for the pressure gradient (same results, faster)", default=True),
    "predictor_list": Field("bool", "the predictor's neighbours (viscosity, surface tension, "
                            "collisions) from the density pass's list of the step before, "
                            "moved only by the corrector, instead of a cell walk of their own "
                            "(needs neighbour_list; faster, results within float noise of the "
                            "walk's)", default=True),
    "cells_per_re": Field("int", "cells of side re/k: the neighbour walk visits the cells of "
                          "the (2k + 1)^d block around that can hold a neighbour",
                          lo=1, lo_incl=True, hi=3, hi_incl=True),
    "wall_model": Field("choice", "the floor: wall and dummy particle layers, or the analytic "
                        "plane floor (no particles under the floor)", choices=WALL_MODELS),
}

RUNG_KEYS = {
    "l0": number("particle spacing", "m", 0, 0.01, required=True),
    "t_end": number("simulated time at this quality (replaces scene.t_end)", "s", 0, 10),
    "frame_interval": number("time between frames at this quality", "s", 0, 10),
    "symmetry": Field("choice", "the part simulated at this quality (replaces scene.symmetry)",
                      choices=tuple(SYMMETRIES)),
    "trim_reach": number("scene.trim_reach at this quality", "", 1, 10, lo_incl=True),
    "numerics": Field("map", "numerics at this quality", keys=NUMERICS_KEYS),
}
RUNG = Field("map", "one quality rung", keys=RUNG_KEYS)

TOP_KEYS = {
    "title": Field("text", "a short title", required=True),
    "description": Field("text", "what the preset shows"),
    "dim": Field("choice", "3, or 2 for a cross-section", choices=(3, 2), default=3),
    "scene": Field("map", "the drop-on-film scene", required=True, keys=SCENE_KEYS),
    "numerics": Field("map", "overrides of crowndemo.core.params.Numerics", keys=NUMERICS_KEYS),
    "quality": Field("map", "the quality ladder", required=True,
                     keys={q: RUNG for q in QUALITIES}),
}
TOP = Field("map", "a preset", keys=TOP_KEYS)


def dotted(path: Iterable[Any]) -> str:
    return ".".join(str(p) for p in path)


def validate(doc: Document) -> dict:
    """The preset's values with defaults filled in; PresetError on the first bad value."""
    return _check(TOP, doc.data, (), doc)


def _fail(doc: Document, path, value, why: str, allowed: str):
    raise PresetError(doc.source_of(path), dotted(path), value, why, allowed)


def _check(f: Field, v, path, doc: Document):
    if f.kind == "map":
        if not isinstance(v, dict):
            _fail(doc, path, v, "not a mapping (key: value lines)", f.allowed())
        return _check_map(f.keys, v, path, doc)
    if f.kind == "number":
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            _fail(doc, path, v, "not a number", f.allowed())
        v = float(v)
        if math.isnan(v) or (math.isinf(v) and not f.allow_inf):
            _fail(doc, path, v, "not a finite number", f.allowed())
        _range(f, v, path, doc)
        return v
    if f.kind == "int":
        if isinstance(v, bool) or not isinstance(v, int):
            _fail(doc, path, v, "not an integer", f.allowed())
        _range(f, v, path, doc)
        return v
    if f.kind == "bool":
        if not isinstance(v, bool):
            _fail(doc, path, v, "not true or false", f.allowed())
        return v
    if f.kind == "choice":
        if not any(type(v) is type(c) and v == c for c in f.choices):
            why = "not one of the choices" + did_you_mean(v, [str(c) for c in f.choices])
            _fail(doc, path, v, why, f.allowed())
        return v
    if f.kind == "text":
        if isinstance(v, str):
            return {"en": v}
        if not isinstance(v, dict):
            _fail(doc, path, v, "not a text", f.allowed())
        for k, t in v.items():
            if k not in LANGUAGES:
                _fail(doc, path + (k,), t, "unknown language" + did_you_mean(k, LANGUAGES),
                      ", ".join(LANGUAGES))
            if not isinstance(t, str):
                _fail(doc, path + (k,), t, "not a string", "a text")
        if "en" not in v:
            raise PresetError(doc.source_of(path), dotted(path + ("en",)), MISSING,
                              "no English text", "a string")
        return dict(v)
    if f.kind == "liquid":
        if isinstance(v, str):
            if v not in LIQUIDS:
                _fail(doc, path, v, "unknown liquid" + did_you_mean(v, LIQUIDS), f.allowed())
            v = {"name": v}
        elif not isinstance(v, dict):
            _fail(doc, path, v, "not a liquid", f.allowed())
        out = _check_map(LIQUID_KEYS, v, path, doc)
        return out
    raise AssertionError(f.kind)


def _range(f: Field, v, path, doc: Document) -> None:
    if not f.in_range(v):
        _fail(doc, path, v, "out of range", f.allowed())


def check_numerics(values: dict, doc: Document) -> dict:
    """A ``numerics`` mapping checked as a preset's is (unknown keys, types, ranges)."""
    return _check_map(NUMERICS_KEYS, values, ("numerics",), doc)


def _check_map(keys: Dict[str, Field], v: dict, path, doc: Document) -> dict:
    for k, item in v.items():
        if k not in keys:
            _fail(doc, path + (k,), item, "unknown key" + did_you_mean(k, [str(x) for x in keys]),
                  ", ".join(str(x) for x in keys))
    out = {}
    for k, f in keys.items():
        p = path + (k,)
        if k in v:
            out[k] = _check(f, v[k], p, doc)
        elif f.required:
            raise PresetError(doc.missing_source(p), dotted(p), MISSING, "no value given"
                              + (f" ({f.doc})" if f.doc else ""), f.allowed())
        elif f.default is not None:
            out[k] = _check(f, copy.deepcopy(f.default), p, doc)
    return out


__all__ = ["validate", "Field", "QUALITIES", "LIQUIDS", "TOP_KEYS", "SCENE_KEYS",
           "NUMERICS_KEYS", "RUNG_KEYS", "LIQUID_KEYS", "check_numerics", "dotted"]
