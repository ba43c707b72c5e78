"""``crowndemo scene``: the reference scenes (tank, dam break, patch) with the one figure
each is checked against (method.md §7)."""
from __future__ import annotations

import math
import sys
import time
from typing import Callable, Dict

from .. import strictjson
from ..core.params import GRADIENT_FORMS, Numerics, ParameterError
from ..config.schema import LIQUID_KEYS, SCENE_KEYS
from .common import (NUMERICS, PROG, Fmt, print_summary, run_result, simulate, start_backend)
from .ranges import ceil3, check_range, floor3


# per scene, by dimension: the defaults of its options (keys are the builders' keywords)
SCENES = {
    "tank": {"defaults": {2: dict(l0=1e-3, width=0.04, depth=0.04, nu=1e-3, t_end=0.2),
                          3: dict(l0=2e-3, width=0.04, depth=0.04, nu=1e-3, t_end=0.2)}},
    "dam-break": {"defaults": {2: dict(l0=1e-3, a=0.05, t_end=0.1),
                               3: dict(l0=2e-3, a=0.03, t_end=0.1)}},
    "patch": {"defaults": {2: dict(l0=1e-4, side=2e-3, sigma=0.0728, t_end=0.03),
                           3: dict(l0=2e-4, side=2e-3, sigma=0.0728, t_end=0.03)}},
}

SCENE_HELP = {
    "tank": "water at rest in an open container; pressure tends to rho g (H - z)",
    "dam-break": "a water column a wide, 2a high collapses along a channel 4a long "
                 "(Martin & Moyce)",
    "patch": "a square (cube) of liquid without gravity, rounded up by surface tension",
}

SCENE_EPILOG = """\
examples:
  crowndemo scene dam-break --dim 3 --t-end 0.05      # a short 3D dam break
  crowndemo scene dam-break --dim 2 --l0 5e-4 --gradient sum
  crowndemo scene tank --dim 2 --depth 0.08 --t-end 0.3
  crowndemo scene patch --dim 3 --side 3e-3 --sigma 0.05 --json

defaults by dimension (2D / 3D):
  tank       l0 1 / 2 mm, width = depth = 40 mm, nu 1e-3 m^2/s (settles the start-up waves), t-end 0.2 s
  dam-break  l0 1 / 2 mm, a 50 / 30 mm, t-end 0.1 s
  patch      l0 0.1 / 0.2 mm, side 2 mm, sigma 0.0728 N/m, t-end 0.03 s
A progress line (simulated time, steps/s) goes to stderr every ~2 s; the summary to stdout.
An unstable run stops with exit status 3 and says what broke; lower the safety numbers
(e.g. --acoustic 0.5 --courant 0.1, half the seed's time step) or try another --gradient.
"""


ACROSS_MIN = 4          # particles across every size of a reference scene, at least


def _positive(key: str, value: float, unit: str) -> None:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise ParameterError(key, value, f"> 0 {unit}".rstrip(), "command line")


def _particles(name: str, dim: int, val: Dict) -> float:
    """The scene's particles, counted before numpy builds it: the fluid block and the shell of
    wall and dummy layers around the container (hydrostatic_tank, dam_break and square_patch
    in scenes/reference.py; within a few per cent)."""
    from ..core.lattice import wall_layers

    l0 = val["l0"]
    layers = wall_layers(2.1)                  # the builders' default re = 2.1 l0

    def points(extents) -> float:            # inf for absurd sizes: 1e100 l0 or more
        ks = [e / l0 + 1e-9 for e in extents]
        return math.prod(int(k) for k in ks) if all(k < 1e100 for k in ks) else math.inf

    if name == "patch":
        return points([val["side"]] * dim)
    if name == "tank":
        w, h = val["width"], val["depth"]
        inner, fluid = [w] * (dim - 1) + [h + max(4 * l0, 0.25 * h)], [w] * (dim - 1) + [h]
    else:
        a = val["a"]
        inner, fluid = [4.0 * a] + [a] * (dim - 2) + [2.5 * a], [a] * (dim - 1) + [2.0 * a]
    # walls on every side face and the floor: layers more points each way, one way up
    outer = [e + 2 * layers * l0 for e in inner[:-1]] + [inner[-1] + layers * l0]
    if points(outer) == math.inf:
        return math.inf
    return points(fluid) + points(outer) - points(inner)


SIZES = ("width", "depth", "a", "side")
# the options that share a preset key's range (config/schema.py)
SCHEMA_RANGES = {"t_end": SCENE_KEYS["t_end"], "nu": LIQUID_KEYS["nu"],
                 "sigma": LIQUID_KEYS["sigma"]}


UNITS = {**{k: "m" for k in SIZES}, "nu": "m^2/s", "sigma": "N/m"}


def _sizes(val: Dict) -> str:
    """'width 0.04 m, depth 0.08 m, nu 0.001 m^2/s': the options other than l0 and t_end."""
    return ", ".join(f"{k} {v:g} {UNITS[k]}" if k in UNITS else f"{k} {v:g}"
                     for k, v in val.items() if k not in ("l0", "t_end"))


def _values(name: str, args, numerics: Numerics) -> Dict:
    """The scene's options with their defaults, checked (a ParameterError names the option)
    before Taichi starts or numpy allocates: positive sizes, sizes of at least l0, t_end, nu
    and sigma in a preset's ranges, and at most the particles one simulator holds
    (core/step.py, max_particles)."""
    d = SCENES[name]["defaults"][args.dim]
    val = {k: (getattr(args, k) if getattr(args, k, None) is not None else v)
           for k, v in d.items()}
    _positive("l0", val["l0"], "m")
    for k, field in SCHEMA_RANGES.items():
        if k in val:
            check_range(k, val[k], field)
    for k in SIZES:
        if k in val:
            _positive(k, val[k], "m")
            # the reference figure needs a body, not a handful of particles
            if val[k] < ACROSS_MIN * val["l0"]:
                raise ParameterError(k, val[k], f">= {ACROSS_MIN} l0 = "
                                     f"{ACROSS_MIN * val['l0']:g} m ({ACROSS_MIN} particles "
                                     "across at least)", "command line")
    _check_size(name, args, val, numerics)
    return val


def _edge(ok: Callable[[float], bool], good: float, bad: float) -> float:
    """The value nearest ``bad`` where ``ok`` (true at ``good``, false at ``bad``) still
    holds: bisection on a log scale, as sizes may span hundreds of decades."""
    while abs(math.log(bad) - math.log(good)) > 1e-4:
        mid = math.sqrt(good) * math.sqrt(bad)
        good, bad = (mid, bad) if ok(mid) else (good, mid)
    return good


def _check_size(name: str, args, val: Dict, numerics: Numerics) -> None:
    """Refuse a scene that one simulator cannot hold (core/step.py, max_particles). The
    message names a size given on the command line, with the largest that fits at this l0,
    unless l0 was given too and a coarser one fits; else l0, with the finest that fits."""
    from ..core.params import Model
    from ..core.step import max_particles

    model = Model(args.dim, False, False, False, numerics.pressure_gradient,
                  numerics.collision > 0, numerics.neighbour_list)
    limit = max_particles(model)
    fits = lambda **change: _particles(name, args.dim, {**val, **change}) <= limit
    n = _particles(name, args.dim, val)
    if n <= limit:
        return
    l0 = val["l0"]
    count = f"{n:,}" if n < 1e15 else f"{n:.3g}" if math.isfinite(n) else "over 1e100"
    where = (f"at l0 = {l0:g} m the scene has ~{count} particles, one simulator holds at "
             f"most {limit:,}")
    sizes = [k for k in SIZES if k in val]
    smallest = ACROSS_MIN * l0           # a size below holds too few particles across
    largest = {k: _edge(lambda v, k=k: fits(**{k: v}), smallest, val[k])
               for k in sizes if getattr(args, k, None) is not None and fits(**{k: smallest})}
    coarsest = min(val[k] for k in sizes) / ACROSS_MIN     # l0 beyond: too few across
    l0_helps = fits(l0=coarsest)
    if largest and (args.l0 is None or not l0_helps):
        k = min(largest, key=lambda k: largest[k] / val[k])
        raise ParameterError(k, val[k], f">= {smallest:g} m and <= {floor3(largest[k]):.3g} m "
                             f"here: {where}", "command line")
    if not l0_helps:                     # neither a coarser l0 nor one smaller size alone
        given = [f"--{k}" for k in sizes if getattr(args, k, None) is not None]
        raise ParameterError("l0", l0, f"a coarser l0 together with a smaller "
                             f"{' or '.join(given) or 'scene'}: {where}", "command line")
    need = ceil3(_edge(lambda v: fits(l0=v), coarsest, l0))
    raise ParameterError("l0", l0, f">= {need:.3g} m for this scene's sizes: {where}",
                         "command line")


def _numerics(args) -> Numerics:
    return Numerics(pressure_gradient=args.gradient, courant=args.courant,
                    acoustic=args.acoustic)


def _build_scene(name: str, args, val: Dict, numerics: Numerics):
    from .. import scenes

    common = dict(dim=args.dim, l0=val["l0"], t_end=val["t_end"], numerics=numerics)
    if name == "tank":
        sc = scenes.hydrostatic_tank(width=val["width"], depth=val["depth"], nu=val["nu"],
                                     **common)
    elif name == "dam-break":
        sc = scenes.dam_break(a=val["a"], **common)
    else:
        sc = scenes.square_patch(side=val["side"], sigma=val["sigma"], **common)
    sc.physics.validate("command line")
    sc.numerics.validate("command line")
    return sc


def _observables(name: str, scene, sim) -> Dict:
    """One scene-specific figure against its reference (method.md §7), at the end time."""
    import numpy as np

    from ..core.state import FLUID
    from ..validate.cases import MARTIN_MOYCE
    from ..validate.observables import surge_front
    from ..scenes import circularity, equivalent_radius

    sim.refresh_pressure()
    snap = sim.snapshot()
    fluid = snap["kind"] == FLUID
    pos = snap["pos"][fluid].astype(float)
    p = snap["pressure"][fluid].astype(float)
    ph = scene.physics
    if len(pos) == 0:
        return {}
    if name == "tank":
        depth = scene.info["depth_m"]
        z = pos[:, -1]
        lower = z < 0.5 * depth
        ref = ph.rho * ph.gravity * (depth - z[lower])
        ratio = float(p[lower].sum() / ref.sum()) if ref.sum() > 0 else math.nan
        return {"pressure_over_hydrostatic_lower_half": ratio,
                "text": f"pressure / rho g (H - z), fluid in the lower half: {ratio:.3f} "
                        "(hydrostatics: 1)"}
    if name == "dam-break":
        a = scene.info["a_m"]
        T = sim.stats.time * math.sqrt(2.0 * ph.gravity / a)
        Z = surge_front(pos, ph.l0) / a      # the leading edge of the connected liquid
        Ts, Zs = zip(*MARTIN_MOYCE)
        ref = float(np.interp(T, Ts, Zs)) if Ts[0] <= T <= Ts[-1] else None
        text = f"surge front Z = z/a = {Z:.3f} at T = t sqrt(2g/a) = {T:.3f}"
        text += (f"; Martin & Moyce: {ref:.3f}" if ref is not None else
                 f"; Martin & Moyce tabulate T = {Ts[0]} .. {Ts[-1]}")
        if Z >= scene.info["length_a"] - 0.1:
            text += " (front at the end wall)"
        return {"T": T, "front_Z": Z, "martin_moyce_Z": ref, "text": text}
    # patch
    R = equivalent_radius(len(pos), ph.dim, ph.l0)
    circ = circularity(pos, ph.l0)
    return {"circularity": circ, "equivalent_radius_m": R,
            "text": f"circularity R_eq/R_out = {circ:.3f} (square 0.80, disc 1.00), "
                    f"R_eq = {R * 1e3:.4g} mm"}


def _scene(args) -> int:
    from ..core import simulator_for

    name = args.scene
    numerics = _numerics(args)
    numerics.validate("command line")
    val = _values(name, args, numerics)        # every option checked before Taichi starts
    be = start_backend(args)
    t0 = time.perf_counter()
    scene = _build_scene(name, args, val, numerics)
    sim = simulator_for(scene)
    setup_s = time.perf_counter() - t0
    t_end = val["t_end"]
    if not args.quiet:
        print(f"{PROG}: scene {name}, {args.dim}D, {len(scene.pos):,} particles, arch "
              f"{be.resolved}, {be.precision}; running to {t_end * 1e3:g} ms "
              "(the first step compiles the kernels or loads them from the cache)",
              file=sys.stderr, flush=True)
    run = simulate(sim, t_end, args.quiet)
    obs = _observables(name, scene, sim)
    counts = sim.counts()
    result = {"scene": name, "dim": args.dim, "parameters": val, "gradient": args.gradient,
              "sound_speed_m_s": scene.physics.c, "arch": be.arch,
              "resolved_arch": be.resolved, "precision": be.precision,
              **run_result(run, counts, setup_s), "observables": obs,
              # health.energy_J and energy_start_J: per unit depth in 2D, as info's masses
              "energy_unit": "J" if args.dim == 3 else "J/m (per unit depth)"}
    if args.json:
        print(strictjson.dumps(result))
        return 0
    head = (f"scene {name}: {args.dim}D, l0 = {val['l0']:g} m, {_sizes(val)}; gradient "
            f"{args.gradient}; arch {be.resolved}, {be.precision}")
    print_summary(head, run, counts, scene.physics.c, setup_s, obs, dim=args.dim)
    return 0


def register(sub, common) -> None:
    p = sub.add_parser("scene", formatter_class=Fmt, epilog=SCENE_EPILOG,
                       help="run a reference scene (tank, dam-break, patch) and summarise it",
                       description="Run a reference scene and print a summary: particles, "
                                   "steps, dt and the limits that bound it, health, wall time.")
    scene_sub = p.add_subparsers(dest="scene", metavar="NAME", required=True)
    for name in SCENES:
        q = scene_sub.add_parser(name, parents=common, formatter_class=Fmt,
                                 epilog=SCENE_EPILOG, help=SCENE_HELP[name],
                                 description=f"Scene {name}: {SCENE_HELP[name]}.")
        q.add_argument("--dim", type=int, choices=(2, 3), default=2, help="dimension (default: 2)")
        q.add_argument("--l0", type=float, metavar="M", help="particle spacing [m] (default: by --dim, below)")
        q.add_argument("--t-end", type=float, metavar="S", help="simulated time [s] (default: below)")
        if name == "tank":
            q.add_argument("--width", type=float, metavar="M", help="container width [m] (default: 0.04)")
            q.add_argument("--depth", type=float, metavar="M", help="water depth H [m] (default: 0.04)")
            q.add_argument("--nu", type=float, metavar="NU", help="kinematic viscosity [m^2/s] (default: 1e-3, which damps the start-up waves; the hydrostatic answer does not depend on it)")
        elif name == "dam-break":
            q.add_argument("--a", type=float, metavar="M",
                           help="column width a [m]; height 2a (default: 0.05 in 2D, 0.03 in 3D)")
        else:
            q.add_argument("--side", type=float, metavar="M", help="side of the square [m] (default: 2e-3)")
            q.add_argument("--sigma", type=float, metavar="SIGMA", help="surface tension [N/m] (default: 0.0728)")
        q.add_argument("--courant", type=float, default=NUMERICS.courant, metavar="X",
                       help="velocity Courant number v dt / l0 (default: %(default)g, S5)")
        q.add_argument("--acoustic", type=float, default=NUMERICS.acoustic, metavar="X",
                       help="acoustic Courant number c dt / l0 (default: %(default)g, S6)")
        q.add_argument("--gradient", choices=GRADIENT_FORMS, default="pmin",
                       help="pressure-gradient form: seed (P_j - P_i), pmin (P_j - Pmin_i), "
                            "sum (P_j + P_i), corrected (P_i L_i + P_j L_j, L the inverse of "
                            "the particle's fabric; method.md M2c) (default: pmin)")
        q.add_argument("--json", action="store_true", help="print the summary as one JSON object")
        q.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
        q.set_defaults(func=lambda a, argv: _scene(a))
