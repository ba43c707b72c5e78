"""Throughput of the full explicit MPS step on a 3D block of water resting in a tank.

``run_one`` builds ``crowndemo.scenes.hydrostatic_tank(dim=3)`` with a fluid block of about N
particles, warms up (the first step compiles the kernels, or loads them from Taichi's offline
cache), then times a number of ``Simulator.step()`` calls. The rate counts fluid particles only:
wall and dummy particles cost work (number density, pressure, neighbour walks) but are not
counted in ``particle_steps_per_s``. ``record`` appends a Markdown section to BENCHMARKS.md.
"""
from __future__ import annotations

import datetime
import math
import os
import platform
import subprocess
import time
from typing import Dict, List, Optional, Sequence, Tuple

DEFAULT_NS = (100_000, 300_000)
DEFAULT_STEPS = 20
DEFAULT_L0 = 1.0e-3
WARMUP_STEPS = 2

BENCHMARKS_HEADER = """\
# Benchmarks

Throughput of the full explicit MPS step, measured by `crowndemo bench` (code:
`crowndemo/bench.py`). The scene is a cube-ish block of water resting in a 3D tank with walls
(`crowndemo.scenes.hydrostatic_tank(dim=3)`, l0 = 1 mm, re = 2.1 l0, water with viscosity,
no surface tension). One step is everything `Simulator.step()` does: cell-grid build with the
re-sort of particles, the predictor (viscosity + gravity), the particle collision model
(pairs closer than 0.5 l0, listed by the predictor's walk), a second grid build, number density
and pressure, the pressure-gradient corrector (`pmin` form), and the health reduction with its
read-back to the host that picks the next dt.

- `fluid`: fluid particles; `total`: including wall and dummy particles (they cost work too).
- `particle-steps/s` = fluid particles x timed steps / seconds.
- The first steps are not timed: they compile the kernels (or load them from Taichi's offline
  cache, so a repeat run shows a smaller `compile s`). `compile s` = first step - a normal step.
- `bytes/particle` = `Simulator.memory_bytes()` / total particles (particle fields, cell grid,
  neighbour list, close-pair list; allocated for the capacity bucket,
  `core.step.capacity_bucket`).

Sections are appended by `crowndemo bench --record`, newest last.
"""


def block_shape(n: int) -> Tuple[int, int]:
    """(k, kz): a k x k x kz lattice block with k = round(n^(1/3)) and k^2 kz close to n."""
    if n < 1:
        raise ValueError("n must be >= 1")
    k = max(1, round(n ** (1.0 / 3.0)))
    kz = max(1, round(n / (k * k)))
    return k, kz


# the seed's formulation with a plain implementation, for ``--compare`` (numerics overrides):
# the seed's gradient form P_j - P_i (S11 in S18) and no collision model; cells of side re
# (a 3^d walk), no neighbour list, no re-sort of the particles into cell order
SEED_NUMERICS = {"pressure_gradient": "seed", "collision": 0.0, "cells_per_re": 1,
                 "neighbour_list": False, "reorder_every": 0}
STAGE_STEPS = 5      # extra steps timed stage by stage (each stage waits for the device)


def run_one(n: int, steps: int = DEFAULT_STEPS, l0: float = DEFAULT_L0,
            numerics: Optional[Dict] = None, label: str = "tuned",
            stages: bool = True) -> Dict:
    """Benchmark one block of about ``n`` fluid particles on the running backend, with the
    project's numerics or with ``numerics`` overrides (``label`` names them). With
    ``stages``, STAGE_STEPS more steps are timed stage by stage (``stage_ms``, per step)."""
    import taichi as ti

    from . import backend
    from .core import simulator_for
    from .core.params import Numerics, with_values
    from .scenes import hydrostatic_tank

    be = backend.current()
    k, kz = block_shape(n)
    t0 = time.perf_counter()
    # the numerics go to the builder: the floor is built of particles or not (wall_model)
    scene = hydrostatic_tank(dim=3, l0=l0, width=k * l0, depth=kz * l0, re_ratio=2.1,
                             numerics=with_values(Numerics(), **(numerics or {})))
    sim = simulator_for(scene)
    ti.sync()
    setup_s = time.perf_counter() - t0

    warm = []
    for _ in range(WARMUP_STEPS):
        t = time.perf_counter()
        sim.step()
        ti.sync()
        warm.append(time.perf_counter() - t)

    t = time.perf_counter()
    for _ in range(steps):
        sim.step()
    ti.sync()
    seconds = time.perf_counter() - t

    stage_ms = None
    if stages:
        sim.time_stages()
        for _ in range(STAGE_STEPS):
            sim.step()
        stage_ms = {name: 1e3 * v / STAGE_STEPS for name, v in sim.stage_seconds.items() if v}
        sim.time_stages(False)

    counts = sim.counts()
    fluid = sim.n_fluid
    total = sim.state.count
    per_step = seconds / steps
    return {
        "label": label,
        "numerics": dict(numerics or {}),
        "model": sim.model.describe(),
        "n_requested": int(n),
        "block": [k, k, kz],
        "l0_m": l0,
        "particles": {"fluid": fluid, "total": total, "wall": counts.get("wall", 0),
                      "dummy": counts.get("dummy", 0)},
        "steps": int(steps),
        "seconds": seconds,
        "seconds_per_step": per_step,
        "particle_steps_per_s": fluid * steps / seconds if seconds > 0 else math.inf,
        "compile_s": max(warm[0] - per_step, 0.0),
        "first_step_s": warm[0],
        "setup_s": setup_s,
        "stage_ms": stage_ms,
        **_backend_and_memory(be, sim),
        "dt_s": sim.stats.dt_max,
    }


def _backend_and_memory(be, sim) -> Dict:
    """The result fields every benchmark shares: where it ran, and the simulator's bytes."""
    total = sim.state.count
    return {"arch": be.arch, "resolved_arch": be.resolved, "precision": be.precision,
            "single_thread": be.single_thread, "fast_compile": be.fast_compile,
            "list_layout": (sim.pressure.neighbours.layout if sim.pressure.neighbours is not None
                            else None),
            "bytes_per_particle": sim.memory_bytes() / total, "memory_bytes": sim.memory_bytes()}


def run_preset(resolved, stages: bool = True, max_steps: Optional[int] = None,
               progress=None) -> Dict:
    """Run a resolved preset (``crowndemo.config.load``) to its end time, as ``crowndemo run``
    does without recording, and time it: ``run_s`` is the whole wall time (scene set-up, the
    first step that compiles or loads the kernels, every step to t_end), ``seconds`` the steps
    after the first. With ``stages`` every step after the first is timed stage by stage
    (``stage_ms``, per step). ``max_steps`` stops early (a smoke test; ``simulated_s`` says
    how far it got). ``progress(sim)`` is called after every step."""
    import taichi as ti

    from . import backend
    from .core import simulator_for

    be = backend.current()
    t0 = time.perf_counter()
    scene = resolved.build_scene()
    sim = simulator_for(scene)
    ti.sync()
    setup_s = time.perf_counter() - t0
    t = time.perf_counter()
    sim.step()
    ti.sync()
    first_s = time.perf_counter() - t
    if progress:
        progress(sim)
    if stages:
        sim.time_stages()

    def on_step(s):
        if progress:
            progress(s)
        if max_steps is not None and s.stats.steps >= max_steps:
            raise _Enough

    t = time.perf_counter()
    try:
        sim.run(resolved.t_end, on_step=on_step)
    except _Enough:
        pass
    ti.sync()
    seconds = time.perf_counter() - t
    run_s = time.perf_counter() - t0
    steps = sim.stats.steps - 1
    stage_ms = None
    if stages and steps > 0:
        stage_ms = {name: 1e3 * v / steps for name, v in sim.stage_seconds.items() if v}
        sim.time_stages(False)
    counts = sim.counts()
    fluid, total = sim.n_fluid, sim.state.count
    per_step = seconds / steps if steps else math.inf
    stats = sim.stats
    return {
        "label": f"{resolved.name} {resolved.quality}",
        "preset": resolved.name,
        "quality": resolved.quality,
        "model": sim.model.describe(),
        "l0_m": resolved.l0,
        "t_end_s": resolved.t_end,
        "simulated_s": stats.time,
        "particles": {"fluid": fluid, "total": total, "wall": counts.get("wall", 0),
                      "dummy": counts.get("dummy", 0), "gone": counts.get("gone", 0)},
        "steps": int(stats.steps),
        "binding_limits": dict(stats.binding),
        "health": stats.as_dict()["health"],     # to compare variants of one preset
        "run_s": run_s,
        "seconds": seconds,
        "seconds_per_step": per_step,
        "particle_steps_per_s": fluid * steps / seconds if seconds > 0 else math.inf,
        "compile_s": max(first_s - per_step, 0.0) if steps else first_s,
        "first_step_s": first_s,
        "setup_s": setup_s,
        "startup_s": setup_s + first_s,
        "stage_ms": stage_ms,
        **_backend_and_memory(be, sim),
        "cells": int(sim.grid.num_cells[None]),
    }


class _Enough(Exception):
    """Raised from the step callback to stop a preset run at ``max_steps``."""


def run(ns: Sequence[int] = DEFAULT_NS, steps: int = DEFAULT_STEPS, l0: float = DEFAULT_L0,
        on_result=None, compare: bool = False, stages: bool = True,
        numerics: Optional[Dict] = None) -> List[Dict]:
    """One result per N; with ``compare``, the seed's formulation (SEED_NUMERICS) first and
    then the tuned one, for each N, in this process; with ``numerics``, those overrides
    (labelled ``KEY=VALUE, ...``) instead of the project's numerics."""
    if numerics:
        label = ", ".join(f"{k}={v}" for k, v in numerics.items())
        variants = [(label, dict(numerics))]
    elif compare:
        variants = [("seed", SEED_NUMERICS), ("tuned", None)]
    else:
        variants = [("tuned", None)]
    results = []
    for n in ns:
        for label, overrides in variants:
            r = run_one(n, steps, l0, numerics=overrides, label=label, stages=stages)
            results.append(r)
            if on_result:
                on_result(r)
    return results


# ---- output ----------------------------------------------------------------------------------
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
    from .core.step import STAGES
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


# ---- the machine (here for bench --record; validate and sweep --record use machine_line) ------
def cpu_model() -> str:
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.lower().startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown CPU"


def usable_cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def gpu_name() -> Optional[str]:
    try:
        out = subprocess.run(["nvidia-smi", "--query-gpu=name", "--format=csv,noheader"],
                             capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    names = [s.strip() for s in out.stdout.splitlines() if s.strip()]
    return ", ".join(names) if out.returncode == 0 and names else None


def os_name() -> str:
    return f"{platform.system()} {platform.release()}"


def machine_line() -> str:
    """The machine in one line, as validate and sweep --record report it: "CPU model, N cores,
    OS release"."""
    return f"{cpu_model()}, {os.cpu_count() or 1} cores, {os_name()}"


def machine() -> Dict:
    import numpy
    import taichi as ti

    info = {"cpu": cpu_model(), "cores": os.cpu_count() or 1, "usable_cores": usable_cores(),
            "python": platform.python_version(), "taichi": ".".join(map(str, ti.__version__)),
            "numpy": numpy.__version__, "os": os_name()}
    gpu = gpu_name()
    if gpu:
        info["gpu"] = gpu
    return info


def record(results: Sequence[Dict], command: str, path: str) -> str:
    """Append a Markdown section (machine, arch, date, command, table) to ``path``; returns it."""
    m = machine()
    be = results[0]
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    arch = be["arch"] if be["arch"] == be["resolved_arch"] else \
        f"{be['arch']} ({be['resolved_arch']})"
    cores = f"{m['cores']} cores" + (f" ({m['usable_cores']} usable)"
                                     if m["usable_cores"] != m["cores"] else "")
    lines = [f"## {now}", "",
             f"- machine: {m['cpu']}, {cores}" + (f"; GPU: {m['gpu']}" if "gpu" in m else ""),
             f"- arch: {arch}; precision: {be['precision']}"
             + ("; single thread" if be["single_thread"] else "")
             + ("; --fast-compile" if be.get("fast_compile") else ""),
             f"- software: taichi {m['taichi']}, python {m['python']}, numpy {m['numpy']}, "
             f"{m['os']}",
             f"- command: `{command}`",
             "", markdown_table(results), ""]
    section = "\n".join(lines)
    new = not os.path.exists(path) or os.path.getsize(path) == 0
    with open(path, "a") as f:
        if new:
            f.write(BENCHMARKS_HEADER)
        f.write("\n" + section)
    return section
