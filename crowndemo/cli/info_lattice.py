"""``crowndemo info --dim D --l0 M``: the constants (n0, lambda0, C, mass, c) and time-step
limits of a lattice, the options first checked against the preset keys' ranges."""
from __future__ import annotations

import math
import sys
from typing import Dict

from .. import strictjson
from ..config.schema import LIQUID_KEYS, RUNG_KEYS, SCENE_KEYS
from ..core import timestep
from ..core.health import starts_too_fast
from ..core.params import SOUND_SPEED_FACTOR, ParameterError
from .ranges import ceil3, check_range


# the name a ParameterError gives each lattice option (cli/common.py OPTION_OF turns it into
# the option) and the preset key whose range (config/schema.py) it shares
LATTICE_RANGES = {"l0": ("l0", RUNG_KEYS["l0"]), "re_ratio": ("re_ratio", SCENE_KEYS["re_ratio"]),
                  "rho": ("rho", LIQUID_KEYS["rho"]), "nu": ("nu", LIQUID_KEYS["nu"]),
                  "sigma": ("sigma", LIQUID_KEYS["sigma"]),
                  "speed": ("speed", SCENE_KEYS["speed"]),
                  "sound_speed": ("sound_speed", SCENE_KEYS["sound_speed"])}


def _check_lattice_ranges(args) -> None:
    """The lattice options within the ranges of a preset's keys: l0 as quality.*.l0, the
    liquid as scene.liquid.*, the speeds and re_ratio as scene.*."""
    for opt, (key, field) in LATTICE_RANGES.items():
        value = getattr(args, opt)
        if value is not None:
            check_range(key, value, field, "info")


def _check_dt_floor(physics, numerics, lim: Dict[str, float]) -> None:
    """Refuse a lattice whose time step a preset's run would refuse (below DT_FLOOR,
    config/resolve.py): name l0 and the finest spacing that passes or, where no l0 in its
    range does (a liquid far too light for its surface tension), rho."""
    from ..config.resolve import DT_FLOOR

    name = min(lim, key=lim.get)
    if not math.isfinite(lim[name]):        # no nu, no sigma, and l0 / v overflows
        slowest = numerics.courant * physics.l0 / sys.float_info.max
        raise ParameterError("speed", physics.v_max, f"> {slowest * 1.01:.3g} m/s (slower, "
                             "the Courant limit l0 / v overflows: dt would be infinite)", "info")
    if lim[name] >= DT_FLOOR:
        return
    why = (f"below, dt = {lim[name]:.3g} s (the {name} limit) is under the {DT_FLOOR:g} s "
           "that a run accepts")
    need = max(timestep.l0_at_dt(k, physics, numerics, DT_FLOOR) for k in lim)
    l0_max = RUNG_KEYS["l0"].hi
    if need <= l0_max:
        raise ParameterError("l0", physics.l0, f">= {ceil3(need):.3g} m and <= {l0_max:g} m "
                             f"here: {why}", "info")
    rho = (DT_FLOOR / numerics.capillary) ** 2 * 2.0 * math.pi * physics.sigma / l0_max ** 3
    raise ParameterError("rho", physics.rho, f">= {ceil3(rho):.3g} kg/m^3 at sigma = "
                         f"{physics.sigma:g} N/m: lighter, the capillary limit leaves dt under "
                         f"{DT_FLOOR:g} s at every l0 <= {l0_max:g} m", "info")


def info_lattice(args) -> int:
    """``crowndemo info --dim D --l0 M ...``: the constants and time-step limits of a lattice."""
    from ..core.lattice import LatticeConstants
    from ..core.params import Model, Numerics, Physics

    _check_lattice_ranges(args)
    physics = Physics(dim=args.dim, l0=args.l0, v_max=args.speed, re_ratio=args.re_ratio,
                      rho=args.rho, nu=args.nu, sigma=args.sigma,
                      sound_speed=args.sound_speed).validate("info")
    numerics = Numerics()
    if starts_too_fast(physics.v_max, physics.c, numerics.max_mach):
        raise ParameterError("sound_speed", physics.c,
                             f"> speed / max_mach = {physics.v_max / numerics.max_mach:.4g} m/s "
                             f"(a run stops when a particle is faster than max_mach * c, "
                             f"max_mach = {numerics.max_mach:g})", "info")
    model = Model.of(physics, numerics)
    lim = timestep.limits(physics, numerics, model, physics.v_max)
    _check_dt_floor(physics, numerics, lim)
    lat = LatticeConstants.compute(physics.dim, physics.l0, physics.re_ratio, physics.rho,
                                   physics.sigma)
    dt, binding = timestep.choose(physics, numerics, model, physics.v_max)
    ties = [k for k, v in lim.items() if v <= dt * (1 + 1e-9)]
    all_limits = {k: lim.get(k) for k in ("courant", "acoustic", "viscous", "capillary")}
    safety = {"courant": numerics.courant, "acoustic": numerics.acoustic,
              "viscous": numerics.viscous, "capillary": numerics.capillary}
    d = physics.dim
    out = {"dim": d, "l0": physics.l0, "re_ratio": physics.re_ratio, "re": lat.re,
           "rho": physics.rho, "nu": physics.nu, "sigma": physics.sigma,
           "speed": physics.v_max, "sound_speed": physics.c,
           "sound_speed_source": ("given" if args.sound_speed is not None
                                  else f"{SOUND_SPEED_FACTOR:g} x speed"),
           "n0": lat.n0, "lambda0": lat.lambda0, "lambda0_over_l0_sq": lat.lambda0 / lat.l0 ** 2,
           "C": lat.C, "mass": lat.mass,
           "mass_unit": "kg" if d == 3 else "kg/m (per unit depth)",
           "limits_s": all_limits, "safety": safety, "dt_s": dt, "binding": binding,
           "binding_ties": ties, "model": Model.describe(model)}
    if args.json:
        print(strictjson.dumps(out))
        return 0

    def lim_line(name, rule):
        v = all_limits[name]
        if v is None:
            why = "no viscosity (nu = 0)" if name == "viscous" else "no surface tension (sigma = 0)"
            return f"  {name:<10} {rule:<34} {'off':>11}    {why}"
        mark = "  <- binds" if name in ties else ""
        return f"  {name:<10} {rule:<34} {v:11.4g} s{mark}"

    c_unit = "J/m^3" if d == 3 else "N/m^3 (per unit depth)"
    print(f"explicit MPS constants: {d}D, l0 = {physics.l0:g} m, re = {physics.re_ratio:g} l0 "
          f"= {lat.re:.4g} m")
    print(f"  {'n0':<10} {lat.n0:.6g}")
    print(f"  {'lambda0':<10} {lat.lambda0:.6g} m^2  (= {lat.lambda0 / lat.l0 ** 2:.6g} l0^2)")
    print(f"  {'C':<10} {lat.C:.6g} {c_unit}  (surface tension, sigma = {physics.sigma:g} N/m)")
    print(f"  {'mass':<10} {lat.mass:.6g} {out['mass_unit']}  (rho = {physics.rho:g} kg/m^3)")
    print(f"  {'c':<10} {physics.c:.6g} m/s  ({out['sound_speed_source']}; "
          f"speed = {physics.v_max:g} m/s)")
    print(f"time-step limits (nu = {physics.nu:g} m^2/s); dt = the smallest:")
    print(lim_line("courant", f"{numerics.courant:g} l0 / v"))
    print(lim_line("acoustic", f"{numerics.acoustic:g} l0 / c"))
    print(lim_line("viscous", f"{numerics.viscous:g} l0^2 / nu"))
    print(lim_line("capillary", f"{numerics.capillary:g} sqrt(rho l0^3 / (2 pi sigma))"))
    print(f"  dt = {dt:.4g} s, bound by {' = '.join(ties)}")
    return 0
