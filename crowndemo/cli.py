"""The ``crowndemo`` command line: ``info``, ``scene`` and ``bench``.

User mistakes (bad flags, parameters out of range, an unavailable arch) print one line
``crowndemo: error: ...`` on stderr and return 2; an unstable run prints the reason and returns 3.
"""
from __future__ import annotations

import os

# Taichi prints a version banner on stdout when imported; keep stdout clean for --json.
os.environ.setdefault("ENABLE_TAICHI_HEADER_PRINT", "0")

import argparse  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import shlex  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from typing import Dict, Optional, Sequence  # noqa: E402

from . import __version__  # noqa: E402
from .backend import ARCHS, PRECISIONS, BackendError  # noqa: E402
from .core.health import InstabilityError  # noqa: E402
from .core.params import GRADIENT_FORMS, Numerics, ParameterError  # noqa: E402

PROG = "crowndemo"
PROGRESS_EVERY_S = 2.0
_NUMERICS = Numerics()       # the core's defaults, shown in --help

# command-line option for each parameter name that a ParameterError can carry
OPTION_OF = {"dim": "--dim", "l0": "--l0", "v_max": "--speed", "re_ratio": "--re-ratio",
             "rho": "--rho", "nu": "--nu", "sigma": "--sigma", "sound_speed": "--sound-speed",
             "pressure_gradient": "--gradient", "t_end": "--t-end", "width": "--width",
             "depth": "--depth", "a": "--a", "side": "--side", "n": "--n", "steps": "--steps",
             "courant": "--courant", "acoustic": "--acoustic"}


class UsageError(Exception):
    """A command-line mistake found by argparse."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):          # one line, no usage dump, no SystemExit
        raise UsageError(f"{message} (see '{self.prog} --help')")


class _Fmt(argparse.RawDescriptionHelpFormatter):
    def __init__(self, prog):
        super().__init__(prog, max_help_position=32)


def _backend_options() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(add_help=False)
    g = p.add_argument_group("backend options")
    g.add_argument("--arch", choices=ARCHS, default=None,
                   help="Taichi backend; auto tries a GPU and falls back to the CPU "
                        "(default: $CROWNDEMO_ARCH, else cpu)")
    g.add_argument("--precision", choices=PRECISIONS, default="f32",
                   help="float precision of every field and kernel (default: f32)")
    g.add_argument("--seed", type=int, default=0, help="Taichi random seed (default: 0)")
    g.add_argument("--single-thread", action="store_true",
                   help="one CPU thread: bit-identical results from run to run")
    return p


def _start_backend(args):
    import contextlib

    from . import backend
    # ti.init prints "[Taichi] Starting on arch=..." on stdout: send it to stderr
    with contextlib.redirect_stdout(sys.stderr):
        return backend.init(args.arch, args.precision, args.seed, args.single_thread)


# ---- info ------------------------------------------------------------------------------------
INFO_EPILOG = """\
examples:
  crowndemo info --dim 3 --l0 1e-4                   # water at 0.1 mm, speed 1 m/s
  crowndemo info --dim 3 --l0 5e-5 --speed 8         # the seed's 8 m/s drop impact
  crowndemo info --dim 2 --l0 1e-3 --nu 1e-3 --json  # a viscous liquid, as JSON

Pure host computation: no Taichi kernel runs (the backend options are accepted and ignored).
n0 and lambda0 come from a perfect lattice (S13), C from the cut-plane energy balance (S23).
"""


def _info(args) -> int:
    from .core import timestep
    from .core.lattice import LatticeConstants
    from .core.params import Model, Numerics, Physics

    physics = Physics(dim=args.dim, l0=args.l0, v_max=args.speed, re_ratio=args.re_ratio,
                      rho=args.rho, nu=args.nu, sigma=args.sigma,
                      sound_speed=args.sound_speed).validate("info")
    numerics = Numerics()
    model = Model.of(physics, numerics)
    lat = LatticeConstants.compute(physics.dim, physics.l0, physics.re_ratio, physics.rho,
                                   physics.sigma)
    lim = timestep.limits(physics, numerics, model, physics.v_max)
    dt, binding = timestep.choose(physics, numerics, model, physics.v_max)
    ties = [k for k, v in lim.items() if v <= dt * (1 + 1e-9)]
    all_limits = {k: lim.get(k) for k in ("courant", "acoustic", "viscous", "capillary")}
    safety = {"courant": numerics.courant, "acoustic": numerics.acoustic,
              "viscous": numerics.viscous, "capillary": numerics.capillary}
    d = physics.dim
    out = {"dim": d, "l0": physics.l0, "re_ratio": physics.re_ratio, "re": lat.re,
           "rho": physics.rho, "nu": physics.nu, "sigma": physics.sigma,
           "speed": physics.v_max, "sound_speed": physics.c,
           "sound_speed_source": "given" if args.sound_speed is not None else "5 x speed",
           "n0": lat.n0, "lambda0": lat.lambda0, "lambda0_over_l0_sq": lat.lambda0 / lat.l0 ** 2,
           "C": lat.C, "mass": lat.mass,
           "mass_unit": "kg" if d == 3 else "kg/m (per unit depth)",
           "limits_s": all_limits, "safety": safety, "dt_s": dt, "binding": binding,
           "binding_ties": ties, "model": Model.describe(model)}
    if args.json:
        print(json.dumps(out, indent=2))
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


# ---- scene -----------------------------------------------------------------------------------
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
  crowndemo scene dam-break --dim 3 --t-end 0.05      # what `make demo` runs
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


def _positive(key: str, value: float, unit: str) -> None:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise ParameterError(key, value, f"> 0 {unit}".rstrip(), "command line")


def _build_scene(name: str, args):
    from . import scenes

    d = SCENES[name]["defaults"][args.dim]
    val = {k: (getattr(args, k) if getattr(args, k, None) is not None else v)
           for k, v in d.items()}
    _positive("l0", val["l0"], "m")
    _positive("t_end", val["t_end"], "s")
    for k in ("width", "depth", "a", "side"):
        if k in val:
            _positive(k, val[k], "m")
            if val[k] < val["l0"]:
                raise ParameterError(k, val[k], f">= l0 = {val['l0']:g} m", "command line")
    numerics = Numerics(pressure_gradient=args.gradient, courant=args.courant,
                        acoustic=args.acoustic)
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
    return sc, val


# Martin & Moyce (1952), column a x 2a: (T = t sqrt(2 g / a), Z = z / a), method.md §7
MARTIN_MOYCE = ((0.832, 1.217), (1.219, 1.474), (1.997, 2.292), (2.547, 2.995), (3.345, 4.134),
                (4.034, 4.944), (4.418, 5.881), (5.091, 6.980), (5.685, 7.945), (6.306, 8.966),
                (6.822, 9.986))


def _observables(name: str, scene, sim) -> Dict:
    """One scene-specific figure against its reference (method.md §7), at the end time."""
    import numpy as np

    from .core.state import FLUID
    from .scenes import circularity, equivalent_radius

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
        Z = float(pos[:, 0].max() + 0.5 * ph.l0) / a
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


def _fmt_counts(counts: Dict[str, int]) -> str:
    parts = [f"{counts[k]:,} {k}" for k in ("fluid", "wall", "dummy", "gone") if counts.get(k)]
    return ", ".join(parts) + f" ({sum(counts.values()):,} total)"


def _scene(args) -> int:
    from .core import simulator_for

    name = args.scene
    be = _start_backend(args)
    t0 = time.perf_counter()
    scene, val = _build_scene(name, args)
    sim = simulator_for(scene)
    setup_s = time.perf_counter() - t0
    t_end = val["t_end"]
    h0 = sim.stats.health
    peak = {"speed": h0.max_speed, "excess": h0.max_density_excess}
    if not args.quiet:
        print(f"{PROG}: scene {name}, {args.dim}D, {len(scene.pos):,} particles, arch "
              f"{be.resolved}, {be.precision}; running to {t_end * 1e3:g} ms "
              "(the first step compiles the kernels)", file=sys.stderr, flush=True)

    def on_step(s):
        h = s.stats.health
        peak["speed"] = max(peak["speed"], h.max_speed)
        peak["excess"] = max(peak["excess"], h.max_density_excess)
        now = time.perf_counter()
        if s.stats.steps == 1:          # the first step compiles the kernels: not in the rate
            if not args.quiet:
                print(f"  first step (compiling) {now - prog['t']:.1f} s", file=sys.stderr,
                      flush=True)
            prog["t"], prog["steps"] = now, 1
        elif not args.quiet and now - prog["t"] >= PROGRESS_EVERY_S:
            rate = (s.stats.steps - prog["steps"]) / (now - prog["t"])
            print(f"  t = {s.stats.time * 1e3:8.3f} / {t_end * 1e3:g} ms  step {s.stats.steps:6d}"
                  f"  {rate:7.1f} steps/s  max speed {h.max_speed:.3g} m/s", file=sys.stderr,
                  flush=True)
            prog["t"], prog["steps"] = now, s.stats.steps

    prog = {"t": time.perf_counter(), "steps": 0}
    stats = sim.run(t_end, on_step=on_step)
    obs = _observables(name, scene, sim)
    counts = sim.counts()
    d = stats.as_dict()
    d["health"]["peak_max_speed_m_s"] = peak["speed"]
    d["health"]["peak_max_density_excess"] = peak["excess"]
    result = {"scene": name, "dim": args.dim, "parameters": val, "gradient": args.gradient,
              "sound_speed_m_s": scene.physics.c, "particles": counts, "arch": be.arch,
              "resolved_arch": be.resolved, "precision": be.precision,
              "setup_seconds": setup_s, **d, "observables": obs}
    if args.json:
        print(json.dumps(result, indent=2, default=float))
        return 0

    h = stats.health
    e0, e1 = stats.energy_start, h.energy
    de = f" ({(e1 - e0) / abs(e0) * 100:+.2f} %)" if e0 else ""
    binding = ", ".join(f"{k} {v}" for k, v in stats.binding.most_common())
    left = ", ".join(f"{v} {k}" for k, v in h.left.items()) or "none"
    size = ", ".join(f"{k} {v:g}" for k, v in val.items() if k not in ("l0", "t_end"))
    print(f"scene {name}: {args.dim}D, l0 = {val['l0']:g} m, {size}; gradient {args.gradient}; "
          f"arch {be.resolved}, {be.precision}")
    print(f"  particles   {_fmt_counts(counts)}")
    print(f"  simulated   {stats.time * 1e3:.4g} ms in {stats.steps:,} steps; dt "
          f"{stats.dt_min:.3g} .. {stats.dt_max:.3g} s; steps bound by: {binding}")
    print(f"  health      max speed {h.max_speed:.4g} m/s (peak {peak['speed']:.4g}, "
          f"c = {scene.physics.c:.4g}); max density excess n/n0 - 1 = "
          f"{h.max_density_excess:.4g} (peak {peak['excess']:.4g})")
    print(f"              energy {e0:.6g} J -> {e1:.6g} J{de}; left the domain: {left}")
    if obs:
        print(f"  result      {obs['text']}")
    rate = stats.steps / stats.wall_seconds if stats.wall_seconds > 0 else math.nan
    print(f"  wall time   {setup_s + stats.wall_seconds:.2f} s (set-up {setup_s:.2f} s, "
          f"stepping {stats.wall_seconds:.2f} s incl. compiling, {rate:.1f} steps/s)")
    return 0


# ---- bench -----------------------------------------------------------------------------------
BENCH_EPILOG = """\
examples:
  crowndemo bench                             # N = 100000 and 300000, 20 steps, table
  crowndemo bench --n 2000 --steps 3 --json   # a quick check
  crowndemo bench --arch cuda --n 1000000     # on an NVIDIA GPU
  crowndemo bench --record                    # append the results to BENCHMARKS.md

The scene is a k x k x kz block of water (k = round(N^(1/3)), l0 = 1 mm, re = 2.1 l0) resting
in a 3D tank with walls. particle-steps/s = fluid particles x steps / seconds; the first steps
(JIT compile) are not timed and are reported as compile_s.
"""


def _repo_root() -> str:
    return os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _bench(args, argv: Sequence[str]) -> int:
    from . import bench

    ns = args.n or list(bench.DEFAULT_NS)
    for n in ns:
        if n < 1:
            raise ParameterError("n", n, "an integer >= 1 (fluid particles)", "command line")
    if args.steps < 1:
        raise ParameterError("steps", args.steps, "an integer >= 1", "command line")
    _start_backend(args)

    def progress(r):
        if not args.json:
            print(f"  N = {r['particles']['fluid']:,}: {r['particle_steps_per_s']:.3e} "
                  f"particle-steps/s", file=sys.stderr, flush=True)

    results = bench.run(ns, args.steps, on_result=progress)
    if args.json:
        print(json.dumps(results[0] if len(results) == 1 else results, indent=2))
    else:
        print(bench.text_table(results))
    if args.record:
        path = os.path.join(_repo_root(), "BENCHMARKS.md")
        bench.record(results, " ".join([PROG] + [shlex.quote(a) for a in argv]), path)
        print(f"{PROG}: appended to {path}", file=sys.stderr)
    return 0


# ---- the parser ------------------------------------------------------------------------------
MAIN_EPILOG = """\
examples:
  crowndemo info --dim 3 --l0 1e-4               # constants and time-step limits
  crowndemo scene dam-break --dim 3 --t-end 0.05  # a short 3D dam break (make demo)
  crowndemo bench --n 100000 --steps 20          # particle-steps per second

Run 'crowndemo COMMAND --help' for the options of a command.
Exit status: 0 ok, 2 a usage or parameter error, 3 the simulation became unstable.
"""


def build_parser() -> argparse.ArgumentParser:
    common = [_backend_options()]
    parser = _Parser(prog=PROG, formatter_class=_Fmt, epilog=MAIN_EPILOG,
                     description="Milk-crown demo: the explicit MPS particle method in Taichi.")
    parser.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    p = sub.add_parser("info", parents=common, formatter_class=_Fmt, epilog=INFO_EPILOG,
                       help="derived constants (n0, lambda0, C, ...) and time-step limits",
                       description="Derived constants of the explicit MPS model and every "
                                   "time-step limit, with the one that binds.")
    p.add_argument("--dim", type=int, required=True, metavar="D", help="dimension, 2 or 3")
    p.add_argument("--l0", type=float, required=True, metavar="M", help="particle spacing [m]")
    p.add_argument("--re-ratio", type=float, default=2.1, help="re / l0 (default: 2.1)")
    p.add_argument("--sigma", type=float, default=0.0728,
                   help="surface tension [N/m] (default: 0.0728, water; 0 turns it off)")
    p.add_argument("--rho", type=float, default=998.0, help="density [kg/m^3] (default: 998)")
    p.add_argument("--nu", type=float, default=1.0e-6,
                   help="kinematic viscosity [m^2/s] (default: 1e-6; 0 turns it off)")
    p.add_argument("--speed", type=float, default=1.0,
                   help="expected maximum speed v [m/s] for the Courant limit (default: 1)")
    p.add_argument("--sound-speed", type=float, default=None,
                   help="artificial sound speed c [m/s] (default: 5 x speed, S8)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=lambda a, argv: _info(a))

    p = sub.add_parser("scene", formatter_class=_Fmt, epilog=SCENE_EPILOG,
                       help="run a reference scene (tank, dam-break, patch) and summarise it",
                       description="Run a reference scene and print a summary: particles, "
                                   "steps, dt and the limits that bound it, health, wall time.")
    scene_sub = p.add_subparsers(dest="scene", metavar="NAME", required=True)
    for name in SCENES:
        q = scene_sub.add_parser(name, parents=common, formatter_class=_Fmt,
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
        q.add_argument("--courant", type=float, default=_NUMERICS.courant, metavar="X",
                       help="velocity Courant number v dt / l0 (default: %(default)g, S5)")
        q.add_argument("--acoustic", type=float, default=_NUMERICS.acoustic, metavar="X",
                       help="acoustic Courant number c dt / l0 (default: %(default)g, S6)")
        q.add_argument("--gradient", choices=GRADIENT_FORMS, default="pmin",
                       help="pressure-gradient form: seed (P_j - P_i), pmin (P_j - Pmin_i), "
                            "sum (P_j + P_i) (default: pmin)")
        q.add_argument("--json", action="store_true", help="print the summary as one JSON object")
        q.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
        q.set_defaults(func=lambda a, argv: _scene(a))

    p = sub.add_parser("bench", parents=common, formatter_class=_Fmt, epilog=BENCH_EPILOG,
                       help="particle-steps per second of the full step on a 3D block",
                       description="Time the full explicit MPS step on a 3D block of water "
                                   "resting in a tank.")
    p.add_argument("--n", type=int, nargs="+", metavar="N",
                   help="fluid particles, one run each (default: 100000 300000)")
    p.add_argument("--steps", type=int, default=20, metavar="S", help="timed steps per run (default: 20)")
    p.add_argument("--json", action="store_true",
                   help="one JSON object per N (a list when several)")
    p.add_argument("--record", action="store_true",
                   help="append a section (machine, arch, date, command, table) to BENCHMARKS.md "
                        "at the repository root")
    p.set_defaults(func=_bench)
    return parser


def _error(message: str) -> int:
    print(f"{PROG}: error: {message}", file=sys.stderr)
    return 2


def _parameter_message(e: ParameterError) -> str:
    opt = OPTION_OF.get(e.key)
    where = f" (option {opt})" if opt else ""
    return f"{e.key} = {e.value!r} is out of range; allowed: {e.allowed}{where}"


def main(argv: Optional[Sequence[str]] = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except UsageError as e:
        return _error(str(e))
    except SystemExit as e:            # --help, --version
        return e.code if isinstance(e.code, int) else 0
    try:
        return args.func(args, argv)
    except ParameterError as e:
        return _error(_parameter_message(e))
    except BackendError as e:
        return _error(str(e))
    except InstabilityError as e:
        print(f"{PROG}: {e}", file=sys.stderr)
        return 3
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130


__all__ = ["main", "build_parser"]
