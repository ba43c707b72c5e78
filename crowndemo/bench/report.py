"""BENCHMARKS.md: its header, and a section per ``crowndemo bench --record`` (machine, arch,
date, command, tables) appended to it."""
from __future__ import annotations

import datetime
import os
from typing import Dict, Sequence

from ..machine import machine
from .tables import markdown_table

BENCHMARKS_HEADER = """\
# Benchmarks

Throughput of the full explicit MPS step, measured by `crowndemo bench` (code:
`crowndemo/bench/`). The scene is a cube-ish block of water resting in a 3D tank with walls
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
