"""The regime map: crown or no crown over film thickness and impact speed, with Cossali et al.'s
splash threshold drawn on it (method.md §7). Each point is a preset with ``scene.film`` and
``scene.speed`` set; in one process one compiled simulator serves every point
(control.Session); ``dispatch`` runs the points on Dask workers instead."""
from __future__ import annotations

import math
import socket
import time
from dataclasses import asdict, dataclass, fields
from typing import Callable, Iterable, List, Optional, Sequence

from .. import backend, config
from ..control import Session
from ..machine import usable_cores
from .verdicts import run_and_measure, threshold_speed


@dataclass
class Point:
    film: float
    speed: float
    crown: Optional[bool]        # None when the run stopped before its end
    rim_height: float
    base_radius: float
    steps: int
    wall_s: float
    outcome: str
    host: str = ""               # the machine that ran it (a Dask worker's host)
    cores: int = 0               # its usable cores
    threads: Optional[int] = None    # Taichi's CPU threads (None: Taichi's default, all)
    arch: str = ""               # the Taichi arch it ran on

    def as_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict) -> "Point":
        """A point read back from JSON (null for the figures a stopped run lacks)."""
        kw = {f.name: d[f.name] for f in fields(cls) if f.name in d}
        for name in ("rim_height", "base_radius"):
            kw[name] = math.nan if kw.get(name) is None else kw[name]
        return cls(**kw)

    @property
    def key(self) -> tuple:
        return (float(self.film), float(self.speed))


def point_sets(sets: Sequence[str], film: Optional[float] = None,
               speed: Optional[float] = None) -> List[str]:
    """The --set overrides of a point: ``sets`` and scene.film / scene.speed."""
    return list(sets) + ([] if film is None else [f"scene.film={film!r}"]) + \
        ([] if speed is None else [f"scene.speed={speed!r}"])


def resolve(preset: str, films: Sequence[float], speeds: Sequence[float],
            quality: str = "draft", sets: Sequence[str] = ()) -> list:
    """Every (film, speed) point's preset, checked (PresetError on the first bad one)."""
    return [config.load(preset, quality, point_sets(sets, h, u)) for h in films for u in speeds]


def run(preset: str, films: Sequence[float], speeds: Sequence[float], quality: str = "draft",
        sets: Sequence[str] = (), on_point: Optional[Callable[[Point], None]] = None
        ) -> List[Point]:
    """Every (film, speed) pair; each is checked through the preset's validation first."""
    return run_resolved(resolve(preset, films, speeds, quality, sets), on_point)


def key_of(resolved) -> tuple:
    """The (film, speed) of a resolved point."""
    return (float(resolved.scene["film"]), float(resolved.speed))


def measure_point(resolved, session: Session) -> Point:
    """One point: built, run to its end (or until it goes unstable) through ``session``'s
    simulator, measured; with the machine and backend it ran on."""
    t0 = time.perf_counter()
    scene = resolved.build_scene()
    sim = session.load(scene)
    m, outcome = run_and_measure(sim, resolved, scene.info)
    be = backend.current()
    return Point(resolved.scene["film"], resolved.speed,
                 m.crown if outcome == "ran to the end" else None, m.rim_height,
                 m.base_radius, sim.stats.steps, time.perf_counter() - t0, outcome,
                 socket.gethostname(), usable_cores(), be.threads, be.resolved)


def run_resolved(resolved: Iterable, on_point: Optional[Callable[[Point], None]] = None
                 ) -> List[Point]:
    """Each resolved point in turn through one compiled simulator (this process)."""
    session = Session()
    points = []
    for r in resolved:
        p = measure_point(r, session)
        points.append(p)
        if on_point:
            on_point(p)
    return points


def plot(points: List[Point], drop: float, liquid: dict, path: str, title: str) -> Optional[str]:
    """The map as a PNG; None when written, else why not (matplotlib is an optional extra)."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return "matplotlib is not installed (pip install '.[plot]')"
    if not points:
        return "no point ran"
    fig, ax = plt.subplots(figsize=(7, 5))
    style = {True: ("o", "C3", "crown"), False: ("s", "C0", "no crown"),
             None: ("x", "grey", "stopped early")}
    for key, (m, col, lab) in style.items():
        sel = [p for p in points if p.crown is key]
        if sel:
            ax.plot([p.film * 1e3 for p in sel], [p.speed for p in sel], m, color=col,
                    markersize=9, label=lab, linestyle="none")
    hs = sorted({p.film for p in points})
    h_lo, h_hi = hs[0] * 0.8, hs[-1] * 1.2
    grid = [h_lo + (h_hi - h_lo) * k / 100 for k in range(101)]
    ax.plot([h * 1e3 for h in grid],
            [threshold_speed(drop, h, liquid["rho"], liquid["nu"], liquid["sigma"]) for h in grid],
            "k--", label="Cossali et al. 1997: K = 2100 + 5880 (h/D)^1.44")
    ax.set_xlabel("film thickness h (mm)")
    ax.set_ylabel("impact speed U (m/s)")
    ax.set_title(title, fontsize=9)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return None


def machine_of(p: Point) -> str:
    """Where a point ran: host, cores, Taichi threads and arch ('-' for an older record)."""
    if not p.host:
        return "-"
    threads = "all threads" if p.threads is None else \
        f"{p.threads} thread{'s' if p.threads != 1 else ''}"
    return f"{p.host}, {p.cores} cores, {threads}, {p.arch}"


def markdown(points: List[Point], drop: float, liquid: dict) -> str:
    out = ["| h (mm) | U (m/s) | simulated | rim height (mm) | base radius (mm) | Cossali "
           "threshold U (m/s) | steps | wall (s) | outcome | ran on |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    for p in points:
        u_th = threshold_speed(drop, p.film, liquid["rho"], liquid["nu"], liquid["sigma"])
        verdict = {True: "crown", False: "no crown", None: "-"}[p.crown]
        base = f"{p.base_radius * 1e3:.3g}" if math.isfinite(p.base_radius) else "-"
        out.append(f"| {p.film * 1e3:.3g} | {p.speed:.3g} | {verdict} | "
                   f"{p.rim_height * 1e3:.3g} | {base} | {u_th:.3g} | {p.steps:,} | "
                   f"{p.wall_s:.1f} | {p.outcome} | {machine_of(p)} |")
    return "\n".join(out)
