"""Benchmark results as tables: plain text for the terminal, Markdown for BENCHMARKS.md (the
main table, the time per step by stage, the tuned / seed ratios)."""
from __future__ import annotations

from typing import Dict, List, Sequence

from .measure import STAGE_STEPS

COLUMNS = ("fluid", "total", "steps", "seconds", "particle-steps/s", "compile s", "bytes/particle",
           "arch", "precision")
# a preset run to its end time: the wall time the user waits, and how it splits
PRESET_COLUMNS = ("preset", "fluid", "total", "steps", "simulated ms", "to t_end s", "start-up s",
                  "particle-steps/s", "bytes/particle", "arch", "precision")


def _preset_row(r: Dict) -> List[str]:
    arch = r["arch"] if r["arch"] == r["resolved_arch"] else f"{r['arch']} ({r['resolved_arch']})"
    return [r["label"], f"{r['particles']['fluid']:,}", f"{r['particles']['total']:,}",
            str(r["steps"]), f"{1e3 * r['simulated_s']:.3g} of {1e3 * r['t_end_s']:.3g}",
            f"{r['run_s']:.1f}", f"{r['startup_s']:.1f}", f"{r['particle_steps_per_s']:.3e}",
            f"{r['bytes_per_particle']:.0f}", arch,
            _build(r)]


def _build(r: Dict) -> str:
    """The precision column: the float type, and how the kernels were run and built (and the
    neighbour list's layout where it is not the default)."""
    return (r["precision"] + (" 1-thread" if r["single_thread"] else "")
            + (" fast-compile" if r.get("fast_compile") else "")
            + (" slot-list" if r.get("list_layout") == "slot" else ""))


def _presets(results: Sequence[Dict]) -> bool:
    return any("preset" in r for r in results)


def _row(r: Dict) -> List[str]:
    arch = r["arch"] if r["arch"] == r["resolved_arch"] else f"{r['arch']} ({r['resolved_arch']})"
    return [f"{r['particles']['fluid']:,}", f"{r['particles']['total']:,}", str(r["steps"]),
            f"{r['seconds']:.3f}", f"{r['particle_steps_per_s']:.3e}", f"{r['compile_s']:.2f}",
            f"{r['bytes_per_particle']:.0f}", arch,
            _build(r)]


def _labelled(results: Sequence[Dict]) -> bool:
    return any(r.get("label", "tuned") != "tuned" for r in results)


def _label_head(results: Sequence[Dict]) -> str:
    return "preset" if _presets(results) else "variant"


def _rows(results: Sequence[Dict]) -> List[List[str]]:
    """The main table: a ``variant`` column first when results compare formulations; preset
    runs have their own columns (PRESET_COLUMNS)."""
    if _presets(results):
        return [list(PRESET_COLUMNS)] + [_preset_row(r) for r in results]
    head = list(COLUMNS)
    rows = [_row(r) for r in results]
    if _labelled(results):
        head = ["variant"] + head
        rows = [[r["label"]] + row for r, row in zip(results, rows)]
    return [head] + rows


def stage_rows(results: Sequence[Dict]) -> List[List[str]]:
    """Milliseconds per step by stage (core/step.py STAGES), with each stage's share."""
    from ..core.step import STAGES
    timed = [r for r in results if r.get("stage_ms")]
    if not timed:
        return []
    head = ([_label_head(results)] if _labelled(results) else []) + ["fluid"] + list(STAGES) \
        + ["sum"]
    rows = [head]
    for r in timed:
        ms = r["stage_ms"]
        total = sum(ms.values())
        cells = [f"{ms[s]:.1f} ({100 * ms[s] / total:.0f} %)" if s in ms else "-"
                 for s in STAGES]
        rows.append(([r["label"]] if _labelled(results) else [])
                    + [f"{r['particles']['fluid']:,}"] + cells + [f"{total:.1f}"])
    return rows


def comparison_lines(results: Sequence[Dict]) -> List[str]:
    """'tuned / seed' throughput ratio per N, where both were run."""
    lines = []
    by_n: Dict[int, Dict[str, Dict]] = {}
    for r in results:
        if "n_requested" in r:      # a tank block (not a preset run)
            by_n.setdefault(r["n_requested"], {})[r.get("label", "tuned")] = r
    for n, pair in by_n.items():
        if "seed" in pair and "tuned" in pair:
            ratio = pair["tuned"]["particle_steps_per_s"] / pair["seed"]["particle_steps_per_s"]
            lines.append(f"N = {pair['tuned']['particles']['fluid']:,}: tuned / seed = "
                         f"{ratio:.2f} x")
    return lines


def _right_aligned(rows: List[List[str]], labelled: bool, text_tail: int) -> List[bool]:
    """Numbers right, words (the variant, and the last ``text_tail`` columns) left."""
    n = len(rows[0])
    return [not (labelled and c == 0) and c < n - text_tail for c in range(n)]


def _markdown(rows: List[List[str]], right: List[bool]) -> str:
    align = ["---:" if r else "---" for r in right]
    return "\n".join("| " + " | ".join(row) + " |" for row in [rows[0], align] + rows[1:])


def _text(rows: List[List[str]], right: List[bool]) -> List[str]:
    widths = [max(len(row[c]) for row in rows) for c in range(len(rows[0]))]
    lines = []
    for i, row in enumerate(rows):
        cells = [cell.rjust(w) if right[c] else cell.ljust(w)
                 for c, (cell, w) in enumerate(zip(row, widths))]
        lines.append("  ".join(cells).rstrip())
        if i == 0:
            lines.append("  ".join("-" * w for w in widths))
    return lines


def _tables(results: Sequence[Dict]):
    """(main rows, its alignment, stage rows, their alignment, ratio lines)."""
    lab = _labelled(results)
    rows = _rows(results)
    stages = stage_rows(results)
    return (rows, _right_aligned(rows, lab, 2), stages,
            _right_aligned(stages, lab, 0) if stages else [], comparison_lines(results))


def markdown_table(results: Sequence[Dict]) -> str:
    rows, right, stages, stage_right, ratios = _tables(results)
    out = _markdown(rows, right)
    if stages:
        how = ("over every step after the first" if _presets(results) else
               f"from {STAGE_STEPS} more steps timed stage by stage")
        out += f"\n\nTime per step by stage, ms (share), {how}:\n\n" + _markdown(stages,
                                                                                   stage_right)
    if ratios:
        out += "\n\n" + "\n".join(f"- {line}" for line in ratios)
    return out


def text_table(results: Sequence[Dict]) -> str:
    rows, right, stages, stage_right, ratios = _tables(results)
    lines = _text(rows, right)
    if stages:
        lines += ["", "time per step by stage, ms (share):"] + _text(stages, stage_right)
    if ratios:
        lines += [""] + ratios
    return "\n".join(lines)
