"""``crowndemo validate``: reference cases at several resolutions and settings (error against
run time), the stability suite, and the seed's crown / no-crown observations."""
from __future__ import annotations

import datetime
import json
import os
import platform
import shlex
import sys

from .common import PROG, Fmt, UsageError, repo_root, start_backend

GROUPS = ("stability", "verdicts")

VALIDATE_EPILOG = """\
examples:
  crowndemo validate --quick                     # the quick subset (what make test runs, ~min)
  crowndemo validate                             # every case, every resolution and setting
  crowndemo validate dam-break-2d laplace-2d     # some cases
  crowndemo validate stability                   # the stiff and extreme cases only
  crowndemo validate verdicts --quality draft    # crown or not, the seed's four runs
  crowndemo validate --list
  crowndemo validate --record                    # also rewrite VALIDATION.md

Cases: hydrostatic, dam-break, drop-oscillation, laplace (each -2d and -3d), crown-base-quick,
crown-base-3m-drop; groups: stability, verdicts. Each case runs at three resolutions in the
base settings and, at the middle one, with f64, half the time-step safety numbers, the other
pressure-gradient forms, and (crown) the untrimmed domain with side walls. Output in --out
(default reports/): validation.md, validation.csv, error_vs_time.png (with matplotlib:
pip install '.[plot]'), stability.md, verdicts.md, and all of it as validation.json.
Wall times exclude the first step of each run, which compiles the kernels (reported apart).
"""


def _machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, {platform.system()} {platform.release()}"


def _validate(args, argv) -> int:
    from ..validate import cases as cases_mod
    from ..validate import report, runner, stability, verdicts

    table = cases_mod.all_cases(full=True)
    if args.list:
        for c in table.values():
            print(f"{c.name:<22} {c.quantity}; reference: {c.reference}; {c.resolution} = "
                  f"{', '.join(f'{s:g}' for s in c.scales)} (quick: "
                  f"{', '.join(f'{s:g}' for s in c.quick)})")
        print(f"{'stability':<22} stiff and extreme drop-on-film cases: "
              f"{', '.join(stability.cases(True))}")
        print(f"{'verdicts':<22} crown or not for {', '.join(verdicts.SEED)} (the seed's runs)")
        return 0
    names = args.cases or (list(table) + list(GROUPS))
    if args.quick and not args.cases:
        names = [n for n in names if n not in ("crown-base-3m-drop", "verdicts")]
    unknown = [n for n in names if n not in table and n not in GROUPS]
    if unknown:
        raise UsageError(f"unknown case {', '.join(unknown)}; allowed: "
                         f"{', '.join(list(table) + list(GROUPS))} (see '{PROG} validate --list')")
    be = start_backend(args)
    out = os.path.join(repo_root(), "reports") if args.out is None else args.out
    os.makedirs(out, exist_ok=True)

    def say(text):
        if not args.json:
            print(text, file=sys.stderr, flush=True)

    def row_line(r):
        err = f"{100 * r.error:.2f} %" if r.error == r.error and r.error != float("inf") else "-"
        say(f"  {r.case:<20} {r.variant:<14} {r.resolution} = {r.scale:<6g} {r.particles:>7,} "
            f"particles {r.steps:>6,} steps {r.wall_s:7.1f} s  error {err:>9}  {r.outcome}")

    result = {"machine": _machine(), "date": datetime.date.today().isoformat(),
              "command": " ".join([PROG] + [shlex.quote(a) for a in argv]),
              "arch": be.resolved, "precision": be.precision, "quick": args.quick}
    selected = [table[n] for n in names if n in table]
    rows = []
    if selected:
        say(f"{PROG}: validating {len(selected)} case(s){' (quick)' if args.quick else ''}")
        rows = runner.run_suite(selected, quick=args.quick, variants=not args.no_variants,
                                on_row=row_line)
        result["cases"] = [r.as_dict() for r in rows]
    stab = []
    if "stability" in names:
        say(f"{PROG}: stability suite")
        stab = stability.run_suite(full=not args.quick, on_row=lambda r: say(
            f"  {r.case:<18} {r.steps:>6,} steps {r.wall_s:6.1f} s  {r.outcome}"
            f"{'' if r.passed else '  FAILED: ' + '; '.join(r.checks)}"))
        result["stability"] = [r.as_dict() for r in stab]
    verd = []
    if "verdicts" in names:
        say(f"{PROG}: crown verdicts at quality {args.quality}")
        verd = verdicts.run_all(quality=args.quality, on_row=lambda v: say(
            f"  {v.preset:<12} {'crown' if v.crown else 'no crown':<9} (seed: "
            f"{'crown' if v.seed_crown else 'no crown'}) {v.wall_s:6.0f} s  {v.outcome}"))
        result["verdicts"] = [v.as_dict() for v in verd]
    header = [f"Machine: {result['machine']}; arch {be.resolved}, {be.precision}; "
              f"date {result['date']}.", "", f"Command: `{result['command']}`"]
    paths = report.write_all(rows, out, header) if rows else {}
    if stab:
        paths["stability"] = os.path.join(out, "stability.md")
        with open(paths["stability"], "w") as f:
            f.write("\n".join(header + ["", stability.markdown(stab), ""]))
    if verd:
        paths["verdicts"] = os.path.join(out, "verdicts.md")
        with open(paths["verdicts"], "w") as f:
            f.write("\n".join(header + ["", verdicts.markdown(verd), ""]))
    result["files"] = paths
    with open(os.path.join(out, "validation.json"), "w") as f:
        json.dump(result, f, indent=1, default=float)
    if args.record:
        _record(result, rows, stab, verd, paths)
    if args.json:
        print(json.dumps(result, indent=1, default=float))
    else:
        if rows:
            print(report.markdown(rows))
        if stab:
            print(stability.markdown(stab))
        if verd:
            print(verdicts.markdown(verd))
        for k, v in paths.items():
            print(f"{k}: {v}", file=sys.stderr)
    failed = [r for r in stab if not r.passed]
    return 1 if failed else 0


def _record(result, rows, stab, verd, paths) -> None:
    """Rewrite VALIDATION.md at the repository root with this run's tables."""
    from ..validate import report, stability, verdicts

    root = repo_root()
    lines = ["# Validation", "",
             "Written by `crowndemo validate --record` (see the README's Validation section); "
             "the numbers below are measured, not edited.", "",
             f"- machine: {result['machine']}", f"- arch: {result['arch']}, {result['precision']}",
             f"- date: {result['date']}", f"- command: `{result['command']}`", ""]
    if rows:
        lines += ["## Error against run time", ""]
        if "plot" in paths:
            rel = os.path.relpath(os.path.join(root, "docs", "error_vs_time.png"), root)
            os.makedirs(os.path.join(root, "docs"), exist_ok=True)
            with open(paths["plot"], "rb") as src, open(os.path.join(root, rel), "wb") as dst:
                dst.write(src.read())
            lines += [f"![error against wall time]({rel})", ""]
        lines += [report.markdown(rows), ""]
    if stab:
        lines += ["## Stability suite", "", stability.markdown(stab), ""]
    if verd:
        lines += ["## The seed's observations: crown or not", "", verdicts.markdown(verd), ""]
    lines += ["## Regime map and interpretation", "",
              "The crown / no-crown regime map against Cossali et al.'s threshold is "
              "[docs/regime.md](docs/regime.md) (`crowndemo sweep --record`). What these "
              "numbers mean, and where they fall short, is discussed in the README's "
              "*Validation status*.", ""]
    with open(os.path.join(root, "VALIDATION.md"), "w") as f:
        f.write("\n".join(lines))


def register(sub, common) -> None:
    from ..config import QUALITIES
    p = sub.add_parser("validate", parents=common, formatter_class=Fmt, epilog=VALIDATE_EPILOG,
                       help="error against run time for the reference cases; stability suite",
                       description="Run the validation cases (method.md §7-8) at several "
                                   "resolutions and settings, the stability suite and the "
                                   "seed's crown / no-crown runs, and report error, wall time, "
                                   "particles and steps.")
    p.add_argument("cases", nargs="*", metavar="CASE",
                   help="cases or groups to run (default: all; see --list)")
    p.add_argument("--quick", action="store_true",
                   help="the coarse resolutions only, stability to 0.4 ms, no 3m-drop crown "
                        "and no verdicts unless named")
    p.add_argument("--no-variants", action="store_true",
                   help="base settings only (no f64, safety/2, gradient forms, untrimmed)")
    p.add_argument("--quality", choices=QUALITIES, default="draft",
                   help="quality of the verdict runs (default: draft)")
    p.add_argument("--out", metavar="DIR", default=None,
                   help="folder for the reports (default: reports/ at the repository root)")
    p.add_argument("--record", action="store_true",
                   help="rewrite VALIDATION.md at the repository root with the results")
    p.add_argument("--list", action="store_true", help="list the cases and exit")
    p.add_argument("--json", action="store_true", help="print everything as one JSON object")
    p.set_defaults(func=_validate)
