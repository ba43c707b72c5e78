"""Runs validation cases at several resolutions and settings and collects one row per run:
error, wall time, particles, steps (method.md §8)."""
from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field
from typing import Callable, Dict, Iterable, List, Optional

from .. import backend
from ..core import InstabilityError, Numerics
from ..control import Session
from .cases import Case, sharing, variant_numerics, variant_scene


@dataclass
class Row:
    case: str
    dim: int
    variant: str                  # "base", "f64", "safety/2", "gradient=sum", "untrimmed", ...
    resolution: str               # e.g. "a/l0"
    scale: float                  # its value
    l0: float
    particles: int
    steps: int
    wall_s: float                 # set-up + stepping, first step (JIT compile) excluded
    compile_s: float              # the first step, which compiles the kernels
    measured: float
    reference: float
    error: float
    outcome: str                  # "ok" or "unstable: ..." / "failed: ..."
    quantity: str = ""
    extra: Dict[str, float] = field(default_factory=dict)

    def as_dict(self) -> dict:
        return asdict(self)


def run_one(case: Case, scale: float, variant: str = "base") -> Row:
    """One case at one resolution and one settings variant (the backend's precision must
    already be the variant's)."""
    l0 = case.l0_of(scale)
    numerics = variant_numerics(variant, case.base(Numerics()))
    opts = variant_scene(variant)
    t0 = time.perf_counter()
    try:
        res = case.run(l0, numerics, **opts)
    except InstabilityError as e:
        return Row(case.name, case.dim, variant, case.resolution, scale, l0, e.particles, e.step,
                   time.perf_counter() - t0, 0.0, math.nan, math.nan, math.inf,
                   f"unstable: {e.what} at step {e.step}, t = {e.time * 1e3:.4g} ms",
                   case.quantity)
    wall = time.perf_counter() - t0
    sim = res.sim
    compile_s = sim.stats.first_step_seconds
    return Row(case.name, case.dim, variant, case.resolution, scale, l0, int(sim.state.count),
               sim.stats.steps, wall - compile_s, compile_s, res.measured, res.reference,
               res.error, "ok", case.quantity, dict(res.extra))


def variant_names(cases: Iterable[Case]) -> List[str]:
    """Every settings variant the given cases run, in first-seen order (for --help)."""
    return list(dict.fromkeys(v for c in cases for v in c.variants))


def plan(case: Case, quick: bool, variants: bool, everywhere: Iterable[str] = ()) -> List[tuple]:
    """(scale, variant) pairs: every resolution in the base settings, and each variant at the
    middle resolution; a quick plan: the quick resolutions, and the case's one quick variant
    at the finest of them. The case's variants named in ``everywhere`` run at every
    resolution of the plan instead (validate --at-every-resolution)."""
    scales = case.quick if quick else case.scales
    out = [(s, "base") for s in scales]
    wanted = set(everywhere)
    wide = [v for v in case.variants if v in wanted]
    if variants:
        mid = scales[len(scales) // 2] if not quick else scales[-1]
        out += [(mid, v) for v in (case.quick_variants if quick else case.variants)
                if v not in wide]
    out += [(s, v) for v in wide for s in scales]
    return out


def run_suite(cases: Iterable[Case], quick: bool = False, variants: bool = True,
              on_row: Optional[Callable[[Row], None]] = None,
              everywhere: Iterable[str] = ()) -> List[Row]:
    """Every case's plan (``everywhere``: variants run at every resolution, ``plan``); the
    f64 runs last, after one switch of the backend's precision.
    Runs of the same compiled model share one simulator where the scene fits in it
    (cases.sharing): only the first of them, and a bigger scene, compile the kernels."""
    be = backend.current()
    jobs = [(c, s, v) for c in cases for s, v in plan(c, quick, variants, everywhere)]
    jobs.sort(key=lambda j: j[2] == "f64")
    rows: List[Row] = []
    kernels = Session()
    for case, scale, variant in jobs:
        if variant == "f64" and backend.current().precision != "f64":
            backend.init(be.arch, "f64", be.seed, be.single_thread,
                         fast_compile=be.fast_compile)
            kernels = Session()             # the restart dropped every compiled simulator
        with sharing(kernels):
            row = run_one(case, scale, variant)
        rows.append(row)
        if on_row:
            on_row(row)
    if backend.current().precision != be.precision:
        backend.init(be.arch, be.precision, be.seed, be.single_thread,
                     fast_compile=be.fast_compile)
    return rows
