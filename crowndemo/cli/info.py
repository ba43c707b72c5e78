"""``crowndemo info``: every resolved value of a preset, or the constants and
time-step limits of a lattice; pure host computation."""
from __future__ import annotations

import math
import shlex
import sys
from typing import Dict

from .. import strictjson
from ..config.schema import LIQUID_KEYS, RUNG_KEYS, SCENE_KEYS, Field
from ..core import timestep
from ..core.health import starts_too_fast
from ..core.params import SOUND_SPEED_FACTOR, WATER, ParameterError
from .common import PRESET_HELP, Fmt, UsageError, add_quality, add_sets, load_preset


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
a lattice given by --dim and --l0 (and --speed, --rho, --nu, --sigma, ...), each within the
range of the preset key it matches (l0 <= 0.01 m as quality.*.l0, speed <= 50 m/s as
scene.speed, rho, nu and sigma as scene.liquid.*); a lattice whose time step would be below
1e-08 s is refused, as a preset's run refuses it.
Pure host computation: no Taichi kernel runs (the backend options are accepted and ignored).
n0 and lambda0 come from a perfect lattice (S13), C from the cut-plane energy balance (S23).
"""

# the lattice options of `info` without a preset, and their defaults
INFO_LATTICE = {"dim": ("--dim", None), "l0": ("--l0", None), "re_ratio": ("--re-ratio", 2.1),
                "sigma": ("--sigma", WATER["sigma"]), "rho": ("--rho", WATER["rho"]),
                "nu": ("--nu", WATER["nu"]),
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


# the name a ParameterError gives each lattice option (cli/common.py OPTION_OF turns it into
# the option) and the preset key whose range (config/schema.py) it shares
LATTICE_RANGES = {"l0": ("l0", RUNG_KEYS["l0"]), "re_ratio": ("re_ratio", SCENE_KEYS["re_ratio"]),
                  "rho": ("rho", LIQUID_KEYS["rho"]), "nu": ("nu", LIQUID_KEYS["nu"]),
                  "sigma": ("sigma", LIQUID_KEYS["sigma"]),
                  "speed": ("speed", SCENE_KEYS["speed"]),
                  "sound_speed": ("sound_speed", SCENE_KEYS["sound_speed"])}


def in_range(field: Field, value) -> bool:
    """Whether ``value`` is a finite number inside a schema Field's range."""
    return (not isinstance(value, bool) and isinstance(value, (int, float))
            and math.isfinite(value) and field.in_range(value))


def check_range(key: str, value, field: Field, source: str = "command line") -> None:
    """ParameterError naming ``key`` when ``value`` is outside the schema Field's range."""
    if not in_range(field, value):
        raise ParameterError(key, value, field.allowed(), source)


def _check_lattice_ranges(args) -> None:
    """The lattice options within the ranges of a preset's keys: l0 as quality.*.l0, the
    liquid as scene.liquid.*, the speeds and re_ratio as scene.*."""
    for opt, (key, field) in LATTICE_RANGES.items():
        value = getattr(args, opt)
        if value is not None:
            check_range(key, value, field, "info")


def ceil3(x: float) -> float:
    """``x`` rounded up to 3 significant digits: a ">=" bound that, printed, still passes."""
    step = 10.0 ** (math.floor(math.log10(x)) - 2)
    return math.ceil(x / step * (1 - 1e-12)) * step


def floor3(x: float) -> float:
    """``x`` rounded down to 3 significant digits: a "<=" bound that, printed, still passes."""
    step = 10.0 ** (math.floor(math.log10(x)) - 2)
    return math.floor(x / step * (1 + 1e-12)) * step


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


def _info_lattice(args) -> int:
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


def _preset_facts(r, tp) -> Dict:
    """Every resolved value and derived quantity of a preset at one quality (no kernels)."""
    from dataclasses import asdict

    from ..config import estimate
    from ..core.lattice import LatticeConstants
    from ..core.params import Model
    from ..core.step import max_particles
    from ..record.recorder import frame_times
    from ..scenes.crown import crown_base_radius
    from ..validate.verdicts import cossali

    ph, s, liq = r.physics, r.scene, r.liquid
    lat = LatticeConstants.compute(ph.dim, ph.l0, ph.re_ratio, ph.rho, ph.sigma)
    est = estimate.summary(r, tp)
    lim, dt = est["limits_s"], est["dt_s"]
    ties = [k for k, v in lim.items() if v <= dt * (1 + 1e-9)]
    U, D, h = s["speed"], s["drop"], s["film"]
    splash = cossali(U, D, h, liq["rho"], liq["nu"], liq["sigma"])
    re_num = U * D / liq["nu"] if liq["nu"] > 0 else math.inf
    impact = s["gap"] / U
    numerics = {key: (None if isinstance(v, float) and math.isinf(v) else v)
                for key, v in asdict(r.numerics).items() if key != "allow_unsafe_dt"}
    return {
        "preset": r.name, "file": r.label, "extends_chain": r.doc.files,
        "quality": r.quality,
        "title": r.title, "description": r.description, "dim": r.dim,
        "scene": {"floor_m": s["floor"], "film_m": h, "drop_m": D, "speed_m_s": U,
                  "height_m": s.get("height"), "gap_m": s["gap"],
                  "gravity_m_s2": s["gravity"], "t_end_s": s["t_end"],
                  "frame_interval_s": s.get("frame_interval"), "frames": len(frame_times(r)),
                  "trim": s["trim"], "impact_at_s": impact},
        "sources": {k: {"key": key, "file": src} for k, (key, src) in sorted(r.where.items())},
        "liquid": {"name": liq["name"], "rho_kg_m3": liq["rho"], "nu_m2_s": liq["nu"],
                   "sigma_N_m": liq["sigma"]},
        "l0_m": ph.l0, "re_ratio": ph.re_ratio, "re_m": lat.re, "drop_over_l0": D / ph.l0,
        "film_over_l0": h / ph.l0, "n0": lat.n0, "lambda0": lat.lambda0,
        "lambda0_over_l0_sq": lat.lambda0 / lat.l0 ** 2, "C": lat.C, "mass": lat.mass,
        "mass_unit": "kg" if ph.dim == 3 else "kg/m (per unit depth)",
        "sound_speed_m_s": ph.c,
        "sound_speed_source": s.get("sound_speed_source") or (
            "given" if s.get("sound_speed") is not None else f"{SOUND_SPEED_FACTOR:g} x speed"),
        "numerics": numerics, "model": Model.describe(r.model),
        "limits_s": {key: lim.get(key) for key in ("courant", "approach", "acoustic",
                                                    "viscous", "capillary", "dt_max")
                     if key not in ("dt_max", "approach") or key in lim},
        "dt_s": dt, "binding": est["binding"], "binding_ties": ties,
        "particles": est["particles"], "memory_bytes": est["memory_bytes"],
        "max_particles": max_particles(r.model),
        "steps": est["steps"], "steps_at_U": est["steps_at_U"],
        "splash_speed_m_s": est["splash_speed_m_s"],
        "relative_speed_m_s": est["relative_speed_m_s"],
        "dt_after_contact_s": est["dt_after_contact_s"],
        "binding_after_contact": est["binding_after_contact"],
        "run_seconds_estimate": est["run_seconds"],
        "run_seconds_at_U": est["run_seconds_at_U"],
        "compile_seconds": est["compile_seconds"],
        "throughput": {"fluid_particle_steps_per_s": tp.rate,
                       "all_particle_steps_per_s": tp.rate_total,
                       "bytes_per_particle": tp.bytes_per_particle, "source": tp.source},
        "dimensionless": {"weber": splash["We"], "reynolds": re_num, "ohnesorge": splash["Oh"],
                          "cossali_K": splash["K"], "cossali_K_splash": splash["K_threshold"],
                          "splash_predicted": splash["splash"],
                          "crown_base_radius_at_t_end_m":
                              crown_base_radius(s["t_end"] - impact, U, D, h)},
        "left_out": est["particles"]["left_out"],
    }


def _speed_in_c(v: float, c: float) -> str:
    """'8 m/s = 0.2 c': a speed and its ratio to the sound speed c."""
    return f"{v:.3g} m/s = {v / c:.2g} c"


def _mm(x: float) -> str:
    return f"{x * 1e3:.4g} mm"


def _info_preset(args) -> int:
    import textwrap

    from ..config import estimate

    r = load_preset(args.preset, args)
    tp = estimate.throughput()
    f = _preset_facts(r, tp)
    f["overrides"] = list(args.sets)
    if args.json:
        print(strictjson.dumps(f))
        return 0
    s, liq, p = f["scene"], f["liquid"], f["particles"]
    src = {k: v["key"] for k, v in f["sources"].items()}
    lang = "en"
    print(f"preset {r.name}, quality {r.quality} ({r.label}): {r.dim}D")
    if len(f["extends_chain"]) > 1:
        print(f"  extends     {' <- '.join(reversed(f['extends_chain']))}")
    if f["overrides"]:
        print("  overrides   " + " ".join("--set " + shlex.quote(o) for o in f["overrides"]))
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
    # as `record` writes them: t = 0 and every frame interval to t_end (record/recorder.py)
    frames = (f"; {s['frames']} frames, every {s['frame_interval_s'] * 1e3:g} ms from t = 0"
              if s["frame_interval_s"] else "; 1 frame (t = 0; no frame_interval)")
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
    relative = n["courant_speed"] == "relative"
    print(f"  numerics    gradient {n['pressure_gradient']}; safety courant {n['courant']:g}"
          + (f" on relative speeds, approach {n['approach']:g}" if relative else "") + ", "
          f"acoustic {n['acoustic']:g}, viscous {n['viscous']:g}, capillary {n['capillary']:g}; "
          f"beta {beta:g}")
    print("              collision model: " + (
        f"approaching pairs closer than {n['collision']:g} l0, restitution "
        f"{n['restitution']:g}" if n["collision"] > 0 else "off"))
    print(f"              abort at density excess {n['max_density_excess']:g}, Mach "
          f"{n['max_mach']:g}, {n['max_out_fraction']:g} of the fluid out; dt_max "
          f"{n['dt_max'] if n['dt_max'] is not None else 'none'}, fixed dt "
          f"{n['fixed_dt'] if n['fixed_dt'] is not None else 'none (adaptive)'}")
    rules = {"courant": f"{n['courant']:g} l0 / U" + (" (relative speed)" if relative else ""),
             "approach": f"{n['approach']:g} l0 / U", "acoustic": f"{n['acoustic']:g} l0 / c",
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
    if p["total"] > f["max_particles"]:
        need = r.l0 * (p["total"] / f["max_particles"]) ** (1.0 / r.dim)
        print(f"  too many    one simulator holds at most {f['max_particles']:,} particles "
              f"(Taichi's 32-bit field indices): a run would be refused; l0 >= ~{_mm(need)}")
    print(f"  memory      ~{estimate.human_bytes(f['memory_bytes'])} ({tp.bytes_per_particle:g} "
          f"bytes per particle with the cell grid, f32)")
    c = f["sound_speed_m_s"]          # the speeds are max(U, k c): state their own ratio
    speeds = f"the splash's ~{_speed_in_c(f['splash_speed_m_s'], c)}"
    if relative:
        speeds = f"a relative speed of ~{_speed_in_c(f['relative_speed_m_s'], c)}, {speeds}"
    print(f"  steps       ~{f['steps']:,} to t_end: dt {f['dt_s']:.3g} s until contact, then "
          f"{f['dt_after_contact_s']:.3g} s ({f['binding_after_contact']} at {speeds}); at "
          f"least {f['steps_at_U']:,} (v = U all along)")
    print(f"  run time    ~{estimate.human_seconds(f['run_seconds_estimate'])} on the CPU of "
          f"BENCHMARKS.md (at least {estimate.human_seconds(f['run_seconds_at_U'])}): "
          f"{tp.rate_total:.3g} particle-steps/s counting every particle, / "
          f"{estimate.CROWN_COST:g} for a crown step, + {f['compile_seconds']:g} s compiling "
          f"(a first run; 3-9 s with the kernels in Taichi's cache)")
    left = f["left_out"] or ["nothing"]
    for i, line in enumerate(left):
        print(f"  {'left out' if i == 0 else '':<11} {'- ' if f['left_out'] else ''}{line}")
    return 0


def register(sub, common) -> None:
    p = sub.add_parser("info", parents=common, formatter_class=Fmt, epilog=INFO_EPILOG,
                       help="derived constants (n0, lambda0, C, ...) and time-step limits",
                       description="Derived constants of the explicit MPS model and every "
                                   "time-step limit, with the one that binds.")
    p.add_argument("preset", nargs="?", metavar="PRESET",
                   help=PRESET_HELP + " (without it: --dim and --l0 describe a lattice)")
    add_quality(p, None, "quality rung of the preset")
    add_sets(p)
    p.add_argument("--dim", type=int, metavar="D", help="without PRESET: dimension, 2 or 3")
    p.add_argument("--l0", type=float, metavar="M",
                   help="without PRESET: particle spacing [m], > 0 and <= 0.01")
    p.add_argument("--re-ratio", type=float, help="re / l0 (default: 2.1)")
    p.add_argument("--sigma", type=float,
                   help=f"surface tension [N/m] (default: {WATER['sigma']:g}, water; 0 turns it "
                        "off)")
    p.add_argument("--rho", type=float, help=f"density [kg/m^3] (default: {WATER['rho']:g})")
    p.add_argument("--nu", type=float,
                   help=f"kinematic viscosity [m^2/s] (default: {WATER['nu']:g}; 0 turns it off)")
    p.add_argument("--speed", type=float,
                   help="expected maximum speed v [m/s] for the Courant limit (default: 1)")
    p.add_argument("--sound-speed", type=float, default=None,
                   help=f"artificial sound speed c [m/s] (default: {SOUND_SPEED_FACTOR:g} x "
                        "speed, S8)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=lambda a, argv: _info(a))
