"""The ``crowndemo`` command line: ``presets``, ``info``, ``run``, ``scene`` and ``bench``.

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
from .config import DEFAULT_QUALITY, QUALITIES, PresetError  # noqa: E402
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
             "courant": "--courant", "acoustic": "--acoustic", "max_steps": "--max-steps"}


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
  crowndemo info 3m-drop                             # a preset at draft quality: everything
  crowndemo info 3m-drop --quality seed --json       # ~11.7M particles: counts, memory, time
  crowndemo info 2m-drop --set scene.height=1.5      # with an override
  crowndemo info --dim 3 --l0 1e-4                   # no preset: water at 0.1 mm, 1 m/s
  crowndemo info --dim 3 --l0 5e-5 --speed 8         # the seed's 8 m/s drop impact
  crowndemo info --dim 2 --l0 1e-3 --nu 1e-3 --json  # a viscous liquid, as JSON

With PRESET: every resolved value and where it came from, n0, lambda0, C, the sound speed,
each time-step limit and the one that binds, particles by kind, memory, steps to the end
time, a rough run time, and what the scene leaves out. Without: the constants and limits of
a lattice given by --dim and --l0 (and --speed, --rho, --nu, --sigma, ...).
Pure host computation: no Taichi kernel runs (the backend options are accepted and ignored).
n0 and lambda0 come from a perfect lattice (S13), C from the cut-plane energy balance (S23).
"""

# the lattice options of `info` without a preset, and their defaults
INFO_LATTICE = {"dim": ("--dim", None), "l0": ("--l0", None), "re_ratio": ("--re-ratio", 2.1),
                "sigma": ("--sigma", 0.0728), "rho": ("--rho", 998.0), "nu": ("--nu", 1.0e-6),
                "speed": ("--speed", 1.0), "sound_speed": ("--sound-speed", None)}


def _info(args) -> int:
    given = [opt for key, (opt, _) in INFO_LATTICE.items() if getattr(args, key) is not None]
    if args.preset is not None:
        if given:
            raise UsageError(f"{', '.join(given)}: not with a PRESET; change a preset with "
                             "--set (e.g. --set scene.speed=7) (see 'crowndemo info --help')")
        return _info_preset(args)
    if args.quality is not None or args.sets:
        raise UsageError("--quality and --set need a PRESET (see 'crowndemo info --help')")
    missing = [INFO_LATTICE[k][0] for k in ("dim", "l0") if getattr(args, k) is None]
    if missing:
        raise UsageError(f"the following arguments are required: {', '.join(missing)} "
                         "(or a PRESET) (see 'crowndemo info --help')")
    for key, (_, default) in INFO_LATTICE.items():
        if getattr(args, key) is None:
            setattr(args, key, default)
    return _info_lattice(args)


def _info_lattice(args) -> int:
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


class _StopRun(Exception):
    """Raised from the step callback to end a run early (--max-steps)."""


def _simulate(sim, t_end: float, quiet: bool, frame_times: Sequence[float] = (),
              max_steps: Optional[int] = None) -> Dict:
    """Run ``sim`` to ``t_end`` (or ``max_steps``) with a progress line on stderr every ~2 s
    (simulated time, steps/s, ETA); returns the stats, the peak health figures and whether
    the run stopped early."""
    h0 = sim.stats.health
    peak = {"speed": h0.max_speed, "excess": h0.max_density_excess}
    prog = {"t": time.perf_counter(), "steps": 0, "sim_t": 0.0}

    def on_step(s):
        h = s.stats.health
        peak["speed"] = max(peak["speed"], h.max_speed)
        peak["excess"] = max(peak["excess"], h.max_density_excess)
        now = time.perf_counter()
        if s.stats.steps == 1:          # the first step compiles the kernels: not in the rate
            if not quiet:
                print(f"  first step (compiling) {now - prog['t']:.1f} s", file=sys.stderr,
                      flush=True)
            prog["t"], prog["steps"], prog["sim_t"] = now, 1, s.stats.time
        elif not quiet and now - prog["t"] >= PROGRESS_EVERY_S:
            rate = (s.stats.steps - prog["steps"]) / (now - prog["t"])
            sim_rate = (s.stats.time - prog["sim_t"]) / (now - prog["t"])
            left = (t_end - s.stats.time) / sim_rate if sim_rate > 0 else math.inf
            if max_steps is not None and rate > 0:
                left = min(left, (max_steps - s.stats.steps) / rate)
            print(f"  t = {s.stats.time * 1e3:8.3f} / {t_end * 1e3:g} ms  step {s.stats.steps:6d}"
                  f"  {rate:7.1f} steps/s  ETA {_clock(left)}  max speed {h.max_speed:.3g} m/s",
                  file=sys.stderr, flush=True)
            prog["t"], prog["steps"], prog["sim_t"] = now, s.stats.steps, s.stats.time
        if max_steps is not None and s.stats.steps >= max_steps:
            raise _StopRun

    stopped = False
    try:
        stats = sim.run(t_end, frame_times=frame_times, on_step=on_step)
    except _StopRun:
        stats, stopped = sim.stats, True
    return {"stats": stats, "peak": peak, "stopped_early": stopped}


def _clock(seconds: float) -> str:
    if not math.isfinite(seconds):
        return "--:--"
    s = int(round(seconds))
    if s >= 3600:
        return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}"
    return f"{s // 60}:{s % 60:02d}"


def _run_result(run: Dict, counts: Dict[str, int], setup_s: float) -> Dict:
    """The JSON part shared by `scene` and `run`: stats, health with peaks, particles."""
    d = run["stats"].as_dict()
    d["health"]["peak_max_speed_m_s"] = run["peak"]["speed"]
    d["health"]["peak_max_density_excess"] = run["peak"]["excess"]
    return {"particles": counts, "setup_seconds": setup_s, **d}


def _print_summary(head: str, run: Dict, counts: Dict[str, int], sound_speed: float,
                   setup_s: float, obs: Optional[Dict] = None) -> None:
    """The summary of a run on stdout: particles, steps and dt with the limits that bound it,
    health, an observable when there is one, wall time."""
    stats, peak = run["stats"], run["peak"]
    h = stats.health
    e0, e1 = stats.energy_start, h.energy
    de = f" ({(e1 - e0) / abs(e0) * 100:+.2f} %)" if e0 else ""
    binding = ", ".join(f"{k} {v}" for k, v in stats.binding.most_common())
    left = ", ".join(f"{v} {k}" for k, v in h.left.items()) or "none"
    print(head)
    print(f"  particles   {_fmt_counts(counts)}")
    early = " (stopped early: --max-steps)" if run.get("stopped_early") else ""
    print(f"  simulated   {stats.time * 1e3:.4g} ms in {stats.steps:,} steps{early}; dt "
          f"{stats.dt_min:.3g} .. {stats.dt_max:.3g} s; steps bound by: {binding}")
    print(f"  health      max speed {h.max_speed:.4g} m/s (peak {peak['speed']:.4g}, "
          f"c = {sound_speed:.4g}); max density excess n/n0 - 1 = "
          f"{h.max_density_excess:.4g} (peak {peak['excess']:.4g})")
    print(f"              energy {e0:.6g} J -> {e1:.6g} J{de}; left the domain: {left}")
    if obs:
        print(f"  result      {obs['text']}")
    rate = stats.steps / stats.wall_seconds if stats.wall_seconds > 0 else math.nan
    print(f"  wall time   {setup_s + stats.wall_seconds:.2f} s (set-up {setup_s:.2f} s, "
          f"stepping {stats.wall_seconds:.2f} s incl. compiling, {rate:.1f} steps/s)")


def _scene(args) -> int:
    from .core import simulator_for

    name = args.scene
    be = _start_backend(args)
    t0 = time.perf_counter()
    scene, val = _build_scene(name, args)
    sim = simulator_for(scene)
    setup_s = time.perf_counter() - t0
    t_end = val["t_end"]
    if not args.quiet:
        print(f"{PROG}: scene {name}, {args.dim}D, {len(scene.pos):,} particles, arch "
              f"{be.resolved}, {be.precision}; running to {t_end * 1e3:g} ms "
              "(the first step compiles the kernels)", file=sys.stderr, flush=True)
    run = _simulate(sim, t_end, args.quiet)
    obs = _observables(name, scene, sim)
    counts = sim.counts()
    result = {"scene": name, "dim": args.dim, "parameters": val, "gradient": args.gradient,
              "sound_speed_m_s": scene.physics.c, "arch": be.arch,
              "resolved_arch": be.resolved, "precision": be.precision,
              **_run_result(run, counts, setup_s), "observables": obs}
    if args.json:
        print(json.dumps(result, indent=2, default=float))
        return 0
    size = ", ".join(f"{k} {v:g}" for k, v in val.items() if k not in ("l0", "t_end"))
    head = (f"scene {name}: {args.dim}D, l0 = {val['l0']:g} m, {size}; gradient "
            f"{args.gradient}; arch {be.resolved}, {be.precision}")
    _print_summary(head, run, counts, scene.physics.c, setup_s, obs)
    return 0


# ---- presets: list, info, run ------------------------------------------------------------------
PRESET_HELP = "a preset name (see 'crowndemo presets') or a path to a preset YAML file"
SET_HELP = ("override a preset value, KEY.PATH=VALUE with VALUE read as YAML, e.g. "
            "scene.speed=7, quality.draft.l0=4e-4, numerics.courant=0.1; repeatable; "
            "an empty VALUE restores the default")

PRESETS_EPILOG = """\
examples:
  crowndemo presets                 # name, title, particles and run time per quality
  crowndemo presets --lang ja       # titles in Japanese
  crowndemo presets --rate 5e7      # estimate for a machine that does 5e7 particle-steps/s
  crowndemo presets --json

The presets are the YAML files in presets/ at the repository root ($CROWNDEMO_PRESETS names
another folder). Particle counts come from building each scene with numpy (no kernel runs);
counts marked ~ are scaled from a build at a coarser spacing. The run time is rough: compile
+ (every particle) x steps / rate, with steps = t_end / dt at the drop's speed and the rate
from the newest CPU section of BENCHMARKS.md; a splash faster than the drop takes smaller
steps, so real runs take longer.
"""

RUN_EPILOG = """\
examples:
  crowndemo run quick                               # a small 3D crown, draft quality
  crowndemo run 3m-drop --quality booth             # the seed's first run, ~289k particles
  crowndemo run 3m-drop --set scene.speed=6 --set quality.draft.t_end=5e-4
  crowndemo run quick --then quick-2d 20cm-drop     # one after another, one process
  crowndemo run my-preset.yaml                      # a file; it may `extends: 3m-drop`
  crowndemo run 2m-drop --arch cuda --quality seed  # ~11.7M particles, on a GPU

--quality and --set apply to every preset of the run. Every preset is checked before the
first one starts; a mistake is reported as
  crowndemo: error: FILE: KEY = VALUE: WHY; allowed: RANGE
A progress line (simulated time, steps/s, ETA) goes to stderr every ~2 s; the summary to
stdout. An unstable run stops with exit status 3 and says what broke.
"""


def _load_preset(spec: str, args, quality: Optional[str] = None):
    from . import config
    return config.load(spec, quality or args.quality or config.DEFAULT_QUALITY, args.sets)


def _preset_facts(r, tp) -> Dict:
    """Every resolved value and derived quantity of a preset at one quality (no kernels)."""
    from dataclasses import asdict

    from .config import estimate
    from .core.lattice import LatticeConstants
    from .core.params import Model
    from .scenes.crown import crown_base_radius

    ph, s, liq = r.physics, r.scene, r.liquid
    lat = LatticeConstants.compute(ph.dim, ph.l0, ph.re_ratio, ph.rho, ph.sigma)
    est = estimate.summary(r, tp)
    lim, dt = est["limits_s"], est["dt_s"]
    ties = [k for k, v in lim.items() if v <= dt * (1 + 1e-9)]
    U, D, h = s["speed"], s["drop"], s["film"]
    mu = liq["rho"] * liq["nu"]
    we = liq["rho"] * U * U * D / liq["sigma"] if liq["sigma"] > 0 else math.inf
    re_num = U * D / liq["nu"] if liq["nu"] > 0 else math.inf
    oh = mu / math.sqrt(liq["rho"] * liq["sigma"] * D) if liq["sigma"] > 0 else math.inf
    k = we * oh ** -0.4 if mu > 0 and liq["sigma"] > 0 else math.inf
    k_splash = 2100.0 + 5880.0 * (h / D) ** 1.44
    impact = s["gap"] / U
    numerics = {key: (None if isinstance(v, float) and math.isinf(v) else v)
                for key, v in asdict(r.numerics).items() if key != "allow_unsafe_dt"}
    return {
        "preset": r.name, "file": r.label, "extends_chain": r.doc.chain, "quality": r.quality,
        "title": r.title, "description": r.description, "dim": r.dim,
        "scene": {"floor_m": s["floor"], "film_m": h, "drop_m": D, "speed_m_s": U,
                  "height_m": s.get("height"), "gap_m": s["gap"],
                  "gravity_m_s2": s["gravity"], "t_end_s": s["t_end"],
                  "frame_interval_s": s.get("frame_interval"), "frames": len(r.frame_times()),
                  "trim": s["trim"], "impact_at_s": impact},
        "sources": {k: {"key": key, "file": src} for k, (key, src) in sorted(r.where.items())},
        "liquid": {"name": liq["name"], "rho_kg_m3": liq["rho"], "nu_m2_s": liq["nu"],
                   "sigma_N_m": liq["sigma"]},
        "l0_m": ph.l0, "re_ratio": ph.re_ratio, "re_m": lat.re, "drop_over_l0": D / ph.l0,
        "film_over_l0": h / ph.l0, "n0": lat.n0, "lambda0": lat.lambda0,
        "lambda0_over_l0_sq": lat.lambda0 / lat.l0 ** 2, "C": lat.C, "mass": lat.mass,
        "mass_unit": "kg" if ph.dim == 3 else "kg/m (per unit depth)",
        "sound_speed_m_s": ph.c,
        "sound_speed_source": "given" if s.get("sound_speed") is not None else "5 x speed",
        "numerics": numerics, "model": Model.describe(r.model),
        "limits_s": {key: lim.get(key) for key in ("courant", "acoustic", "viscous",
                                                    "capillary", "dt_max")
                     if key != "dt_max" or key in lim},
        "dt_s": dt, "binding": est["binding"], "binding_ties": ties,
        "particles": est["particles"], "memory_bytes": est["memory_bytes"],
        "steps": est["steps"], "steps_at_U": est["steps_at_U"],
        "splash_speed_m_s": est["splash_speed_m_s"],
        "dt_after_contact_s": est["dt_after_contact_s"],
        "binding_after_contact": est["binding_after_contact"],
        "run_seconds_estimate": est["run_seconds"],
        "run_seconds_at_U": est["run_seconds_at_U"],
        "throughput": {"fluid_particle_steps_per_s": tp.rate,
                       "all_particle_steps_per_s": tp.rate_total, "compile_s": tp.compile_s,
                       "bytes_per_particle": tp.bytes_per_particle, "source": tp.source},
        "dimensionless": {"weber": we, "reynolds": re_num, "ohnesorge": oh,
                          "cossali_K": k, "cossali_K_splash": k_splash,
                          "splash_predicted": k > k_splash,
                          "crown_base_radius_at_t_end_m":
                              crown_base_radius(s["t_end"] - impact, U, D, h)},
        "left_out": est["particles"]["left_out"],
    }


def _mm(x: float) -> str:
    return f"{x * 1e3:.4g} mm"


def _info_preset(args) -> int:
    import textwrap

    from .config import estimate

    r = _load_preset(args.preset, args)
    tp = estimate.throughput()
    f = _preset_facts(r, tp)
    if args.json:
        print(json.dumps(f, indent=2, default=float))
        return 0
    s, liq, p = f["scene"], f["liquid"], f["particles"]
    src = {k: v["key"] for k, v in f["sources"].items()}
    lang = "en"
    print(f"preset {r.name}, quality {r.quality} ({r.label}): {r.dim}D")
    if len(r.doc.chain) > 1:
        print(f"  extends     {' <- '.join(reversed(r.doc.chain))}")
    print(f"  title       {f['title'].get(lang, '')}")
    if f["description"].get(lang):
        for i, line in enumerate(textwrap.wrap(f["description"][lang], 82)):
            print(f"  {'about' if i == 0 else '':<11} {line}")
    speed = (f"U = {s['speed_m_s']:.4g} m/s = sqrt(2 g H), H = {s['height_m']:g} m"
             if s["height_m"] is not None else f"U = {s['speed_m_s']:.4g} m/s")
    floor = "square floor" if r.dim == 3 else "wide slice"
    print(f"  scene       {_mm(s['floor_m'])} {floor}, film h = {_mm(s['film_m'])}, drop D = "
          f"{_mm(s['drop_m'])}, gap {_mm(s['gap_m'])}")
    print(f"              {speed} ({src['speed']}); contact at t = {s['impact_at_s'] * 1e3:.4g} ms")
    frames = (f"; frames every {s['frame_interval_s'] * 1e3:g} ms ({s['frames']})"
              if s["frame_interval_s"] else "; no frames")
    print(f"              t_end = {s['t_end_s'] * 1e3:g} ms ({src['t_end']}){frames}")
    print(f"  liquid      {liq['name']}: rho {liq['rho_kg_m3']:g} kg/m^3, nu {liq['nu_m2_s']:g} "
          f"m^2/s, sigma {liq['sigma_N_m']:g} N/m; gravity {s['gravity_m_s2']:g} m/s^2")
    dl = f["dimensionless"]
    verdict = "a splash" if dl["splash_predicted"] else "no splash"
    print(f"  numbers     We = {dl['weber']:,.0f}, Re = {dl['reynolds']:,.0f}, Oh = "
          f"{dl['ohnesorge']:.3g}; Cossali K = We Oh^-0.4 = {dl['cossali_K']:.3g} against "
          f"{dl['cossali_K_splash']:.4g}: {verdict} predicted")
    print(f"              crown base radius at t_end (Yarin & Weiss): "
          f"{_mm(dl['crown_base_radius_at_t_end_m'])}")
    print(f"  resolution  l0 = {_mm(f['l0_m'])} ({src['l0']}): D/l0 = {f['drop_over_l0']:.3g}, "
          f"h/l0 = {f['film_over_l0']:.3g}; re = {f['re_ratio']:g} l0 = {_mm(f['re_m'])}")
    c_unit = "J/m^3" if r.dim == 3 else "N/m^3 (per unit depth)"
    print(f"  constants   n0 {f['n0']:.6g}, lambda0 {f['lambda0']:.6g} m^2 (= "
          f"{f['lambda0_over_l0_sq']:.6g} l0^2), C {f['C']:.6g} {c_unit}, mass {f['mass']:.6g} "
          f"{f['mass_unit']}")
    print(f"  sound speed c = {f['sound_speed_m_s']:.4g} m/s ({f['sound_speed_source']})")
    n = f["numerics"]
    beta = n["beta"] if n["beta"] is not None else r.numerics.free_surface_beta(r.dim)
    print(f"  numerics    gradient {n['pressure_gradient']}; safety courant {n['courant']:g}, "
          f"acoustic {n['acoustic']:g}, viscous {n['viscous']:g}, capillary {n['capillary']:g}; "
          f"beta {beta:g}")
    print(f"              abort at density excess {n['max_density_excess']:g}, Mach "
          f"{n['max_mach']:g}, {n['max_out_fraction']:g} of the fluid out; dt_max "
          f"{n['dt_max'] if n['dt_max'] is not None else 'none'}, fixed dt "
          f"{n['fixed_dt'] if n['fixed_dt'] is not None else 'none (adaptive)'}")
    rules = {"courant": f"{n['courant']:g} l0 / U", "acoustic": f"{n['acoustic']:g} l0 / c",
             "viscous": f"{n['viscous']:g} l0^2 / nu",
             "capillary": f"{n['capillary']:g} sqrt(rho l0^3 / (2 pi sigma))",
             "dt_max": "numerics.dt_max"}
    print("  time step   limits at v = U; dt = the smallest:")
    for name, v in f["limits_s"].items():
        if v is None:
            why = "no viscosity (nu = 0)" if name == "viscous" else "no surface tension"
            print(f"    {name:<10} {rules[name]:<34} {'off':>11}    {why}")
        else:
            mark = "  <- binds" if name in f["binding_ties"] else ""
            print(f"    {name:<10} {rules[name]:<34} {v:11.4g} s{mark}")
    approx = "" if p["exact"] else "~"
    how = ("" if p["exact"] else f"; scaled from the scene built at l0 = {_mm(p['built_l0'])}")
    print(f"  particles   {approx}{p['fluid']:,} fluid (film {p['n_film']:,}, drop "
          f"{p['n_drop']:,}), {approx}{p['wall']:,} wall, {approx}{p['dummy']:,} dummy "
          f"({approx}{p['total']:,} total{how})")
    print(f"  memory      ~{estimate.human_bytes(f['memory_bytes'])} ({tp.bytes_per_particle:g} "
          f"bytes per particle with the cell grid, f32)")
    print(f"  steps       ~{f['steps']:,} to t_end: dt {f['dt_s']:.3g} s until contact, then "
          f"{f['dt_after_contact_s']:.3g} s ({f['binding_after_contact']} at the splash's "
          f"~{f['splash_speed_m_s']:.3g} m/s = {estimate.SPLASH_MACH:g} c); at least "
          f"{f['steps_at_U']:,} (v = U all along)")
    print(f"  run time    ~{estimate.human_seconds(f['run_seconds_estimate'])} on the CPU of "
          f"BENCHMARKS.md (at least {estimate.human_seconds(f['run_seconds_at_U'])}): "
          f"{tp.rate_total:.3g} particle-steps/s counting every particle, / "
          f"{estimate.CROWN_COST:g} for a crown step, + {tp.compile_s:g} s compiling")
    left = f["left_out"] or ["nothing"]
    for i, line in enumerate(left):
        print(f"  {'left out' if i == 0 else '':<11} {'- ' if f['left_out'] else ''}{line}")
    return 0


def _display_width(text: str) -> int:
    import unicodedata
    return sum(2 if unicodedata.east_asian_width(ch) in "WF" else 1 for ch in text)


def _pad(text: str, width: int) -> str:
    return text + " " * max(width - _display_width(text), 0)


def _presets(args) -> int:
    import textwrap

    from . import config
    from .config import estimate, schema

    tp = estimate.throughput(rate=args.rate)
    folder = config.presets_dir()
    rows, errors = [], []
    for name in config.preset_names(folder):
        try:
            doc = config.load_document(name)
            values = schema.validate(doc)
            row = {"name": name, "file": doc.label, "dim": values["dim"],
                   "title": values["title"], "description": values.get("description", {}),
                   "extends": doc.chain[-2] if len(doc.chain) > 1 else None, "qualities": {}}
            for q in config.QUALITIES:
                if q not in values["quality"]:
                    continue
                r = config.resolve(doc, q)
                e = estimate.summary(r, tp)
                part = e["particles"]
                row["qualities"][q] = {
                    "l0_m": r.l0, "t_end_s": r.t_end, "speed_m_s": r.speed,
                    "particles": {k: part[k] for k in ("fluid", "wall", "dummy", "total")},
                    "exact_count": part["exact"], "steps": e["steps"], "dt_s": e["dt_s"],
                    "binding": e["binding"], "run_seconds_estimate": e["run_seconds"],
                    "memory_bytes": e["memory_bytes"]}
            rows.append(row)
        except PresetError as e:
            errors.append(e)
    if args.json:
        print(json.dumps({"folder": str(folder), "throughput": {
            "fluid_particle_steps_per_s": tp.rate, "all_particle_steps_per_s": tp.rate_total,
            "compile_s": tp.compile_s, "source": tp.source}, "presets": rows}, indent=2))
    else:
        lang = args.lang
        titles = [row["title"].get(lang) or row["title"]["en"] for row in rows]
        tw = min(max([_display_width(t) for t in titles] + [5]), 60)
        nw = max([len(row["name"]) for row in rows] + [4])
        head = f"{'NAME':<{nw}}  DIM  {_pad('TITLE', tw)}"
        for q in config.QUALITIES:
            head += f"  {q.upper():<15}"
        print(f"presets in {config.display(folder)}{os.sep}: fluid particles and a rough run "
              "time per quality on this machine")
        print(head.rstrip())
        for row, title in zip(rows, titles):
            line = f"{row['name']:<{nw}}  {row['dim']}D   {_pad(title, tw)}"
            for q in config.QUALITIES:
                e = row["qualities"].get(q)
                if e is None:
                    cell = "-"
                else:
                    approx = "" if e["exact_count"] else "~"
                    count = approx + estimate.human_count(e["particles"]["fluid"])
                    cell = f"{count:>6} {estimate.human_seconds(e['run_seconds_estimate']):>8}"
                line += f"  {cell:<15}"
            print(line.rstrip())
        for line in textwrap.wrap(
                f"~: particle count scaled from a coarser build. Run time: compile + every "
                f"particle x steps x {estimate.CROWN_COST:g} (a crown step's cost) / "
                f"{tp.rate_total:.3g} particle-steps/s ({tp.rate:.3g} fluid; {tp.source}); "
                f"steps: dt at the drop's speed until contact, then at the splash's "
                f"{estimate.SPLASH_MACH:g} c (measured). Details: crowndemo info PRESET "
                f"--quality Q.", 96):
            print(line)
    for e in errors:
        _error(str(e))
    return 2 if errors else 0


def _run(args) -> int:
    from .core import simulator_for

    if args.max_steps is not None and args.max_steps < 1:
        raise ParameterError("max_steps", args.max_steps, "an integer >= 1", "command line")
    specs = [args.preset] + list(args.then or [])
    resolved = [_load_preset(spec, args) for spec in specs]     # every mistake before any run
    be = _start_backend(args)
    results = []
    t_all = time.perf_counter()
    for i, r in enumerate(resolved):
        t0 = time.perf_counter()
        scene = r.build_scene()
        sim = simulator_for(scene)
        setup_s = time.perf_counter() - t0
        if not args.quiet:
            nth = f" ({i + 1} of {len(resolved)})" if len(resolved) > 1 else ""
            print(f"{PROG}: run {r.name}{nth}, quality {r.quality}, {r.dim}D, "
                  f"{scene.counts()['fluid']:,} fluid of {len(scene.pos):,} particles, arch "
                  f"{be.resolved}, {be.precision}; running to {r.t_end * 1e3:g} ms "
                  "(the first step compiles the kernels)", file=sys.stderr, flush=True)
        run = _simulate(sim, r.t_end, args.quiet, r.frame_times(), args.max_steps)
        counts = sim.counts()
        s = r.scene
        results.append({
            "preset": r.name, "file": r.label, "quality": r.quality, "dim": r.dim,
            "l0_m": r.l0, "speed_m_s": r.speed, "film_m": s["film"], "drop_m": s["drop"],
            "t_end_s": r.t_end, "gradient": r.numerics.pressure_gradient,
            "sound_speed_m_s": scene.physics.c, "arch": be.arch, "resolved_arch": be.resolved,
            "precision": be.precision, "stopped_early": run["stopped_early"],
            **_run_result(run, counts, setup_s), "left_out": scene.info.get("left_out", [])})
        if not args.json:
            head = (f"preset {r.name} ({r.quality}): {r.dim}D, l0 = {r.l0:g} m, U = "
                    f"{r.speed:.4g} m/s, film {s['film']:g} m, drop {s['drop']:g} m; gradient "
                    f"{r.numerics.pressure_gradient}; arch {be.resolved}, {be.precision}")
            _print_summary(head, run, counts, scene.physics.c, setup_s)
    if args.json:
        print(json.dumps(results[0] if len(results) == 1 else results, indent=2, default=float))
    elif len(results) > 1:
        print(f"{len(results)} runs in {time.perf_counter() - t_all:.2f} s")
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
  crowndemo presets                              # the presets, particles and run time
  crowndemo info 3m-drop --quality booth         # every parameter of a preset, no kernels
  crowndemo run quick                            # a small 3D crown (well under a minute)
  crowndemo run 3m-drop --set scene.speed=6      # a preset with an override
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
    p.add_argument("preset", nargs="?", metavar="PRESET",
                   help=PRESET_HELP + " (without it: --dim and --l0 describe a lattice)")
    p.add_argument("--quality", choices=QUALITIES, default=None,
                   help=f"quality rung of the preset (default: {DEFAULT_QUALITY})")
    p.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                   help=SET_HELP)
    p.add_argument("--dim", type=int, metavar="D", help="without PRESET: dimension, 2 or 3")
    p.add_argument("--l0", type=float, metavar="M",
                   help="without PRESET: particle spacing [m]")
    p.add_argument("--re-ratio", type=float, help="re / l0 (default: 2.1)")
    p.add_argument("--sigma", type=float,
                   help="surface tension [N/m] (default: 0.0728, water; 0 turns it off)")
    p.add_argument("--rho", type=float, help="density [kg/m^3] (default: 998)")
    p.add_argument("--nu", type=float,
                   help="kinematic viscosity [m^2/s] (default: 1e-6; 0 turns it off)")
    p.add_argument("--speed", type=float,
                   help="expected maximum speed v [m/s] for the Courant limit (default: 1)")
    p.add_argument("--sound-speed", type=float, default=None,
                   help="artificial sound speed c [m/s] (default: 5 x speed, S8)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=lambda a, argv: _info(a))

    p = sub.add_parser("presets", formatter_class=_Fmt, epilog=PRESETS_EPILOG,
                       help="list the presets: title, particles and run time per quality",
                       description="List the presets with their title, fluid particle count "
                                   "and a rough run time per quality (draft, booth, seed); no "
                                   "kernel runs.")
    p.add_argument("--lang", choices=("en", "ja"), default="en",
                   help="language of the titles (default: en)")
    p.add_argument("--rate", type=float, metavar="R",
                   help="fluid particle-steps per second to estimate with (default: the "
                        "newest CPU figure in BENCHMARKS.md)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=lambda a, argv: _presets(a))

    p = sub.add_parser("run", parents=common, formatter_class=_Fmt, epilog=RUN_EPILOG,
                       help="run a preset (a drop on a film) and summarise it",
                       description="Run a preset: a drop falling on a film "
                                   "(crowndemo.scenes.crown). Prints a progress line and a "
                                   "summary: particles, steps, dt and the limits that bound "
                                   "it, health, wall time.")
    p.add_argument("preset", metavar="PRESET", help=PRESET_HELP)
    p.add_argument("--quality", choices=QUALITIES, default=DEFAULT_QUALITY,
                   help="quality rung: draft (minutes on a CPU), booth (l0 ~0.3 mm), seed "
                        "(the seed's ~12M particles, a GPU) (default: %(default)s)")
    p.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                   help=SET_HELP)
    p.add_argument("--then", action="extend", nargs="+", default=[], metavar="PRESET",
                   help="presets to run afterwards, one after another in this process")
    p.add_argument("--max-steps", type=int, metavar="N",
                   help="stop each run after N steps (a smoke test)")
    p.add_argument("--json", action="store_true",
                   help="print the summary as one JSON object (a list with --then)")
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    p.set_defaults(func=lambda a, argv: _run(a))

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
    except UsageError as e:
        return _error(str(e))
    except PresetError as e:
        return _error(str(e))
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
