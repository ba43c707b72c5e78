"""``crowndemo sweep``: the crown / no-crown regime map over film thickness and impact speed."""
from __future__ import annotations

import os
import re
import shlex
import sys

from .common import (EXIT_FAILED, EXIT_INTERRUPTED, PRESET_HELP, PROG, Fmt, UsageError,
                     add_quality, add_sets, load_preset, path_argument, repo_root, require_folder,
                     start_backend)

# numbers like -1e-3 are values, not options (argparse alone knows only -1 and -0.5)
NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")

SWEEP_EPILOG = """\
examples:
  crowndemo sweep                                        # quick-2d: 3 films x 4 speeds
  crowndemo sweep quick --film 1.2e-3 2.4e-3 --speed 2 5 8
  crowndemo sweep 3m-drop --film 1e-3 3e-3 1e-2 --speed 2 5 8 --quality draft
  crowndemo sweep quick-2d --set scene.t_end=5e-4 --out /tmp/map
  crowndemo sweep quick-2d --workers 2                   # 2 Dask worker processes here
  crowndemo sweep 3m-drop --quality seed --scheduler tcp://head:8786 --resume

Each point is the preset with scene.film and scene.speed set (checked like --set), run to its
end time and judged by the crown rule of crowndemo.validate.crown_metrics (a sheet at least
D/4 high outside the drop's footprint). Every point is checked before Taichi starts or any
point is submitted. In one process one compiled simulator serves every point; with --workers
or --scheduler the points run on Dask workers (pip install 'crowndemo[cluster]'), each worker
with its own Taichi runtime, and arrive as they finish, with a progress bar. A point whose
worker dies (killed, out of memory) runs once more on a fresh worker (a --scheduler's own
retry count applies there); a second death reports it as failed, the map is drawn without
it and the sweep exits 1.

Each finished point is written at once to DIR/points.jsonl; --resume (same preset, --quality
and --set) runs only the points missing there, so an interrupted sweep loses at most the
points in flight. Writes regime.md and regime.json (with the command, the --set overrides,
each point's machine, and the failed points) and, with matplotlib (pip install '.[plot]'),
regime.png with Cossali et al.'s splash threshold K = We Oh^-0.4 = 2100 + 5880 (h/D)^1.44
drawn on it; without matplotlib an older regime.png in --out is removed. Ctrl-C cancels the
points not done, writes those that ran, marked as a partial map, and exits 130.
"""


def _point_error(what: str, key: str, e) -> str:
    """A PresetError of a sweep point as a message naming the option and value (``what``)."""
    if e.key == f"scene.{key}":                  # the value itself is out of range
        return f"{what}: {e.why}" + (f"; allowed: {e.allowed}" if e.allowed else "")
    return f"{what} does not fit the preset: {e}"


def _resolve_points(args, quality: str, films, speeds) -> list:
    """Every grid point's preset, checked before Taichi starts; a bad film or speed is named
    by its option and value (each value alone first, then the pairs)."""
    from ..config import PresetError, load
    from ..validate.sweep import point_sets

    def check(what: str, key: str, **point):
        try:
            return load(args.preset, quality, point_sets(args.sets, **point))
        except PresetError as e:
            raise UsageError(_point_error(what, key, e)) from None

    for h in films:
        check(f"--film {h:g}", "film", film=h)
    for u in speeds:
        check(f"--speed {u:g}", "speed", speed=u)
    return [check(f"--film {h:g} with --speed {u:g}", "", film=h, speed=u)
            for h in films for u in speeds]


def _header(base, command: str, sets, interrupted: str) -> str:
    """regime.md's head: what ran, with the command and the --set overrides."""
    lines = [f"# Regime map: {base.name} ({base.quality}), D = {base.scene['drop'] * 1e3:g} mm",
             "", f"Command: `{command}`; overrides (--set): "
             f"{', '.join(f'`{s}`' for s in sets) or 'none'}.", ""]
    return "\n".join(lines + ([interrupted, ""] if interrupted else []))


def _identity(base, sets) -> dict:
    """What a sweep's journal is of: a --resume must name the same preset, quality and
    overrides (its films and speeds may grow: the points done are kept by film and speed)."""
    return {"preset": base.name, "quality": base.quality, "sets": list(sets)}


def _progress_line(p) -> str:
    """A progress bar: points done, running, failed, and the time left."""
    width = 24
    filled = int(round(width * (p.done + p.failed) / max(p.total, 1)))
    eta = p.eta_s
    eta_s = "-" if eta is None else f"{int(eta // 60)}:{int(eta % 60):02d}"
    return (f"  [{'#' * filled}{'.' * (width - filled)}] {p.done}/{p.total} done, "
            f"{p.running} running, {p.failed} failed, ETA {eta_s}")


def _sweep(args, argv) -> int:
    from ..validate import sweep
    from ..validate.journal import Journal, JournalError

    base = load_preset(args.preset, args)          # the preset and --set, checked first
    films = args.film or [0.5 * base.scene["film"], base.scene["film"], 2 * base.scene["film"]]
    speeds = args.speed or [2.0, 4.0, 6.0, 8.0]
    out = args.out or os.path.join(repo_root(), "reports")
    require_folder("--out", out)
    resolved = _resolve_points(args, base.quality, films, speeds)
    distributed = args.workers is not None or args.scheduler is not None
    if args.threads is not None and not distributed:
        raise UsageError("--threads sets each Dask worker's threads: give --workers or "
                         "--scheduler (or --single-thread for one thread here)")
    cluster = None
    if distributed:
        from ..validate.dispatch import Cluster, DispatchError, distributed as need_dask
        try:
            need_dask()                            # the extra, before anything starts
            cluster = Cluster(args.workers, args.scheduler,
                              1 if args.single_thread else args.threads)
        except DispatchError as e:
            raise UsageError(str(e)) from None
    try:
        journal = Journal(out, _identity(base, args.sets), resume=args.resume)
    except JournalError as e:
        raise UsageError(str(e)) from None
    todo = [r for r in resolved if sweep.key_of(r) not in journal.done]
    if args.resume:
        print(f"{PROG}: --resume: {len(resolved) - len(todo)} of {len(resolved)} points done "
              f"before ({journal.path}), {len(todo)} to run", file=sys.stderr, flush=True)
    print(f"{PROG}: sweep {base.name} ({base.quality}): {len(films)} films x {len(speeds)} "
          "speeds", file=sys.stderr, flush=True)

    def on_point(p):
        journal.add(p)
        print(f"  h = {p.film * 1e3:6.3g} mm  U = {p.speed:5.3g} m/s  "
              f"{'-' if p.crown is None else ('crown' if p.crown else 'no crown'):<9}"
              f"  {p.wall_s:6.1f} s  {p.outcome}  [{p.host}]", file=sys.stderr, flush=True)
    failures = []

    def on_failure(f):
        failures.append(f)
        print(f"  h = {f.film * 1e3:6.3g} mm  U = {f.speed:5.3g} m/s  FAILED: {f.cause}",
              file=sys.stderr, flush=True)
    interrupted = ""
    try:
        if cluster is None:
            start_backend(args)
            sweep.run_resolved(todo, on_point=on_point)
        else:
            _run_on_dask(args, cluster, todo, on_point, on_failure)
    except KeyboardInterrupt:
        done = len(journal.done)
        interrupted = (f"**Interrupted (Ctrl-C): {done} of {len(resolved)} points ran; "
                       "a partial map.**")
        print(f"{PROG}: interrupted (Ctrl-C): writing the {done} points that ran; --resume "
              "runs the others", file=sys.stderr)
    points = [journal.done[sweep.key_of(r)] for r in resolved if sweep.key_of(r) in journal.done]
    missing = "" if interrupted else _missing_note(failures)
    command = " ".join([PROG] + [shlex.quote(a) for a in argv])
    table, why = _write(out, base, points, len(resolved), command, args.sets,
                        interrupted or missing, failures)
    if args.record and (interrupted or missing):
        print(f"{PROG}: docs/regime.md not rewritten: the map is not whole", file=sys.stderr)
    elif args.record:
        _record(base, table, out, why is None, argv)
    print(table)
    print(f"{PROG}: wrote {out}/regime.md, regime.json, {os.path.basename(journal.path)}"
          + (", regime.png" if why is None else f" (no image: {why})"), file=sys.stderr)
    if interrupted:
        return EXIT_INTERRUPTED
    return EXIT_FAILED if failures else 0


def _missing_note(failures) -> str:
    if not failures:
        return ""
    which = ", ".join(f"h = {f.film * 1e3:g} mm, U = {f.speed:g} m/s ({f.cause})"
                      for f in failures)
    return f"**{len(failures)} point(s) failed and are missing from the map: {which}.**"


def _run_on_dask(args, cluster, todo, on_point, on_failure) -> None:
    """The points on the Dask cluster, with a progress bar on stderr."""
    from ..validate.dispatch import DispatchError
    from ..validate.dispatch_worker import BackendSpec

    spec = BackendSpec(args.arch, args.precision, args.seed, cluster.threads,
                       bool(args.fast_compile))
    try:
        with cluster:
            print(f"{PROG}: on {cluster.describe()}", file=sys.stderr, flush=True)
            cluster.run(todo, spec, on_point, on_failure,
                        on_progress=lambda p: print(_progress_line(p), file=sys.stderr,
                                                    flush=True))
    except DispatchError as e:
        raise UsageError(str(e)) from None


def _write(out: str, base, points, planned: int, command: str, sets, interrupted: str,
           failures=()):
    """regime.md, regime.json and regime.png (or, without it, no older one) in ``out``;
    returns the table and why there is no image (None when there is)."""
    from ..validate import report, sweep

    drop, liquid = base.scene["drop"], base.liquid
    table = sweep.markdown(points, drop, liquid)
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "regime.md"), "w") as f:
        f.write(f"{_header(base, command, sets, interrupted)}\n{table}\n")
    with open(os.path.join(out, "regime.json"), "w") as f:
        report.dump_json({"preset": base.name, "quality": base.quality, "command": command,
                          "sets": list(sets), "interrupted": bool(interrupted),
                          "points_planned": planned, "drop_m": drop, "liquid": liquid,
                          "points": [p.as_dict() for p in points],
                          "failed": [{"film": x.film, "speed": x.speed, "cause": x.cause}
                                     for x in failures]}, f)
    why = sweep.plot(points, drop, liquid, os.path.join(out, "regime.png"),
                     f"{base.name} ({base.quality}, {base.dim}D, l0 = {base.l0 * 1e3:g} mm), "
                     f"D = {drop * 1e3:g} mm" + (f"; --set {' '.join(sets)}" if sets else ""))
    if why is not None:                            # not an earlier run's image beside it
        for path in report.remove_stale(out, ["regime.png"], []):
            print(f"{PROG}: removed {path} (an earlier run's)", file=sys.stderr)
    return table, why


def _record(base, table: str, out: str, has_image: bool, argv) -> None:
    """docs/regime.md (and docs/regime.png) at the repository root, linked from VALIDATION.md."""
    import datetime
    import shutil

    from ..machine import machine_line

    docs = os.path.join(repo_root(), "docs")
    os.makedirs(docs, exist_ok=True)
    lines = [f"# Regime map: {base.name} ({base.quality}, {base.dim}D, l0 = "
             f"{base.l0 * 1e3:g} mm), D = {base.scene['drop'] * 1e3:g} mm", "",
             "Written by `crowndemo sweep --record`; the verdicts follow the crown rule of "
             "the README's **validate** section.", "",
             f"- machine: {machine_line()}", f"- date: {datetime.date.today().isoformat()}",
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
    p._negative_number_matcher = NEGATIVE_NUMBER     # argparse's own test, widened
    p.add_argument("preset", nargs="?", default="quick-2d", metavar="PRESET",
                   help=PRESET_HELP + " (default: quick-2d)")
    p.add_argument("--film", type=float, nargs="+", metavar="H",
                   help="film thicknesses [m] (default: 0.5, 1 and 2 x the preset's)")
    p.add_argument("--speed", type=float, nargs="+", metavar="U",
                   help="impact speeds [m/s] (default: 2 4 6 8)")
    add_quality(p, "draft")
    add_sets(p)
    p.add_argument("--out", type=path_argument, metavar="DIR",
                   help="folder for the map (default: reports/ at the repository root, "
                        "wherever the command runs)")
    p.add_argument("--record", action="store_true",
                   help="also write docs/regime.md and docs/regime.png (linked from "
                        "VALIDATION.md)")
    d = p.add_argument_group("running the points on Dask (pip install 'crowndemo[cluster]')")
    d.add_argument("--workers", type=int, metavar="N",
                   help="a local Dask cluster of N worker processes, each with its own Taichi "
                        "runtime and cores / N threads (at most one worker a core)")
    d.add_argument("--scheduler", metavar="ADDRESS",
                   help="submit the points to the running Dask scheduler at ADDRESS (e.g. "
                        "tcp://host:8786); its workers need crowndemo installed")
    d.add_argument("--threads", type=int, metavar="K",
                   help="Taichi threads of each worker (default: cores / N with --workers, "
                        "all of a worker's cores with --scheduler)")
    p.add_argument("--resume", action="store_true",
                   help="run only the points missing from --out's points.jsonl (written as "
                        "each point finishes) of the same sweep")
    p.set_defaults(func=_sweep)
