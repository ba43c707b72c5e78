"""``crowndemo presets``: the presets with their titles, particle counts and run-time
estimates per quality."""
from __future__ import annotations

import math
import os

from .. import strictjson
from ..config import PresetError
from ..core.params import ParameterError
from .common import EXIT_USAGE, Fmt, error


PRESETS_EPILOG = """\
examples:
  crowndemo presets                 # name, title, particles and run time per quality
  crowndemo presets --lang ja       # titles in Japanese
  crowndemo presets --rate 5e7      # estimate for a machine that does 5e7 particle-steps/s
  crowndemo presets --json

The presets are the YAML files in presets/ at the repository root ($CROWNDEMO_PRESETS names
another folder). Particle counts come from building each scene with numpy (no kernel runs);
counts marked ~ are scaled from a build at a coarser spacing. The run time is rough: a first
run's compile (5 s in 2D, 50 s in 3D, measured; a run whose kernels are in Taichi's cache
starts in 3-9 s) + (every particle) x steps x 0.8 (a crown step's cost per particle against
the bench's, measured) / the rate of the newest CPU section of BENCHMARKS.md (--rate: another
machine's, 1e3 to 1e12 fluid particle-steps/s). Steps: dt at the drop's speed until it
touches the film, then at the splash's speed, 0.5 c (with the Courant limit on relative
speeds, 0.3 c relative), as measured on crown runs. The table's footer names the figures
used; `crowndemo info PRESET` shows the steps.
"""


# --rate: from a slow single core to far beyond any machine of today (BENCHMARKS.md: about
# 2e6 on 2 CPU cores); outside, the run times printed would mean nothing
RATE_RANGE = (1.0e3, 1.0e12)


def _display_width(text: str) -> int:
    import unicodedata
    return sum(2 if unicodedata.east_asian_width(ch) in "WF" else 1 for ch in text)


def _pad(text: str, width: int) -> str:
    return text + " " * max(width - _display_width(text), 0)


def _presets(args) -> int:
    import textwrap

    from .. import config
    from ..config import estimate, schema

    lo, hi = RATE_RANGE
    if args.rate is not None and not (math.isfinite(args.rate) and lo <= args.rate <= hi):
        raise ParameterError("rate", args.rate, f">= {lo:g} and <= {hi:g} fluid particle-steps "
                             "per second", "command line")
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
        print(strictjson.dumps({"folder": str(folder), "throughput": {
            "fluid_particle_steps_per_s": tp.rate, "all_particle_steps_per_s": tp.rate_total,
            "source": tp.source}, "presets": rows}, indent=2))
    else:
        lang = args.lang
        titles = [row["title"].get(lang) or row["title"]["en"] for row in rows]
        tw = min(max([_display_width(t) for t in titles] + [5]), 60)
        nw = max([len(row["name"]) for row in rows] + [4])
        head = f"{'NAME':<{nw}}  DIM  {_pad('TITLE', tw)}"
        for q in config.QUALITIES:
            head += f"  {q.upper():<15}"
        print(f"presets in {config.display(folder)}{os.sep}: fluid particles and a rough run "
              "time per quality at the throughput of BENCHMARKS.md (--rate for yours)")
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
                f"~: particle count scaled from a coarser build. Run time: a first run's "
                f"compile ({estimate.FIRST_RUN_COMPILE_S[2]:g} s in 2D, "
                f"{estimate.FIRST_RUN_COMPILE_S[3]:g} s in 3D; 3-9 s with the kernels in "
                f"Taichi's cache) + fluid particles x steps / {tp.rate:.3g} fluid particle-steps/s "
                f"({tp.source}) x a crown step's cost, {estimate.CALM_COST:g} of the bench's "
                f"before contact and {estimate.SPLASH_COST:g} after it at D/l0 = "
                f"{estimate.SPLASH_COST_AT:g} (x (D/l0 / {estimate.SPLASH_COST_AT:g})^"
                f"{estimate.SPLASH_COST_GROWTH:g}), wall and dummy particles "
                f"{estimate.WALL_COST:g} of a fluid one; "
                f"steps: dt at the drop's speed U until contact, then at the splash's "
                f"{estimate.SPLASH_SPEED_U:g} U at D/l0 = {estimate.SPLASH_AT_D_L0:g} "
                f"(x (D/l0 / {estimate.SPLASH_AT_D_L0:g})^{estimate.SPLASH_GROWTH:g}) and, "
                f"with the Courant limit on relative speeds, {estimate.RELATIVE_SPEED_U:g} U "
                f"relative (measured, VALIDATION.md \"Sound speed\"). Details: "
                f"crowndemo info PRESET --quality Q.", 96):
            print(line)
    for e in errors:
        error(str(e))
    return EXIT_USAGE if errors else 0


def register(sub, common) -> None:
    p = sub.add_parser("presets", formatter_class=Fmt, epilog=PRESETS_EPILOG,
                       help="list the presets: title, particles and run time per quality",
                       description="List the presets with their title, fluid particle count "
                                   "and a rough run time per quality (draft, booth, seed); no "
                                   "kernel runs.")
    p.add_argument("--lang", choices=("en", "ja"), default="en",
                   help="language of the titles (default: en)")
    p.add_argument("--rate", type=float, metavar="R",
                   help="fluid particle-steps per second to estimate with, 1e3 to 1e12 "
                        "(default: the newest CPU figure in BENCHMARKS.md)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=lambda a, argv: _presets(a))
