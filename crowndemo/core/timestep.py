"""Time-step limits (method.md §1: S5-S8 and M1) and the choice of dt, naming the one that binds."""
from __future__ import annotations

import math
from typing import Dict, Optional, Tuple

from .params import VISCOUS_STIFFNESS, Model, Numerics, ParameterError, Physics

# (new names go last: RunStats.bound_log stores their index, and checkpoints keep it)
LIMIT_NAMES = ("courant", "acoustic", "viscous", "capillary", "dt_max", "approach")


def limits(physics: Physics, numerics: Numerics, model: Model, speed: float,
           relative_speed: Optional[float] = None) -> Dict[str, float]:
    """Every limit on dt in force for this model at the given maximum speed (and, with
    ``courant_speed: relative``, the largest relative speed of neighbours; None, not measured
    yet: the maximum speed, as in the seed's form).

    courant:   C_v l0 / v        (S5, S7); v = the speed, or the relative speed
                                 (measured by the predictor's walk, terms.py)
    approach:  C_a l0 / v        (with the relative speed only; terms.py says why)
    acoustic:  C_c l0 / c        (S6, S8)
    viscous:   k_nu l0^2 / (s nu) (M1; only when viscosity is compiled in; s the viscosity
                                 member's stiffness, params.VISCOUS_STIFFNESS)
    capillary: k_st sqrt(rho l0^3 / (2 pi sigma))  (M1; only with surface tension)
    """
    l0 = physics.l0
    v = speed
    if numerics.courant_speed == "relative" and relative_speed is not None:
        v = relative_speed
    out = {"courant": numerics.courant * l0 / v if v > 0 else math.inf,
           "acoustic": numerics.acoustic * l0 / physics.c}
    if numerics.courant_speed == "relative":
        out["approach"] = numerics.approach * l0 / speed if speed > 0 else math.inf
    if model.viscosity:
        out["viscous"] = numerics.viscous * l0 * l0 / (
            physics.nu * VISCOUS_STIFFNESS[numerics.viscosity])
    if model.surface_tension:
        out["capillary"] = numerics.capillary * math.sqrt(
            physics.rho * l0 ** 3 / (2.0 * math.pi * physics.sigma))
    if math.isfinite(numerics.dt_max):
        out["dt_max"] = numerics.dt_max
    return out


def l0_at_dt(name: str, physics: Physics, numerics: Numerics, dt: float) -> float:
    """The l0 at which the ``name`` limit of ``limits`` (at speed v_max, not the relative
    speed) equals ``dt``: each limit inverted for l0."""
    if name == "courant":
        return dt * physics.v_max / numerics.courant
    if name == "acoustic":
        return dt * physics.c / numerics.acoustic
    if name == "viscous":
        return math.sqrt(dt * physics.nu * VISCOUS_STIFFNESS[numerics.viscosity]
                         / numerics.viscous)
    if name == "capillary":
        return ((dt / numerics.capillary) ** 2 * 2.0 * math.pi * physics.sigma
                / physics.rho) ** (1.0 / 3.0)
    raise ValueError(f"no l0 sets the {name} limit")


def choose(physics: Physics, numerics: Numerics, model: Model, speed: float,
           relative_speed: Optional[float] = None) -> Tuple[float, str]:
    """dt = the smallest limit (or the user's fixed dt), and the name of what binds."""
    lim = limits(physics, numerics, model, speed, relative_speed)
    name = min(lim, key=lim.get)
    if numerics.fixed_dt is not None:
        return numerics.fixed_dt, "fixed"
    return lim[name], name


def check_fixed_dt(physics: Physics, numerics: Numerics, model: Model, source: str = "parameters"
                   ) -> None:
    """Refuse a user-fixed dt that breaks a limit at the scene's expected speed, before any run."""
    if numerics.fixed_dt is None or numerics.allow_unsafe_dt:
        return
    lim = limits(physics, numerics, model, physics.v_max)
    broken = sorted((v, k) for k, v in lim.items() if numerics.fixed_dt > v and k != "dt_max")
    if broken:
        names = " and ".join(k for _, k in broken)
        raise ParameterError("fixed_dt", numerics.fixed_dt,
                             f"<= {broken[0][0]:.3g} s (it breaks the {names} limit"
                             f"{'s' if len(broken) > 1 else ''} at v_max = {physics.v_max:g} m/s)",
                             source)
