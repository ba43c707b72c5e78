"""Validation output: a Markdown table, a CSV file and a log-log plot of error against wall time
per case (matplotlib, an optional extra: without it the plot is skipped and said so)."""
from __future__ import annotations

import csv
import math
import os
from typing import IO, Any, Dict, Iterable, List, Optional, Sequence, Tuple

from .. import strictjson

COLUMNS = ("case", "variant", "resolution", "scale", "l0", "particles", "steps", "wall_s",
           "compile_s", "measured", "reference", "error", "outcome")


def _fmt(v) -> str:
    if isinstance(v, float):
        if not math.isfinite(v):
            return str(v)
        return f"{v:.4g}"
    return str(v)


# extras shown under a case's table, one line per run (errors as per cent)
SHOWN_EXTRAS = {"time origin dT": "{:.3g}", "worst without dT": "{:.2%}",
                "turn_rad": "{:.3g}", "drift_over_R": "{:.2g}", "p_in_over_laplace": "{:.3f}",
                "decay_1_s": "{:.3g}", "decay_ref_1_s": "{:.3g}",
                "decay_exact_1_s": "{:.3g}", "ejected": "{:d}"}


def _shown_extras(r) -> str:
    parts = [f"{k} {fmt.format(r.extra[k])}" for k, fmt in SHOWN_EXTRAS.items()
             if isinstance(r.extra.get(k), int) or (
                 isinstance(r.extra.get(k), float) and math.isfinite(r.extra[k]))]
    return ", ".join(parts)


def markdown(rows: Sequence, title: str = "Validation") -> str:
    """One table per case: a row per run, the error in per cent."""
    out: List[str] = []
    by_case: Dict[str, list] = {}
    for r in rows:
        by_case.setdefault(r.case, []).append(r)
    for name, rs in by_case.items():
        out.append(f"### {name}: {rs[0].quantity}")
        out.append("")
        out.append("| variant | resolution | l0 (m) | particles | steps | wall (s) | compile (s) "
                   "| measured | reference | error | outcome |")
        out.append("|---|---|---|---|---|---|---|---|---|---|---|")
        for r in rs:
            err = f"{100 * r.error:.2f} %" if math.isfinite(r.error) else "-"
            out.append(f"| {r.variant} | {r.resolution} = {r.scale:g} | {r.l0:.3g} | "
                       f"{f'{r.particles:,}' if r.particles else '-'} | {r.steps:,} | "
                       f"{r.wall_s:.1f} | {r.compile_s:.1f} | "
                       f"{_fmt(r.measured)} | {_fmt(r.reference)} | {err} | {r.outcome} |")
        notes = [(r, _shown_extras(r)) for r in rs]
        if any(text for _, text in notes):
            out.append("")
            out += [f"- {r.variant}, {r.resolution} = {r.scale:g}: {text}"
                    for r, text in notes if text]
        out.append("")
    return "\n".join(out)


def write_csv(rows: Sequence, path: str) -> None:
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(COLUMNS + ("extra",))
        for r in rows:
            d = r.as_dict()
            w.writerow([d[k] for k in COLUMNS] +
                       ["; ".join(f"{k}={_fmt(v)}" for k, v in d["extra"].items())])


# the last part of a case's name says which member of its family it is: a family (the same
# physics) shares a colour, its members differ in line style (2D solid, 3D dashed)
MEMBER_STYLES = {"-2d": "-", "-3d": "--", "-quick": "-", "-3m-drop": "--"}
# matplotlib's ten cycle colours, then the ten lighter ones of its tab20 map
PALETTE = tuple(f"C{k}" for k in range(10)) + (
    "#aec7e8", "#ffbb78", "#98df8a", "#ff9896", "#c5b0d5", "#c49c94", "#f7b6d2", "#c7c7c7",
    "#dbdb8d", "#9edae5")


def case_styles(names: Iterable[str]) -> Dict[str, Tuple[str, str]]:
    """(matplotlib colour, line style) for each case name: one colour per family, in the order
    families first appear in sorted names, and the line style of its member suffix."""
    styles: Dict[str, Tuple[str, str]] = {}
    families: Dict[str, int] = {}
    for name in sorted(names):
        suffix = next((s for s in MEMBER_STYLES if name.endswith(s)), "")
        family = families.setdefault(name[:len(name) - len(suffix)], len(families))
        styles[name] = (PALETTE[family % len(PALETTE)], MEMBER_STYLES.get(suffix, ":"))
    return styles


def plot(rows: Sequence, path: str) -> Optional[str]:
    """Error against wall time, log-log, one line per case through its base-setting runs (its
    colour and style from ``case_styles``) and a marker per variant. Returns None when
    written, else why not."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return "matplotlib is not installed (pip install '.[plot]')"
    cases: Dict[str, list] = {}
    for r in rows:
        if r.outcome == "ok" and math.isfinite(r.error) and r.error > 0:
            cases.setdefault(r.case, []).append(r)
    if not cases:                       # nothing for log-log axes
        return "no run with a finite, positive error"
    fig, ax = plt.subplots(figsize=(10, 5.5))
    markers = {"f64": "s", "safety/2": "^", "gradient=sum": "D", "gradient=seed": "v",
               "untrimmed": "P", "plane-floor": "<", "relative-courant": ">",
               "lattice": "x", "viscosity=laplacian": "*"}
    styles = case_styles(cases)
    for name, rs in sorted(cases.items()):
        colour, line = styles[name]
        base = sorted((r for r in rs if r.variant == "base"), key=lambda r: r.wall_s)
        if base:
            ax.plot([r.wall_s for r in base], [r.error for r in base], "o", linestyle=line,
                    color=colour, label=name)
        for r in rs:
            if r.variant != "base":
                ax.plot(r.wall_s, r.error, markers.get(r.variant, "x"), color=colour,
                        markerfacecolor="none")
    for v, m in markers.items():
        ax.plot([], [], m, color="grey", markerfacecolor="none", label=v)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time without JIT compile (s)")
    ax.set_ylabel("relative error")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))   # beside the data
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return None


def write_all(rows: Sequence, folder: str, header: Iterable[str] = ()) -> Dict[str, str]:
    """validation.md, validation.csv and error_vs_time.png in ``folder``; returns the paths
    (and 'plot_skipped' with the reason when there is no plot)."""
    os.makedirs(folder, exist_ok=True)
    md = os.path.join(folder, "validation.md")
    with open(md, "w") as f:
        f.write("\n".join(list(header) + ["", markdown(rows)]))
    out = {"markdown": md, "csv": os.path.join(folder, "validation.csv")}
    write_csv(rows, out["csv"])
    png = os.path.join(folder, "error_vs_time.png")
    why = plot(rows, png)
    if why is None:
        out["plot"] = png
    else:
        out["plot_skipped"] = why
        remove_stale(folder, ["error_vs_time.png"], [])     # an older run's plot
    return out


def remove_stale(folder: str, names: Iterable[str], written: Iterable[str]) -> List[str]:
    """Remove the report files ``names`` in ``folder`` that this run did not write (an
    earlier run's, which would be read as this run's); returns the removed paths."""
    keep = {os.path.abspath(p) for p in written}
    removed = []
    for name in names:
        path = os.path.join(folder, name)
        if os.path.isfile(path) and os.path.abspath(path) not in keep:
            os.remove(path)
            removed.append(path)
    return removed


def dump_json(data: Any, f: IO[str]) -> None:
    """``data`` as strict JSON (null for NaN and Infinity) into the open file ``f``."""
    strictjson.dump(data, f, indent=1)


def dumps_json(data: Any) -> str:
    return strictjson.dumps(data, indent=1)
