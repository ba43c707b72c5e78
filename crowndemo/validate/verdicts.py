"""The seed's four observations (method.md §6) reproduced from the presets: crown at 8 and
7 m/s on a 1 mm film, none at 2 m/s, none on a 10 mm layer at 5 m/s; each with its crown
metrics at the seed's observation times (its frames at 2, 3 and 4 ms, those up to the run's end
time, and the end time) and Cossali et al.'s splash number K against its threshold (§7). The
verdict is a crown when one stands at any of those times: a crown that has broken into jets
and droplets by 4 ms still stood at 2-3 ms."""
from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass
from typing import Callable, Iterable, List, Optional, Tuple

from .. import config
from ..core import FLUID, InstabilityError, Simulator, simulator_for
from .crown_metrics import CrownMetrics, film_edge, measure

# preset -> what the seed saw
SEED = {"3m-drop": True, "2.5m-drop": True, "20cm-drop": False, "thick-layer": False}
SEED_FRAMES = (2.0e-3, 3.0e-3, 4.0e-3)      # s, the seed's frames after the start


def observation_times(t_end: float) -> List[float]:
    """The seed's frames up to t_end, and t_end itself."""
    return sorted({t for t in SEED_FRAMES if t < t_end - 1e-12} | {t_end})


def splash_threshold(D: float, h: float) -> float:
    """Cossali et al.'s (1997) splash threshold 2100 + 5880 delta^1.44, delta = h/D (method.md
    §7)."""
    return 2100.0 + 5880.0 * (h / D) ** 1.44


def cossali(U: float, D: float, h: float, rho: float, nu: float, sigma: float) -> dict:
    """K = We Oh^-0.4 against ``splash_threshold`` (Cossali et al. 1997, method.md §7). With no
    surface tension or no viscosity K is infinite (We or Oh^-0.4 is)."""
    we = rho * U * U * D / sigma if sigma > 0 else math.inf
    oh = rho * nu / math.sqrt(rho * sigma * D) if sigma > 0 else math.inf
    k = we * oh ** -0.4 if nu > 0 and sigma > 0 else math.inf
    threshold = splash_threshold(D, h)
    return {"We": we, "Oh": oh, "K": k, "K_threshold": threshold, "splash": k > threshold}


def threshold_speed(D: float, h: float, rho: float, nu: float, sigma: float) -> float:
    """The impact speed at which K reaches Cossali's threshold for a film h (m/s)."""
    oh = rho * nu / math.sqrt(rho * sigma * D)
    return math.sqrt(splash_threshold(D, h) * oh ** 0.4 * sigma / (rho * D))


@dataclass
class Verdict:
    preset: str
    quality: str
    l0: float
    speed: float
    film: float
    drop: float
    t_end: float
    particles: int
    steps: int
    wall_s: float
    metrics: Optional[dict]
    crown: Optional[bool]
    seed_crown: Optional[bool]
    agrees: Optional[bool]
    cossali: dict
    outcome: str
    series: Optional[List[dict]] = None    # per observation time: time, crown, rim, base

    def as_dict(self) -> dict:
        return asdict(self)

    @property
    def crown_times(self) -> List[float]:
        return [o["time"] for o in self.series or [] if o["crown"]]


def film_limit(scene_info: Optional[dict], l0: float) -> Optional[float]:
    """How far from the axis the crown rule looks (its ``edge``), from the info of the scene the
    simulator was loaded with: inside a trimmed film's free edge, or inside the container's
    side walls (the largest disc on the square floor), whose liquid rises on its own: in the
    3m-drop booth run at 4 ms a bulge 0.65 mm high at r = 55 mm, in a corner, was taken for the
    crown's foot. None without scene info."""
    info = scene_info or {}
    if info.get("trimmed"):
        return film_edge(info.get("extent_m"), l0)
    if info.get("floor_m"):
        return film_edge(0.5 * info["floor_m"], l0)
    return None


def run_and_observe(sim: Simulator, resolved: config.Resolved, scene_info: Optional[dict] = None,
                    times: Optional[List[float]] = None) -> Tuple[List[CrownMetrics], str]:
    """Run to the preset's end time (or until it goes unstable), measuring the crown at each
    of ``times`` reached (default ``observation_times``), and at the last time when it
    stopped early. ``scene_info``: the scene's, for where the film ends (``film_limit``)."""
    s = resolved.scene
    seen: List[CrownMetrics] = []
    edge = film_limit(scene_info, resolved.l0)

    def observe(sim_, i):
        snap = sim_.snapshot()              # a half or quarter run: measured as the whole
        seen.append(measure(snap["pos"][snap["kind"] == FLUID], sim_.stats.time, s["film"],
                            s["drop"], resolved.l0, edge=edge, planes=sim_.model.mirror_planes))
    outcome = "ran to the end"
    try:
        sim.run(resolved.t_end, on_frame=observe,
                frame_times=observation_times(resolved.t_end) if times is None else times)
    except InstabilityError as e:
        outcome = f"stopped: {e.what} at t = {e.time * 1e3:.4g} ms"
        observe(sim, -1)
    return seen, outcome


def run_and_measure(sim: Simulator, resolved: config.Resolved,
                    scene_info: Optional[dict] = None) -> Tuple[CrownMetrics, str]:
    """``run_and_observe`` with one look, at the last time reached; returns those metrics and
    the outcome."""
    seen, outcome = run_and_observe(sim, resolved, scene_info, times=[resolved.t_end])
    return seen[-1], outcome


def run_preset(preset: str, quality: str = "draft", sets: Iterable[str] = ()) -> Verdict:
    r = config.load(preset, quality, list(sets))
    s, liq = r.scene, r.liquid
    t0 = time.perf_counter()
    scene = r.build_scene()
    sim = simulator_for(scene)
    seen, outcome = run_and_observe(sim, r, scene.info)
    crowned = [m for m in seen if m.crown]
    m = crowned[0] if crowned else seen[-1]      # the first crown, else the last look
    seed = SEED.get(r.name)
    series = [{"time": o.time, "crown": o.crown, "rim_height": o.rim_height,
               "base_radius": o.base_radius, "verdict": o.verdict} for o in seen]
    return Verdict(r.name, quality, r.l0, r.speed, s["film"], s["drop"], r.t_end,
                   int(len(scene.pos)), sim.stats.steps, time.perf_counter() - t0, m.as_dict(),
                   bool(crowned), seed, None if seed is None else (bool(crowned) == seed),
                   cossali(r.speed, s["drop"], s["film"], liq["rho"], liq["nu"], liq["sigma"]),
                   outcome, series)


def run_all(presets: Iterable[str] = tuple(SEED), quality: str = "draft",
            on_row: Optional[Callable[[Verdict], None]] = None) -> List[Verdict]:
    rows = []
    for p in presets:
        v = run_preset(p, quality)
        rows.append(v)
        if on_row:
            on_row(v)
    return rows


def markdown(rows: List[Verdict]) -> str:
    out = ["| preset | U (m/s) | h (mm) | D/l0 | looked at (ms) | crown at (ms) | t (ms) | "
           "base r (mm) | rim h (mm) | jets | droplets | verdict | the seed | "
           "Cossali K / threshold | wall (s) |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for v in rows:
        m = v.metrics or {}
        seed = {True: "crown", False: "no crown", None: "-"}[v.seed_crown]
        mine = "crown" if v.crown else "no crown"
        agree = "" if v.agrees is None else (" (agrees)" if v.agrees else " (DISAGREES)")
        c = v.cossali
        looked = ", ".join(f"{o['time'] * 1e3:.3g}" for o in v.series or []) or "-"
        crowned = ", ".join(f"{t * 1e3:.3g}" for t in v.crown_times) or "-"
        out.append(f"| {v.preset} | {v.speed:.3g} | {v.film * 1e3:.3g} | {v.drop / v.l0:.3g} | "
                   f"{looked} | {crowned} | {m.get('time', 0) * 1e3:.3g} | {m.get('base_radius', math.nan) * 1e3:.3g} | "
                   f"{m.get('rim_height', math.nan) * 1e3:.3g} | {m.get('jets', 0)} | "
                   f"{m.get('droplets', 0)} | {mine}{agree} | {seed} | "
                   f"{c['K']:.3g} / {c['K_threshold']:.3g} "
                   f"({'splash' if c['splash'] else 'no splash'}) | {v.wall_s:.0f} |")
    return "\n".join(out)
