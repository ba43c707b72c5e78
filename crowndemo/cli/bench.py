"""``crowndemo bench``: particle-steps per second of the full step (BENCHMARKS.md)."""
from __future__ import annotations

import os
import shlex
import sys
from typing import Dict, Sequence

from .. import strictjson
from ..core.health import InstabilityError
from ..core.params import ParameterError
from .common import (PROG, Fmt, Progress, UsageError, add_quality, add_sets, repo_root,
                     start_backend)

PRESET_QUALITY = "booth"    # of --preset runs, without --quality


BENCH_EPILOG = """\
examples:
  crowndemo bench                             # N = 100000 and 300000, 20 steps, table
  crowndemo bench --n 2000 --steps 3 --json   # a small run (compiling the kernels takes most of it)
  crowndemo bench --arch cuda --n 1000000     # on an NVIDIA GPU
  crowndemo bench --record                    # append the results to BENCHMARKS.md
  crowndemo bench --compare --n 100000        # the seed's formulation against the tuned one
  crowndemo bench --n 300000 --set numerics.cells_per_re=1   # one numerics value changed
  crowndemo bench --preset 3m-drop            # the 3m-drop preset at booth quality to its end
  crowndemo bench --preset 2.5m-drop --quality seed --arch cuda --record   # on a GPU

The scene is a k x k x kz block of water (k = round(N^(1/3)), l0 = 1 mm, re = 2.1 l0) resting
in a 3D tank with walls. particle-steps/s = fluid particles x steps / seconds; the first steps
(JIT compile) are not timed and are reported as compile_s. Then 5 more steps are timed stage by
stage (grid, predictor, collision, density, corrector, health; each stage waits for the device,
so their sum is a little over a normal step). bytes/particle: the simulator's fields (particles,
cell grid, neighbour list), allocated for a capacity rounded up to the next 2^(1/4) step, over
the particles in use, walls included.

--compare runs each N twice in one process: "seed" is the seed's formulation with a plain
implementation (gradient P_j - P_i, no collision model, cells of side re, no neighbour list, no
re-sort); "tuned" is the project's default (pmin gradient, collisions, cells of side re/2, the
neighbour list, re-sort every step). It prints tuned / seed. --set numerics.KEY=VALUE (any
number of times) runs the block with those numerics instead, labelled with them.

--preset runs presets to their end time instead (as `crowndemo run`, nothing recorded), at
--quality (default booth) with --set overrides: "to t_end s" is the whole wall time (scene
set-up, the first step, which compiles or loads the kernels, and every step), "start-up s" its
set-up and first step; particle-steps/s counts fluid particles over the steps after the first,
which are also timed stage by stage (the stage timer waits for the device after each stage).
A preset that goes unstable ends the command (exit status 3, the step and the limit it broke)
after the presets before it are reported (and recorded, with --record).
"""


def _bench(args, argv: Sequence[str]) -> int:
    from .. import bench

    if args.preset:
        return _bench_presets(args, argv)
    if args.quality or args.max_steps is not None:
        raise UsageError("--quality and --max-steps apply to --preset runs only (the tank "
                         "block has neither) (see 'crowndemo bench --help')")
    if args.sets and args.compare:
        raise UsageError("--set or --compare, not both: --compare sets the numerics of its "
                         "two variants (see 'crowndemo bench --help')")
    ns = args.n or list(bench.DEFAULT_NS)
    for n in ns:
        if n < 1:
            raise ParameterError("n", n, "an integer >= 1 (fluid particles)", "command line")
    if args.steps < 1:
        raise ParameterError("steps", args.steps, "an integer >= 1", "command line")
    numerics = _tank_numerics(args.sets, ns)
    start_backend(args)

    def progress(r):
        if not args.json:
            label = f" ({r['label']})" if args.compare else ""
            print(f"  N = {r['particles']['fluid']:,}{label}: {r['particle_steps_per_s']:.3e} "
                  f"particle-steps/s", file=sys.stderr, flush=True)

    results = bench.run(ns, args.steps, on_result=progress, compare=args.compare,
                        stages=not args.no_stages, numerics=numerics)
    _finish(args, argv, results)
    return 0


def _tank_numerics(items: Sequence[str], ns: Sequence[int]) -> Dict:
    """``--set numerics.KEY=VALUE`` for the tank block (it has no other keys), checked as a
    preset's numerics are, before Taichi starts: each key, its type and range
    (config/schema.py), and a fixed dt against every block's time-step limits."""
    from ..config import Document, PresetError, overrides, schema
    from ..core.params import Numerics, with_values

    for item in items:
        parts, value = overrides.parse(item)
        if len(parts) != 2 or parts[0] != "numerics":
            raise PresetError(overrides.SOURCE, ".".join(parts), value,
                              "not a numerics key: the tank block takes numerics.KEY only "
                              "(a preset's other keys need --preset)",
                              "numerics." + ", numerics.".join(schema.NUMERICS_KEYS))
    # merged as a preset's --set layer: a later one wins, an empty VALUE restores the default
    doc = overrides.apply(Document("bench", None, "the tank block", {}, {}), items)
    given = doc.data.get("numerics", {})
    # the schema's own check of a preset's numerics mapping (unknown keys, types, ranges)
    checked = schema.check_numerics(given, doc)
    values = {k: checked[k] for k in given}
    try:            # the core's own checks (the schema's ranges make these pass)
        numerics = with_values(Numerics(), **values).validate()
    except ParameterError as e:
        raise PresetError(overrides.SOURCE, "numerics." + e.key, e.value,
                          "refused by the solver", e.allowed) from None
    for n in ns:
        _check_fixed_dt(numerics, n)
    return values


def _check_fixed_dt(numerics, n: int) -> None:
    """A fixed dt must keep the time-step limits of the block of ``n`` (its depth sets the
    speed and the sound speed; core/timestep.py check_fixed_dt), as in a preset."""
    from .. import bench
    from ..config import PresetError, overrides
    from ..core import timestep
    from ..core.params import Model
    from ..scenes import hydrostatic_tank

    if numerics.fixed_dt is None:
        return
    l0, kz = bench.DEFAULT_L0, bench.block_shape(n)[1]
    # the physics depends on the depth only: a column a few particles wide builds at once
    physics = hydrostatic_tank(dim=3, l0=l0, width=4 * l0, depth=kz * l0, re_ratio=2.1,
                               numerics=numerics).physics
    try:
        timestep.check_fixed_dt(physics, numerics, Model.of(physics, numerics))
    except ParameterError as e:
        raise PresetError(overrides.SOURCE, "numerics.fixed_dt", e.value, "breaks a time-step "
                          f"limit of the N = {n:,} block", e.allowed) from None


def recorded_command(argv: Sequence[str], results) -> str:
    """The command line a BENCHMARKS.md section gives, with the environment that changed what
    ran (the slot-major neighbour list) in front, so that it repeats the run."""
    from ..core.neighbours import LAYOUT_VARIABLE

    env = [f"{LAYOUT_VARIABLE}=slot"] if any(r.get("list_layout") == "slot"
                                             for r in results) else []
    return " ".join(env + [PROG] + [shlex.quote(a) for a in argv])


def _finish(args, argv: Sequence[str], results) -> None:
    from .. import bench

    if args.json:
        print(strictjson.dumps(results[0] if len(results) == 1 else results))
    else:
        print(bench.text_table(results))
    if args.record:
        path = os.path.join(repo_root(), "BENCHMARKS.md")
        bench.record(results, recorded_command(argv, results), path)
        print(f"{PROG}: appended to {path}", file=sys.stderr)


def _bench_presets(args, argv: Sequence[str]) -> int:
    """--preset: each preset to its end time (every one checked before the first runs)."""
    from .. import bench, config

    if args.n or args.compare:
        raise UsageError("--n and --compare apply to the tank block only, not with --preset "
                         "(a preset sets its own particles and numerics; use --set) "
                         "(see 'crowndemo bench --help')")
    if args.max_steps is not None and args.max_steps < 2:
        raise ParameterError("max_steps", args.max_steps, "an integer >= 2 (the first step "
                             "is the warm-up, the rest are timed)", "command line")
    quality = args.quality or PRESET_QUALITY
    resolved = [config.load(spec, quality, args.sets) for spec in args.preset]
    start_backend(args)
    results = []
    for r in resolved:
        progress = Progress(r.t_end, args.json, args.max_steps,
                            first_label=f"{r.name} {quality}: set-up and first step")
        try:
            res = bench.run_preset(r, stages=not args.no_stages, max_steps=args.max_steps,
                                   progress=progress)
        except InstabilityError:
            if results:             # the presets that finished are reported, then the error
                _finish(args, argv, results)
            raise
        results.append(res)
        if not args.json:
            print(f"  {res['label']}: {res['run_s']:.1f} s to t = "
                  f"{1e3 * res['simulated_s']:.3g} ms ({res['steps']} steps)",
                  file=sys.stderr, flush=True)
    _finish(args, argv, results)
    return 0


def register(sub, common) -> None:
    p = sub.add_parser("bench", parents=common, formatter_class=Fmt, epilog=BENCH_EPILOG,
                       help="particle-steps per second of the full step on a 3D block",
                       description="Time the full explicit MPS step on a 3D block of water "
                                   "resting in a tank, or (--preset) presets run to their "
                                   "end time.")
    p.add_argument("--n", type=int, nargs="+", metavar="N",
                   help="fluid particles, one run each (default: 100000 300000)")
    p.add_argument("--steps", type=int, default=20, metavar="S", help="timed steps per run (default: 20)")
    p.add_argument("--json", action="store_true",
                   help="one JSON object per N (a list when several)")
    p.add_argument("--compare", action="store_true",
                   help="run the seed's formulation and the tuned one for each N; print the ratio")
    p.add_argument("--no-stages", action="store_true",
                   help="skip the stage-by-stage timing (5 extra steps per run)")
    p.add_argument("--preset", nargs="+", metavar="PRESET",
                   help="run these presets to their end time instead of the tank block")
    add_quality(p, None, "quality rung of --preset", shown=PRESET_QUALITY)
    add_sets(p, "override a value of --preset (as in crowndemo run); for the tank block, a "
                "numerics value (numerics.KEY=VALUE)")
    p.add_argument("--max-steps", type=int, metavar="N",
                   help="stop each --preset run after N steps, at least 2: the first "
                        "compiles or loads the kernels from the cache, the rest are timed "
                        "(a smoke test)")
    p.add_argument("--record", action="store_true",
                   help="append a section (machine, arch, date, command, table) to BENCHMARKS.md "
                        "at the repository root")
    p.set_defaults(func=_bench)
