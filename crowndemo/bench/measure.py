"""Time the full explicit MPS step: a 3D block of water resting in a tank (``run_one``,
``run``), or a preset run to its end time (``run_preset``); each returns a result dict."""
from __future__ import annotations

import math
import time
from typing import Dict, List, Optional, Sequence, Tuple

DEFAULT_NS = (100_000, 300_000)
DEFAULT_STEPS = 20
DEFAULT_L0 = 1.0e-3
WARMUP_STEPS = 2


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

    from .. import backend
    from ..core import simulator_for
    from ..core.params import Numerics, with_values
    from ..scenes import hydrostatic_tank

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

    from .. import backend
    from ..core import simulator_for

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
