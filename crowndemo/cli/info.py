"""``crowndemo info``: every resolved value of a preset (cli/info_preset.py), or the constants
and time-step limits of a lattice (cli/info_lattice.py); pure host computation."""
from __future__ import annotations

from ..core.params import SOUND_SPEED_FACTOR, WATER
from .common import PRESET_HELP, Fmt, UsageError, add_quality, add_sets
from .info_lattice import info_lattice
from .info_preset import info_preset


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
        return info_preset(args)
    if args.quality is not None or args.sets:
        raise UsageError("--quality and --set need a PRESET (see 'crowndemo info --help')")
    missing = [INFO_LATTICE[k][0] for k in ("dim", "l0") if getattr(args, k) is None]
    if missing:
        raise UsageError(f"the following arguments are required: {', '.join(missing)} "
                         "(or a PRESET) (see 'crowndemo info --help')")
    for key, (_, default) in INFO_LATTICE.items():
        if getattr(args, key) is None:
            setattr(args, key, default)
    return info_lattice(args)


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
