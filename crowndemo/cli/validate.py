"""``crowndemo validate``: reference cases at several resolutions and settings (error against
run time), the stability suite, and the seed's crown / no-crown observations."""
from __future__ import annotations

import datetime
import os
import shlex
import sys
from typing import List

from .common import (EXIT_FAILED, EXIT_INTERRUPTED, PROG, Fmt, UsageError, add_quality,
                     path_argument, repo_root, require_folder, start_backend)

GROUPS = ("stability", "verdicts")
# what --quick leaves out unless named: the costly crown case, the 3D free drop (10 periods,
# ~100 s at its quick R/l0 = 8; the 2D one checks the same conservation) and the verdicts
QUICK_LEAVES_OUT = ("crown-base-3m-drop", "stress-free-drop-3d", "verdicts")
INTERRUPTED = "**Interrupted (Ctrl-C): a partial run; only the runs that finished are reported.**"

VALIDATE_EPILOG = """\
examples:
  crowndemo validate --quick                     # coarse resolutions, each variant once
  crowndemo validate                             # every case, every resolution and setting
  crowndemo validate dam-break-2d laplace-2d     # some cases
  crowndemo validate stability                   # the stiff and extreme cases only
  crowndemo validate verdicts --quality draft    # crown or not, the seed's four runs
  crowndemo validate --list
  crowndemo validate --record                    # also rewrite VALIDATION.md
  crowndemo validate stress-laplace-3d stress-drop-oscillation-3d --at-every-resolution re=3.1
                                                 # the stress drops at both neighbourhoods

Cases: hydrostatic, dam-break, drop-oscillation, laplace, shear-wave, sliding-layer,
stress-laplace, stress-drop-oscillation, stress-free-drop (each -2d and -3d),
crown-base-quick, crown-base-3m-drop; groups: stability, verdicts. The stress- cases run the
surface-stress model (method.md §4c) with the sum gradient form, their 3D drops started off
the lattice (variant lattice: on it), at re = 2.1 l0 (variant re=3.1: the member's wider
neighbourhood). Each case runs at three resolutions in the base settings and, at the middle
one, in its settings variants (--list says which case runs which; --at-every-resolution
VARIANT runs one at every resolution):
  {variants}
--quick runs each case at one coarse resolution and in one of its variants (--list names
it), the stability suite to 0.4 ms, and leaves out crown-base-3m-drop, stress-free-drop-3d and
the verdicts unless named; it compiles as with --fast-compile (unless $CROWNDEMO_FAST_COMPILE
says otherwise).
Output in --out (default reports/): validation.md, validation.csv, error_vs_time.png (with
matplotlib: pip install '.[plot]'), stability.md, verdicts.md, and all of it as
validation.json (strict JSON: null for a value that is not a finite number). A run that
measures cases replaces their report as a whole (an older plot it could not redraw is
removed); stability.md and verdicts.md of earlier runs stay, headed by their own command.
Ctrl-C writes the runs finished so far, marked as an interrupted run, and exits 130.
Wall times exclude the first step of each run, which compiles the kernels (reported apart);
runs of the same compiled model share one simulator where the scene fits in it, so only the
first of them (and a bigger scene) compiles.
"""


def variants_text() -> str:
    """The settings variants the cases run, from the case table (read when help is shown)."""
    from ..config import PresetError
    from ..validate.cases import all_cases
    from ..validate.runner import variant_names
    try:
        return ", ".join(variant_names(all_cases(full=True).values()))
    except PresetError as e:
        return f"unknown: {e}"


class _VariantsFmt(Fmt):
    """Fills {variants} in the help texts when they are shown, so they list the code's."""

    def add_text(self, text):
        if text and "{variants}" in text:
            text = text.replace("{variants}", variants_text())
        super().add_text(text)

    def _get_help_string(self, action):
        text = action.help or ""
        return text.replace("{variants}", variants_text()) if "{variants}" in text else text


def _list(table, extra, as_json: bool = False) -> int:
    """The cases and groups, a line each (``as_json``: one JSON object)."""
    from .. import strictjson
    from ..validate import stability, verdicts

    if extra:
        raise UsageError(f"--list takes no case names (got {', '.join(extra)}); allowed: "
                         f"'{PROG} validate --list' alone")
    if as_json:
        print(strictjson.dumps({
            "cases": [{"name": c.name, "quantity": c.quantity, "reference": c.reference,
                       "resolution": c.resolution, "scales": list(c.scales),
                       "quick": list(c.quick), "quick_variants": list(c.quick_variants),
                       "variants": list(c.variants)}
                      for c in table.values()],
            "groups": {"stability": list(stability.cases(True)),
                       "verdicts": list(verdicts.SEED)}}))
        return 0
    for c in table.values():
        print(f"{c.name:<22} {c.quantity}; reference: {c.reference}; {c.resolution} = "
              f"{', '.join(f'{s:g}' for s in c.scales)} (quick: "
              f"{', '.join(f'{s:g}' for s in c.quick)}"
              f"{''.join(', variant ' + v for v in c.quick_variants)}); variants: "
              f"{', '.join(c.variants) or 'none'}")
    print(f"{'stability':<22} stiff and extreme drop-on-film cases: "
          f"{', '.join(stability.cases(True))}")
    print(f"{'verdicts':<22} crown or not for {', '.join(verdicts.SEED)} (the seed's runs)")
    return 0


def _names(args, table) -> list:
    """The cases and groups to run, each once, in the order given; UsageError for unknown."""
    names = list(dict.fromkeys(args.cases)) or (list(table) + list(GROUPS))
    if args.quick and not args.cases:
        names = [n for n in names if n not in QUICK_LEAVES_OUT]
    unknown = [n for n in names if n not in table and n not in GROUPS]
    if unknown:
        from ..config.errors import did_you_mean
        hint = did_you_mean(unknown[0], list(table) + list(GROUPS)) if len(unknown) == 1 else ""
        raise UsageError(f"unknown case {', '.join(unknown)}{hint}; allowed: "
                         f"{', '.join(list(table) + list(GROUPS))} (see '{PROG} validate --list')")
    return names


def _check_everywhere(args, selected) -> None:
    """--at-every-resolution names variants of the selected cases, and asks for variants
    (UsageError otherwise, before any kernel runs)."""
    from ..validate.runner import variant_names
    if not args.at_every_resolution:
        return
    if args.no_variants:
        raise UsageError("--at-every-resolution runs a settings variant; --no-variants "
                         "runs none: give one or the other")
    allowed = variant_names(selected)
    unknown = [v for v in args.at_every_resolution if v not in allowed]
    if unknown:
        raise UsageError(f"--at-every-resolution {unknown[0]}: not a variant of the cases "
                         f"selected; allowed: {', '.join(allowed) or 'none'} (see "
                         f"'{PROG} validate --list')")


def _run(args, names, table, found, say) -> None:
    """Run the selected cases and groups; every finished row goes into ``found`` at once, so
    that an interrupted run keeps it."""
    from ..validate import runner, stability, verdicts

    def row_line(r):
        found["cases"].append(r)
        err = f"{100 * r.error:.2f} %" if r.error == r.error and r.error != float("inf") else "-"
        say(f"  {r.case:<20} {r.variant:<14} {r.resolution} = {r.scale:<6g} {r.particles:>7,} "
            f"particles {r.steps:>6,} steps {r.wall_s:7.1f} s  error {err:>9}  {r.outcome}")

    def stab_line(r):
        found["stability"].append(r)
        say(f"  {r.case:<18} {r.steps:>6,} steps {r.wall_s:6.1f} s  {r.outcome}"
            f"{'' if r.passed else '  FAILED: ' + '; '.join(r.checks)}")

    def verdict_line(v):
        found["verdicts"].append(v)
        say(f"  {v.preset:<12} {'crown' if v.crown else 'no crown':<9} (seed: "
            f"{'crown' if v.seed_crown else 'no crown'}) {v.wall_s:6.0f} s  {v.outcome}")

    selected = [table[n] for n in names if n in table]
    if selected:
        say(f"{PROG}: validating {len(selected)} case(s){' (quick)' if args.quick else ''}")
        runner.run_suite(selected, quick=args.quick, variants=not args.no_variants,
                         on_row=row_line, everywhere=args.at_every_resolution)
    if "stability" in names:
        say(f"{PROG}: stability suite")
        stability.run_suite(full=not args.quick, on_row=stab_line)
    if "verdicts" in names:
        say(f"{PROG}: crown verdicts at quality {args.quality}")
        verdicts.run_all(quality=args.quality, on_row=verdict_line)


def _write(out, header, rows, stab, verd, ran: dict) -> dict:
    """The report files in ``out`` of the groups this run ran (``ran``), even with no row
    (interrupted before the first finished: the header says so). The cases' report
    (validation.md, .csv and the plot) is replaced as a whole (report.write_all removes a
    plot it could not draw). The reports of groups it did not run are left, each headed by
    its own run's command and date (a quick subset must not delete an hour-long run's)."""
    from ..validate import report, stability, verdicts

    os.makedirs(out, exist_ok=True)
    paths = report.write_all(rows, out, header) if ran["cases"] else {}
    for key, items, md in (("stability", stab, stability.markdown),
                           ("verdicts", verd, verdicts.markdown)):
        if ran[key]:
            paths[key] = os.path.join(out, f"{key}.md")
            with open(paths[key], "w") as f:
                f.write("\n".join(header + ["", md(items), ""]))
    return paths


def _validate(args, argv) -> int:
    from ..machine import machine_line
    from ..validate import cases as cases_mod
    from ..validate import report, stability, verdicts

    table = cases_mod.all_cases(full=True)
    if args.list:
        return _list(table, args.cases, args.json)
    names = _names(args, table)
    _check_everywhere(args, [table[n] for n in names if n in table])
    out = os.path.join(repo_root(), "reports") if args.out is None else args.out
    require_folder("--out", out)
    if args.quick and args.fast_compile is None and "CROWNDEMO_FAST_COMPILE" not in os.environ:
        args.fast_compile = True        # a check, not a timing: compile in a fraction of the time
    be = start_backend(args)

    def say(text):
        if not args.json:
            print(text, file=sys.stderr, flush=True)

    result = {"machine": machine_line(), "date": datetime.date.today().isoformat(),
              "command": " ".join([PROG] + [shlex.quote(a) for a in argv]),
              "arch": be.resolved, "precision": be.precision, "fast_compile": be.fast_compile,
              "quick": args.quick}
    found = {"cases": [], "stability": [], "verdicts": []}
    interrupted = False
    try:
        _run(args, names, table, found, say)
    except KeyboardInterrupt:
        interrupted = True
        print(f"{PROG}: interrupted (Ctrl-C): writing the "
              f"{sum(map(len, found.values()))} runs that finished", file=sys.stderr)
    rows, stab, verd = found["cases"], found["stability"], found["verdicts"]
    result["interrupted"] = interrupted
    ran = {"cases": any(n in table for n in names), "stability": "stability" in names,
           "verdicts": "verdicts" in names}
    result.update({k: [r.as_dict() for r in found[k]] for k in found if ran[k]})
    header = [f"Machine: {result['machine']}; arch {be.resolved}, {be.precision}"
              f"{', fast compile' if be.fast_compile else ''}; date {result['date']}.", "",
              f"Command: `{result['command']}`"]
    if interrupted:
        header += ["", INTERRUPTED]
    paths = _write(out, header, rows, stab, verd, ran)
    result["files"] = paths
    with open(os.path.join(out, "validation.json"), "w") as f:
        report.dump_json(result, f)
    if args.record and interrupted:
        print(f"{PROG}: VALIDATION.md not rewritten: the run was interrupted", file=sys.stderr)
    elif args.record:
        _record(result, rows, stab, verd, paths)
    if args.json:
        print(report.dumps_json(result))
    else:
        if rows:
            print(report.markdown(rows))
        if stab:
            print(stability.markdown(stab))
        if verd:
            print(verdicts.markdown(verd))
        for k, v in paths.items():
            print(f"{k}: {v}", file=sys.stderr)
    if interrupted:
        return EXIT_INTERRUPTED
    return EXIT_FAILED if any(not r.passed for r in stab) else 0


def _record(result, rows, stab, verd, paths) -> None:
    """Rewrite VALIDATION.md at the repository root with this run's tables."""
    from ..validate import report, stability, verdicts

    root = repo_root()
    lines = ["# Validation", "",
             "Written by `crowndemo validate --record` (see the README's `validate` command "
             "and its Validation status); the numbers below are measured, not edited.", "",
             f"- machine: {result['machine']}", f"- arch: {result['arch']}, {result['precision']}"
             f"{', fast compile' if result.get('fast_compile') else ''}",
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
    lines += ["## Symmetry planes and trim", "",
              "A half or quarter run with mirror planes against the whole scene (tank floor "
              "pressure, dam-break front, the quarter crown against the whole run's "
              "quadrants) and how far the impact disturbs the film (the trim): "
              "[docs/symmetry.md](docs/symmetry.md) (`tools/symmetry_study.py`; "
              "`tests/test_symmetry.py`).", ""]
    lines += ["## Regime map and interpretation", "",
              "The crown / no-crown regime map against Cossali et al.'s threshold is "
              "[docs/regime.md](docs/regime.md) (`crowndemo sweep --record`). What these "
              "numbers mean, and where they fall short, is discussed in the README's "
              "*Validation status*.", ""]
    path = os.path.join(root, "VALIDATION.md")
    if os.path.isfile(path):        # sections other commands write (the sound-speed study)
        with open(path, encoding="utf-8") as f:
            lines += kept_sections(f.read(), lines)
    with open(path, "w") as f:
        f.write("\n".join(lines))


def kept_sections(old: str, new_lines: List[str]) -> List[str]:
    """The '## ' sections of the old VALIDATION.md whose headings the new lines do not have:
    those that other commands write (`python -m crowndemo.validate.sound_speed table FILE
    --record`), kept through a rewrite, each to the next '## ' heading."""
    written = {line for line in new_lines if line.startswith("## ")}
    out: List[str] = []
    keep = False
    for line in old.splitlines():
        if line.startswith("## "):
            keep = line not in written
        if keep:
            out.append(line)
    return out + ([""] if out and out[-1] != "" else [])


def register(sub, common) -> None:
    p = sub.add_parser("validate", parents=common, formatter_class=_VariantsFmt,
                       epilog=VALIDATE_EPILOG,
                       help="error against run time for the reference cases; stability suite",
                       description="Run the validation cases (method.md §7-8) at several "
                                   "resolutions and settings, the stability suite and the "
                                   "seed's crown / no-crown runs, and report error, wall time, "
                                   "particles and steps.")
    p.add_argument("cases", nargs="*", metavar="CASE",
                   help="cases or groups to run (default: all; see --list)")
    p.add_argument("--quick", action="store_true",
                   help="one coarse resolution and at most one settings variant per case "
                        "(--list names it), stability to 0.4 ms, no 3m-drop crown and no verdicts "
                        "unless named; compiles as with --fast-compile unless "
                        "$CROWNDEMO_FAST_COMPILE is set")
    p.add_argument("--no-variants", action="store_true",
                   help="base settings only (no {variants})")
    p.add_argument("--at-every-resolution", action="append", default=[], metavar="VARIANT",
                   help="run this settings variant at every resolution of the cases that have "
                        "it, not only the middle one (repeatable; e.g. re=3.1: the stress "
                        "drops at the member's wider neighbourhood)")
    add_quality(p, "draft", "quality of the verdict runs")
    p.add_argument("--out", type=path_argument, metavar="DIR", default=None,
                   help="folder for the reports (default: reports/ at the repository root)")
    p.add_argument("--record", action="store_true",
                   help="rewrite VALIDATION.md at the repository root with the results")
    p.add_argument("--list", action="store_true",
                   help="list the cases (with their variants) and groups, and exit")
    p.add_argument("--json", action="store_true", help="print everything as one JSON object")
    p.set_defaults(func=_validate)
