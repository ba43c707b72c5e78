"""``crowndemo run``: simulate presets one after another in one session and summarise each."""
from __future__ import annotations

import sys
import time

from .. import strictjson
from ..config import DEFAULT_QUALITY
from ..core.health import InstabilityError
from ..core.params import ParameterError
from .common import (CTRL_C_NOTICE, EXIT_INTERRUPTED, EXIT_UNSTABLE, FIRST_STEP, PRESET_HELP,
                     PROG, Fmt, add_quality, add_sequence_options, add_sets, load_presets,
                     print_summary, run_result, simulate, start_backend)


RUN_EPILOG = """\
examples:
  crowndemo run quick                               # a small 3D crown, draft quality
  crowndemo run 3m-drop --quality booth             # the seed's first run, ~289k particles
  crowndemo run 3m-drop --set scene.speed=6 --set quality.draft.t_end=5e-4
  crowndemo run quick --then quick-2d 20cm-drop     # one after another, one process
  crowndemo run quick --playlist presets/booth.txt  # then the presets listed in a file
  crowndemo run my-preset.yaml                      # a file; it may `extends: 3m-drop`
  crowndemo run 2m-drop --arch cuda --quality seed  # ~11.7M particles, on a GPU

--quality and --set apply to every preset of the run. Every preset is checked before the
first one starts; a mistake is reported as
  crowndemo: error: FILE: KEY = VALUE: WHY; allowed: RANGE
The runs share one session: presets with the same compiled model (dimension, terms,
gradient form) reuse one simulator, its kernels and fields; only the values change. Each
summary gives the start-up time (set-up + first step) and whether kernels were compiled.
A progress line (simulated time, steps/s, ETA) goes to stderr every ~2 s; the summary to
stdout. Ctrl-C stops after the current step, prints the summary so far and exits 130 (run
keeps no checkpoint: use 'crowndemo record' for a run you may want to resume). An
unstable run stops with exit status 3 and says what broke.
"""


def _run(args) -> int:
    from ..control import Session, compiled_kernels
    from ..interrupt import StopRequest

    if args.max_steps is not None and args.max_steps < 1:
        raise ParameterError("max_steps", args.max_steps, "an integer >= 1", "command line")
    resolved = load_presets(args)                # every mistake before any run
    be = start_backend(args)
    session = Session()
    stop = StopRequest(CTRL_C_NOTICE)
    results = []
    t_all = time.perf_counter()
    with stop.catching():
        for i, r in enumerate(resolved):
            t0 = time.perf_counter()
            kernels0, built0 = compiled_kernels(), session.constructions
            scene = r.build_scene()
            sim = session.load(scene)
            setup_s = time.perf_counter() - t0
            reused = session.constructions == built0
            if not args.quiet:
                nth = f" ({i + 1} of {len(resolved)})" if len(resolved) > 1 else ""
                how = ("reusing the compiled simulator" if reused else
                       "the first step compiles the kernels or loads them from the cache")
                print(f"{PROG}: run {r.name}{nth}, quality {r.quality}, {r.dim}D, "
                      f"{scene.counts()['fluid']:,} fluid of {len(scene.pos):,} particles, arch "
                      f"{be.resolved}, {be.precision}; running to {r.t_end * 1e3:g} ms ({how})",
                      file=sys.stderr, flush=True)
            try:
                run = simulate(sim, r.t_end, args.quiet, r.frame_times(), args.max_steps,
                               stop=stop,
                               first_label="first step" if reused else FIRST_STEP)
            except InstabilityError as e:
                return _unstable(r, e, results, [x.name for x in resolved[i + 1:]],
                                 len(resolved) > 1, args)
            counts = sim.counts()
            s = r.scene
            first = run["first_step_s"] or 0.0
            results.append({
                "preset": r.name, "file": r.label, "quality": r.quality, "dim": r.dim,
                "l0_m": r.l0, "speed_m_s": r.speed, "film_m": s["film"], "drop_m": s["drop"],
                "t_end_s": r.t_end, "gradient": r.numerics.pressure_gradient,
                "sound_speed_m_s": scene.physics.c, "arch": be.arch,
                "resolved_arch": be.resolved, "precision": be.precision,
                "stopped_early": run["stopped_early"], "stopped_by": run["stopped_by"],
                **run_result(run, counts, setup_s),
                "startup": {"seconds": setup_s + first, "setup_seconds": setup_s,
                            "first_step_seconds": first, "reused_simulator": reused,
                            "kernels_compiled": compiled_kernels() - kernels0,
                            "session": session.events[-1]},
                "left_out": scene.info.get("left_out", [])})
            if not args.json:
                head = (f"preset {r.name} ({r.quality}): {r.dim}D, l0 = {r.l0:g} m, U = "
                        f"{r.speed:.4g} m/s, film {s['film']:g} m, drop {s['drop']:g} m; "
                        f"gradient {r.numerics.pressure_gradient}; arch {be.resolved}, "
                        f"{be.precision}")
                print_summary(head, run, counts, scene.physics.c, setup_s, dim=r.dim)
                st = results[-1]["startup"]
                print(f"  start-up    {st['seconds']:.2f} s (set-up {setup_s:.2f} s + first step "
                      f"{first:.2f} s); {st['session']}; {st['kernels_compiled']} kernels "
                      "compiled or loaded from the cache")
            if run["stopped_by"] == "ctrl-c":
                left = [x.name for x in resolved[i + 1:]]
                print(f"{PROG}: interrupted at t = {sim.stats.time * 1e3:.4g} ms (step "
                      f"{sim.stats.steps:,}) of {r.name}" +
                      (f"; not run: {', '.join(left)}" if left else "") +
                      f". 'run' keeps no checkpoint; to be able to resume, record instead: "
                      f"'{PROG} record {r.name}', then '{PROG} record {r.name} --resume'",
                      file=sys.stderr)
                break
    if args.json:
        print(strictjson.dumps(results[0] if len(results) == 1 else results))
    elif len(results) > 1:
        print(f"{len(results)} runs in {time.perf_counter() - t_all:.2f} s")
    return EXIT_INTERRUPTED if stop.requested else 0


def _unstable(r, e, results: list, left: list, chain: bool, args) -> int:
    """A preset of the list went unstable: the runs before it are reported as usual (with
    --json, in the list, followed by this one's step, time and cause), the error names the
    preset and the presets not run; exit status 3."""
    if args.json:
        results.append({"preset": r.name, "file": r.label, "quality": r.quality,
                         "unstable": {"step": e.step, "time_s": e.time, "what": e.what,
                                      "binding": e.binding, "message": str(e)}})
        print(strictjson.dumps(results[0] if len(results) == 1 else results))
    print(f"{PROG}: {r.name + ': ' if chain else ''}{e}", file=sys.stderr)
    if left:
        print(f"{PROG}: not run: {', '.join(left)}", file=sys.stderr)
    return EXIT_UNSTABLE


def register(sub, common) -> None:
    p = sub.add_parser("run", parents=common, formatter_class=Fmt, epilog=RUN_EPILOG,
                       help="run a preset (a drop on a film) and summarise it",
                       description="Run a preset: a drop falling on a film "
                                   "(crowndemo.scenes.crown). Prints a progress line and a "
                                   "summary: particles, steps, dt and the limits that bound "
                                   "it, health, wall time.")
    p.add_argument("preset", metavar="PRESET", help=PRESET_HELP)
    add_quality(p, DEFAULT_QUALITY, "quality rung: draft (minutes on a CPU), booth (l0 ~0.3 "
                                    "mm), seed (the seed's ~12M particles, a GPU)")
    add_sets(p)
    add_sequence_options(p)
    p.add_argument("--max-steps", type=int, metavar="N",
                   help="stop each run after N steps (a smoke test)")
    p.add_argument("--json", action="store_true",
                   help="print the summary as one JSON object (a list with several presets)")
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    p.set_defaults(func=lambda a, argv: _run(a))
