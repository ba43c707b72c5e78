"""The stability suite: stiff and extreme drop-on-film cases (issue 5). Each either runs to its
end time with no non-finite value, a bounded density excess, energy that does not grow without
a source and every particle that left the domain counted, or stops with the named cause of the
core's health check; a user-fixed time step that breaks a limit is refused before the run.

Cases are 2D cross-sections of the ``quick`` drop (D = 4 mm on a 1.2 mm film, 8 m/s) at
D/l0 = 20 unless they say otherwise, so that the whole suite runs in minutes on 2 cores;
``full=True`` runs each to 1 ms instead of 0.4 ms, and adds 3D variants of the fast impact.
"""
from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field, replace
from typing import Callable, Dict, List, Optional

import numpy as np

from ..core import GONE, InstabilityError, ParameterError, simulator_for
from ..core.params import GRAVITY, WATER, Model
from ..control import Session
from ..scenes import Scene, crown

ENERGY_GROWTH = 0.02     # E_end > (1 + this) E_start with no source counts as growth
L0_2D = 2.0e-4           # D/l0 = 20 for the 4 mm drop


@dataclass
class StabilityCase:
    name: str
    kind: str                    # "stiff" or "extreme"
    what: str                    # one line
    build: Callable[[float], Scene]   # t_end -> scene
    energy_source: bool = False  # True when something feeds energy in (none of these yet)


@dataclass
class StabilityRow:
    case: str
    kind: str
    what: str
    particles: int
    steps: int
    t_end_s: float
    time_s: float
    wall_s: float
    dt_min_s: float
    dt_max_s: float
    binding: Dict[str, int]
    peak_density_excess: float
    peak_speed_m_s: float
    sound_speed_m_s: float
    energy_start_J: float
    energy_end_J: float
    left_domain: Dict[str, int]
    nonfinite: int
    outcome: str                 # "ran to the end", "stopped: ...", "refused: ..."
    passed: bool                 # one of the acceptable outcomes, and the checks hold
    checks: List[str] = field(default_factory=list)

    def as_dict(self) -> dict:
        return asdict(self)


def _kw(**over) -> dict:
    """The crown keywords of the suite's base: quick's drop as a 2D slice at D/l0 = 20."""
    kw = dict(dim=2, l0=L0_2D, film=1.2e-3, drop=4.0e-3, speed=8.0, gap=4.0e-4, floor=0.09,
              gravity=GRAVITY, **WATER)
    kw.update(over)
    return kw


def _two_drops(t_end: float) -> Scene:
    """Two drops side by side, 1.25 D apart (centre to centre), hitting the film together."""
    sc = crown(t_end=t_end, **_kw())
    n_film = sc.info["n_film"]
    n_drop = sc.info["n_drop"]
    drop = slice(n_film, n_film + n_drop)
    shift = np.zeros(sc.dim)
    shift[0] = 0.625 * sc.info["drop_m"]
    pos = np.concatenate([sc.pos[:n_film], sc.pos[drop] - shift, sc.pos[drop] + shift,
                          sc.pos[n_film + n_drop:]])
    vel = np.concatenate([sc.vel[:n_film], sc.vel[drop], sc.vel[drop], sc.vel[n_film + n_drop:]])
    kind = np.concatenate([sc.kind[:n_film], sc.kind[drop], sc.kind[drop],
                           sc.kind[n_film + n_drop:]])
    info = dict(sc.info, scene="two drops", n_drop=2 * n_drop)
    return replace(sc, pos=pos, vel=vel, kind=kind, info=info)


def _relative(sc: Scene) -> Scene:
    """The same scene with the Courant limit on relative speeds (the crown presets' setting,
    core/terms.py): fewer, larger steps once the splash flies."""
    sc.numerics = replace(sc.numerics, courant_speed="relative")
    return sc


def _thrown_out(t_end: float) -> Scene:
    """The domain's top cut 1 mm above the drop: the splash flies out and is counted."""
    sc = crown(t_end=t_end, **_kw(speed=15.0))
    lo, hi = sc.domain
    top = sc.info["film_m"] + sc.info["gap_m"] + sc.info["drop_m"] + 1.0e-3
    sc.numerics = replace(sc.numerics, max_out_fraction=1.0)   # count them all, do not abort
    return replace(sc, domain=(lo, tuple(hi[:-1]) + (top,)))


def _fixed_dt(t_end: float) -> Scene:
    """A user-fixed dt three times the acoustic limit: refused before the run."""
    sc = crown(t_end=t_end, **_kw())
    dt = 3.0 * sc.numerics.acoustic * sc.physics.l0 / sc.physics.c
    sc.numerics = replace(sc.numerics, fixed_dt=dt)
    return sc


def cases(full: bool = False) -> Dict[str, StabilityCase]:
    c = [
        StabilityCase("sound-speed-20x", "stiff", "c = 20 v_max instead of 5 (the acoustic "
                      "limit binds at a quarter of the seed's dt)",
                      lambda t: crown(t_end=t, sound_speed=20 * 8.0, **_kw())),
        StabilityCase("viscous-1e-3", "stiff", "kinematic viscosity 1e-3 m^2/s: the viscous "
                      "limit binds at D/l0 = 40", lambda t: crown(t_end=t, **_kw(nu=1.0e-3, l0=1.0e-4))),
        StabilityCase("sigma-x10", "stiff", "surface tension 10 x water's (0.728 N/m)",
                      lambda t: crown(t_end=t, **_kw(sigma=0.728))),
        StabilityCase("fine-drop", "stiff", "a fine resolution: D/l0 = 40",
                      lambda t: crown(t_end=t, **_kw(l0=1.0e-4))),
        StabilityCase("impact-15m-s", "extreme", "a 15 m/s impact",
                      lambda t: crown(t_end=t, **_kw(speed=15.0))),
        StabilityCase("touching", "extreme", "the drop touches the film at t = 0 (gap 0)",
                      lambda t: crown(t_end=t, **_kw(gap=0.0))),
        StabilityCase("dry-floor", "extreme", "no film: the drop hits the dry floor",
                      lambda t: crown(t_end=t, **_kw(film=0.0))),
        StabilityCase("deep-layer-3cm", "extreme", "a 3 cm deep layer",
                      lambda t: crown(t_end=t, **_kw(film=0.03))),
        StabilityCase("tiny-drop", "extreme", "a drop 4 particles across (D = 4 l0)",
                      lambda t: crown(t_end=t, **_kw(l0=1.0e-3, drop=4.0e-3, film=3.0e-3))),
        StabilityCase("two-drops", "extreme", "two drops side by side, 1.25 D apart",
                      _two_drops),
        StabilityCase("thrown-out", "extreme", "the domain's top 1 mm above the drop: a 15 m/s "
                      "splash leaves it and is counted", _thrown_out),
        StabilityCase("impact-15m-s-relative", "extreme", "a 15 m/s impact, the Courant "
                      "limit on relative speeds (the crown presets' setting)",
                      lambda t: _relative(crown(t_end=t, **_kw(speed=15.0)))),
        StabilityCase("touching-relative", "extreme", "the drop touching the film at t = 0, "
                      "the Courant limit on relative speeds",
                      lambda t: _relative(crown(t_end=t, **_kw(gap=0.0)))),
        StabilityCase("dry-floor-relative", "extreme", "the drop on the dry floor, the Courant "
                      "limit on relative speeds",
                      lambda t: _relative(crown(t_end=t, **_kw(film=0.0)))),
        StabilityCase("fixed-dt-3x", "extreme", "a user-fixed dt 3 x the acoustic limit: "
                      "refused before the run", _fixed_dt),
    ]
    if full:
        c.append(StabilityCase("impact-15m-s-3d", "extreme", "a 15 m/s impact in 3D (D/l0 = 10)",
                               lambda t: crown(t_end=t, **_kw(dim=3, l0=4.0e-4, speed=15.0))))
    return {x.name: x for x in c}


def run_case(case: StabilityCase, t_end: float,
             session: Optional[Session] = None) -> StabilityRow:
    """One case; its simulator from ``session`` when given (the compiled simulator of an
    earlier case of the same model, when the scene fits in it: see cases.sharing), else a
    new one."""
    t0 = time.perf_counter()
    scene = case.build(t_end)
    counts = scene.counts()
    try:
        sim = session.load(scene) if session is not None else simulator_for(scene)
    except ParameterError as e:
        return StabilityRow(case.name, case.kind, case.what, counts["total"], 0, t_end, 0.0,
                            time.perf_counter() - t0, math.nan, math.nan, {}, 0.0, 0.0,
                            scene.physics.c, math.nan, math.nan, {}, 0,
                            f"refused: {e}", "fixed_dt" == e.key, [])
    outcome = "ran to the end"
    try:
        sim.run(t_end)
    except InstabilityError as e:
        outcome = f"stopped: {e.what} at step {e.step}, t = {e.time * 1e3:.4g} ms (dt bound by {e.binding})"
    st, h = sim.stats, sim.stats.health
    checks = []
    if outcome == "ran to the end":
        if h.nonfinite:
            checks.append(f"{h.nonfinite} non-finite values")
        if st.peak_max_density_excess > scene.numerics.max_density_excess:
            checks.append(f"density excess {st.peak_max_density_excess:.3g} over the limit")
        if (not case.energy_source and st.energy_start is not None
                and h.energy > st.energy_start + ENERGY_GROWTH * abs(st.energy_start)):
            checks.append(f"energy grew {h.energy / st.energy_start - 1:+.1%} with no source")
        n_out = sum(h.left.values())
        n_gone = int((sim.snapshot()["kind"] == GONE).sum())
        if n_out != n_gone:
            checks.append(f"{n_gone} particles gone but {n_out} counted")
    return StabilityRow(case.name, case.kind, case.what, counts["total"], st.steps, t_end,
                        st.time, time.perf_counter() - t0, st.dt_min, st.dt_max,
                        dict(st.binding), st.peak_max_density_excess, st.peak_max_speed, scene.physics.c,
                        st.energy_start if st.energy_start is not None else math.nan, h.energy,
                        dict(h.left), int(h.nonfinite), outcome, not checks, checks)


def run_suite(names: Optional[List[str]] = None, full: bool = False,
              on_row: Optional[Callable[[StabilityRow], None]] = None) -> List[StabilityRow]:
    table = cases(full)
    t_end = 1.0e-3 if full else 4.0e-4
    rows = []
    names = names or list(table)
    # the cases of one model share its compiled simulator, sized first for the largest of
    # their scenes (the step's kernels compile at the first step, not here), so that no case
    # needs a bigger one compiled again
    session = Session()
    largest: Dict[Model, Scene] = {}
    for name in names:
        sc = table[name].build(t_end)
        if sc.numerics.fixed_dt is not None:      # refused before its run: never stepped
            continue
        model = Model.of(sc.physics, sc.numerics)
        if model not in largest or len(sc.pos) > len(largest[model].pos):
            largest[model] = sc
    for sc in largest.values():
        session.load(sc)
    for name in names:
        row = run_case(table[name], t_end, session)
        rows.append(row)
        if on_row:
            on_row(row)
    return rows


def markdown(rows: List[StabilityRow]) -> str:
    out = ["| case | kind | what | particles | steps | dt range (s) | binding limits | peak n/n0-1 "
           "| peak speed / c | energy end/start | left the domain | outcome |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        bind = ", ".join(f"{k} {v}" for k, v in sorted(r.binding.items(), key=lambda kv: -kv[1]))
        left = ", ".join(f"{v} {k}" for k, v in r.left_domain.items()) or "none"
        e = (f"{r.energy_end_J / r.energy_start_J:.3f}"
             if r.energy_start_J and math.isfinite(r.energy_start_J) else "-")
        dt = f"{r.dt_min_s:.2g} .. {r.dt_max_s:.2g}" if r.steps else "-"
        mach = f"{r.peak_speed_m_s / r.sound_speed_m_s:.2f}" if r.steps else "-"
        verdict = r.outcome + ("" if r.passed else " — FAILED: " + "; ".join(r.checks))
        out.append(f"| {r.case} | {r.kind} | {r.what} | {r.particles:,} | {r.steps:,} | {dt} | "
                   f"{bind or '-'} | {r.peak_density_excess:.3g} | {mach} | {e} | {left} | "
                   f"{verdict} |")
    return "\n".join(out)
