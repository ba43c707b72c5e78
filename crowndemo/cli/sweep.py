"""``crowndemo sweep``: the crown / no-crown regime map over film thickness and impact speed."""
from __future__ import annotations

import json
import os
import sys

from ..config import QUALITIES
from .common import PRESET_HELP, PROG, SET_HELP, Fmt, load_preset, repo_root, start_backend

SWEEP_EPILOG = """\
examples:
  crowndemo sweep                                        # quick-2d: 3 films x 4 speeds
  crowndemo sweep quick --film 0.8e-3 1.2e-3 --speed 2 5 8
  crowndemo sweep 3m-drop --film 1e-3 3e-3 1e-2 --speed 2 5 8 --quality draft
  crowndemo sweep quick-2d --set scene.t_end=5e-4 --out /tmp/map

Each point is the preset with scene.film and scene.speed set (checked like --set), run to its
end time through one compiled simulator, and judged by the crown rule of
crowndemo.validate.crown_metrics (a sheet at least D/4 high outside the drop's footprint).
Writes regime.md, regime.json and, with matplotlib (pip install '.[plot]'), regime.png with
Cossali et al.'s splash threshold K = We Oh^-0.4 = 2100 + 5880 (h/D)^1.44 drawn on it.
"""


def _sweep(args, argv) -> int:
    from ..validate import sweep

    base = load_preset(args.preset, args)          # the preset and --set, checked first
    films = args.film or [0.5 * base.scene["film"], base.scene["film"], 2 * base.scene["film"]]
    speeds = args.speed or [2.0, 4.0, 6.0, 8.0]
    out = args.out or os.path.join(repo_root(), "reports")
    start_backend(args)
    print(f"{PROG}: sweep {base.name} ({base.quality}): {len(films)} films x {len(speeds)} "
          "speeds", file=sys.stderr, flush=True)
    points = sweep.run(args.preset, films, speeds, base.quality, args.sets,
                       on_point=lambda p: print(
                           f"  h = {p.film * 1e3:6.3g} mm  U = {p.speed:5.3g} m/s  "
                           f"{'-' if p.crown is None else ('crown' if p.crown else 'no crown'):<9}"
                           f"  {p.wall_s:6.1f} s  {p.outcome}", file=sys.stderr, flush=True))
    os.makedirs(out, exist_ok=True)
    drop, liquid = base.scene["drop"], base.liquid
    table = sweep.markdown(points, drop, liquid)
    with open(os.path.join(out, "regime.md"), "w") as f:
        f.write(f"# Regime map: {base.name} ({base.quality}), D = {drop * 1e3:g} mm\n\n"
                f"{table}\n")
    with open(os.path.join(out, "regime.json"), "w") as f:
        json.dump({"preset": base.name, "quality": base.quality, "drop_m": drop,
                   "liquid": liquid, "points": [p.as_dict() for p in points]}, f, indent=1)
    why = sweep.plot(points, drop, liquid, os.path.join(out, "regime.png"),
                     f"{base.name} ({base.quality}, {base.dim}D, l0 = {base.l0 * 1e3:g} mm), "
                     f"D = {drop * 1e3:g} mm")
    if args.record:
        _record(base, table, out, why is None, argv)
    print(table)
    print(f"{PROG}: wrote {out}/regime.md, regime.json"
          + (", regime.png" if why is None else f" (no image: {why})"), file=sys.stderr)
    return 0


def _record(base, table: str, out: str, has_image: bool, argv) -> None:
    """docs/regime.md (and docs/regime.png) at the repository root, linked from VALIDATION.md."""
    import datetime
    import shlex
    import shutil

    from .validate import _machine

    docs = os.path.join(repo_root(), "docs")
    os.makedirs(docs, exist_ok=True)
    lines = [f"# Regime map: {base.name} ({base.quality}, {base.dim}D, l0 = "
             f"{base.l0 * 1e3:g} mm), D = {base.scene['drop'] * 1e3:g} mm", "",
             "Written by `crowndemo sweep --record`; the verdicts follow the crown rule of "
             "the README's **validate** section.", "",
             f"- machine: {_machine()}", f"- date: {datetime.date.today().isoformat()}",
             f"- command: `{' '.join([PROG] + [shlex.quote(a) for a in argv])}`", ""]
    if has_image:
        shutil.copyfile(os.path.join(out, "regime.png"), os.path.join(docs, "regime.png"))
        lines += ["![regime map](regime.png)", ""]
    with open(os.path.join(docs, "regime.md"), "w") as f:
        f.write("\n".join(lines + [table, ""]))
    print(f"{PROG}: wrote {docs}/regime.md", file=sys.stderr)


def register(sub, common) -> None:
    p = sub.add_parser("sweep", parents=common, formatter_class=Fmt, epilog=SWEEP_EPILOG,
                       help="crown / no-crown regime map over film thickness and speed",
                       description="Run a preset over film thicknesses and impact speeds and "
                                   "draw the crown / no-crown regime map with the literature's "
                                   "splash threshold.")
    p.add_argument("preset", nargs="?", default="quick-2d", metavar="PRESET",
                   help=PRESET_HELP + " (default: quick-2d)")
    p.add_argument("--film", type=float, nargs="+", metavar="H",
                   help="film thicknesses [m] (default: 0.5, 1 and 2 x the preset's)")
    p.add_argument("--speed", type=float, nargs="+", metavar="U",
                   help="impact speeds [m/s] (default: 2 4 6 8)")
    p.add_argument("--quality", choices=QUALITIES, default="draft",
                   help="quality rung (default: draft)")
    p.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                   help=SET_HELP)
    p.add_argument("--out", metavar="DIR", help="folder for the map (default: reports/)")
    p.add_argument("--record", action="store_true",
                   help="also write docs/regime.md and docs/regime.png (linked from "
                        "VALIDATION.md)")
    p.set_defaults(func=_sweep)
