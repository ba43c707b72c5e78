"""Throughput of the full explicit MPS step on a 3D block of water resting in a tank.

``run_one`` builds ``crowndemo.scenes.hydrostatic_tank(dim=3)`` with a fluid block of about N
particles, warms up (the first step compiles the kernels, or loads them from Taichi's offline
cache), then times a number of ``Simulator.step()`` calls. The rate counts fluid particles only:
wall and dummy particles cost work (number density, pressure, neighbour walks) but are not
counted in ``particle_steps_per_s``. ``run_preset`` runs a preset to its end time instead.

measure.py   the timed runs (a tank block, a preset) -> result dicts
tables.py    results -> text and Markdown tables (main table, stages, tuned / seed ratios)
report.py    BENCHMARKS.md: ``record`` appends a section (machine, date, command, tables)
The machine's description is ``crowndemo.machine`` (validate and sweep --record use it too).
"""
from __future__ import annotations

from .measure import (DEFAULT_L0, DEFAULT_NS, DEFAULT_STEPS, SEED_NUMERICS, STAGE_STEPS,
                      WARMUP_STEPS, block_shape, run, run_one, run_preset)
from .report import BENCHMARKS_HEADER, record
from .tables import comparison_lines, markdown_table, stage_rows, text_table

__all__ = ["DEFAULT_L0", "DEFAULT_NS", "DEFAULT_STEPS", "SEED_NUMERICS", "STAGE_STEPS",
           "WARMUP_STEPS", "block_shape", "run", "run_one", "run_preset", "BENCHMARKS_HEADER",
           "record", "comparison_lines", "markdown_table", "stage_rows", "text_table"]
