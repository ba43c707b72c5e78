"""Sizes and rough costs of a resolved preset, without running a kernel: particle counts (the
scene built with numpy, or scaled from a coarser build when it would be large), steps to the
end time, memory, and a run-time estimate from the throughput recorded in BENCHMARKS.md.

Figures measured on crown runs correct the bench:

- after the drop touches the film, the splash sets dt. Its speeds scale with the impact speed U,
  not with the sound speed c: the sound-speed study (VALIDATION.md "Sound speed", the 3m-drop
  at c = 5, 10 and 20 U, 2026-12-01) measured a mean dt after contact of 0.125 l0/U in 2D and
  0.131 l0/U in 3D at D/l0 = 30 and c = 5 U, bound by the approach limit 0.5 l0/v at the
  splash's v = 4 U and the Courant limit 0.2 l0/v_rel at a relative speed of 1.5 U (walls at
  rest; the booth runs of 2026-11-22 at c = 5 U: 0.26-0.35 c = 1.3-1.75 U), and 0.081 l0/U at
  D/l0 = 100 (2D, c = 10 and 20 U: the approach limit at 6.2 U). The splash speed grows with
  the resolution as (D/l0)^0.36 through those two points (issue 21: 4-5 U at D/l0 = 100 and
  more as the spacing refines);
- where the acoustic limit l0/c binds (c >= 10 U) the mean dt after contact is 0.88-0.95 of
  it (a few steps bound by a faster splash or the relative Courant limit): STEP_MIX;
- a crown step's cost per fluid particle, against the bench's per fluid particle (the tank
  block's rate, BENCHMARKS.md), differs before and after contact: CALM_COST while the drop
  falls onto a film at rest, SPLASH_COST after it, growing with the resolution as the splash
  disorders the lattice and crowds the crown (the neighbour walks cost more at the same cell
  side, BENCHMARKS.md "the cell grid of the splash"). A wall or dummy particle costs WALL_COST
  of a fluid one (walls take part in the density walk, dummies only as neighbours). Measured
  on the 2-core machine on 2026-12-02, each against the bench's rate measured next to it
  (BENCHMARKS.md, "info's crown costs"; this host's speed moved by a third within that hour):
  the seed rung of 3m-drop (1,227,236 fluid particles, a quarter on the plane floor) at 1.11 s
  a step before contact and 1.74-1.80 s at 2 and 4 ms (`tools/snapshot_stages.py`) against
  1.15-1.22e6 fluid particle-steps/s: 1.07 and 1.70; the booth 3m-drop (289,405 fluid) on its
  particle floor (353,628 wall and dummy particles), 1,132 steps in 351.8 s, and on the plane
  floor (72,720 in the side walls), 1,112 steps in 281.6 s (`crowndemo bench --preset 3m-drop
  [--set numerics.wall_model=plane]`), against 1.12-1.15e6 just after them: solved for 0.25 a
  wall or dummy particle and 0.93 after contact at D/l0 = 33, so the splash's cost grows as
  (D/l0)^0.55. tests/test_estimate.py checks the run time of two other runs of that hour.

``steps_to_end`` gives both the floor (dt at v = U all along) and the expected count.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Dict, Optional

from ..core import timestep
from .resolve import Resolved

EXACT_UP_TO = 1.5e6          # total particles: build the scene itself up to this many
SCALE_FROM = 5.0e5           # otherwise build about this many and scale
BUILD_AT_MOST = 3.0e6        # a coarse build that must resolve a thin film may hold this many;
                             # past it the counts come from the sizes alone (rough_counts)
# used when BENCHMARKS.md cannot be read (the 2026-11-22 CPU figures: AMD EPYC, 2 cores)
FALLBACK_RATE = 8.0e5        # fluid particle-steps/s, 3D, f32
FALLBACK_COMPILE_S = 5.0
FALLBACK_BYTES = 92.0        # per particle (fields + cell grid), f32
SPLASH_SPEED_U = 4.0         # the splash's speed / U after contact at D/l0 = SPLASH_AT_D_L0
SPLASH_AT_D_L0 = 30.0
SPLASH_GROWTH = 0.36         # ... times (D/l0 / SPLASH_AT_D_L0)^this (6.2 U at D/l0 = 100)
RELATIVE_SPEED_U = 1.5       # largest relative speed / U after contact (measured, see above)
STEP_MIX = 0.9               # mean dt after contact / the smallest limit (measured, see above)
CALM_COST = 1.07             # a fluid particle-step before contact / the bench's (measured)
SPLASH_COST = 1.70           # ... after contact at D/l0 = SPLASH_COST_AT (measured)
SPLASH_COST_AT = 100.0
SPLASH_COST_GROWTH = 0.55    # ... times (D/l0 / SPLASH_COST_AT)^this (0.93 at D/l0 = 33)
WALL_COST = 0.25             # a wall or dummy particle-step / a fluid one (measured)
# A crown step's cost with each surface-tension model / the seed's potential's: the booth
# 3m-drop timed whole, one run after the other, nothing else running (BENCHMARKS.md "The
# surface-tension models' cost", 2026-12-05): 0.1365 s a step with the potential (0.1353 with
# the sum form: the form costs nothing), 0.1714 with the curvature model; with the stress
# member and the sum form 0.3724 before its curvature correction C5 and 0.4212 with it (its
# two passes, the pair pass walking to 3 l0 and summing C5's curvature, method.md §4c;
# BENCHMARKS.md "The stress model's cost with C5", against 0.1353 the same hour).
SURFACE_TENSION_COST = {"potential": 1.0, "stress": 3.11, "curvature": 1.26}
# A preset's first step compiles the crown step's kernels. With Taichi's offline cache empty
# (`crowndemo run quick-2d|quick --max-steps 1`, TI_OFFLINE_CACHE_FILE_PATH an empty folder,
# 2026-11-23, this CPU): 4.9 s in 2D, 51.5 s in 3D (about 5 s with --fast-compile, BENCHMARKS.md
# "The walk's rows in a loop"; the stress member's 92 s without it). A run whose kernels are
# cached starts in 3-9 s: the estimates are a first run's.
FIRST_RUN_COMPILE_S = {2: 5.0, 3: 50.0}


@dataclass(frozen=True)
class Throughput:
    rate: float              # fluid particle-steps/s of the bench's 3D tank
    total_per_fluid: float   # the bench scene's (fluid + wall + dummy) / fluid
    compile_s: float         # first-step compile time (an upper figure: the cache helps)
    bytes_per_particle: float
    source: str

    @property
    def rate_total(self) -> float:
        """Particle-steps/s counting every particle (wall and dummy particles cost work)."""
        return self.rate * self.total_per_fluid


def benchmarks_path() -> Path:
    import crowndemo
    return Path(crowndemo.__file__).resolve().parent.parent / "BENCHMARKS.md"


def throughput(path: Optional[Path] = None, rate: Optional[float] = None) -> Throughput:
    """The newest CPU f32 figure of BENCHMARKS.md (its largest N); ``rate`` overrides it."""
    found = _parse_benchmarks(path or benchmarks_path())
    if found is None:
        t = Throughput(FALLBACK_RATE, 1.3, FALLBACK_COMPILE_S, FALLBACK_BYTES,
                       "built-in figure (BENCHMARKS.md not found)")
    else:
        t = found
    if rate is not None:
        t = Throughput(rate, t.total_per_fluid, t.compile_s, t.bytes_per_particle,
                       f"--rate {rate:g}")
    return t


def _parse_benchmarks(path: Path) -> Optional[Throughput]:
    try:
        text = path.read_text(encoding="utf-8")
    except OSError:
        return None
    best = None
    for section in re.split(r"^## ", text, flags=re.M)[1:]:
        title = section.splitlines()[0].strip()
        machine = re.search(r"^- machine: (.+)$", section, re.M)
        rows = []
        for line in section.splitlines():
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if cells and cells[0] in ("seed", "tuned"):     # a `bench --compare` table
                if cells[0] != "tuned":
                    continue                  # the seed's formulation is not what runs
                cells = cells[1:]
            if len(cells) < 9 or not re.fullmatch(r"[\d,]+", cells[0]):
                continue
            try:
                fluid, total = int(cells[0].replace(",", "")), int(cells[1].replace(",", ""))
                rate, compile_s, bpp = float(cells[4]), float(cells[5]), float(cells[6])
            except ValueError:
                continue
            if cells[7].startswith("cpu") and cells[8] == "f32":
                rows.append((fluid, total, rate, compile_s, bpp))
        if rows:
            fluid, total, rate, compile_s, bpp = max(rows)
            where = f"BENCHMARKS.md {title}"
            if machine:
                where += f", {machine.group(1).strip()}"
            best = Throughput(rate, total / fluid, compile_s, bpp,
                              f"{where}, N = {fluid:,}")
    return best


def particle_counts(r: Resolved, exact_up_to: float = EXACT_UP_TO,
                    scale_from: float = SCALE_FROM) -> Dict:
    """Particles by kind: exact from the scene built at l0 when that is at most
    ``exact_up_to`` particles, else scaled from the scene built at a coarser spacing with
    about ``scale_from`` particles (fluid by film layers and drop volume, walls by area)."""
    rough = rough_total(r)
    if rough <= exact_up_to:
        sc = r.build_scene()
        c = sc.counts()
        return {**c, "n_film": sc.info["n_film"], "n_drop": sc.info["n_drop"], "exact": True,
                "built_l0": r.l0, "left_out": list(sc.info.get("left_out", [])),
                "trimmed": sc.info.get("trimmed"), "walls": sc.info.get("walls"),
                "extent_m": sc.info.get("extent_m")}
    d, h, D = r.dim, r.scene["film"], r.scene["drop"]
    l0c = r.l0 * (rough / scale_from) ** (1.0 / d)
    l0c = min(l0c, min(h, D) / 3.0)           # the builder needs 3 particles across each
    if rough * (r.l0 / l0c) ** d > BUILD_AT_MOST:     # a thin film under a wide drop
        return rough_counts(r)
    sc = r.build_scene(l0=l0c)
    c = sc.counts()
    k = l0c / r.l0
    layers = math.floor(h / r.l0 + 1e-9) / max(math.floor(h / l0c + 1e-9), 1)
    n_film = sc.info["n_film"] * k ** (d - 1) * layers
    n_drop = (math.pi / 6 * D ** 3 if d == 3 else math.pi / 4 * D ** 2) / r.l0 ** d
    n_drop *= sc.info.get("simulated_fraction", 1.0)     # of a half or quarter run
    fluid = int(round(n_film + n_drop))
    area = k ** (d - 1)            # walls go with the floor area over l0^(d-1) ...
    if sc.info.get("trimmed"):     # ... of a disc (a strip in 2D) with a rim of layers x l0
        e, layers_w = sc.info["extent_m"], math.ceil(r.scene["re_ratio"] - 1e-9)
        area *= ((e + layers_w * r.l0) / (e + layers_w * l0c)) ** (d - 1)
    wall = int(round(c["wall"] * area))
    dummy = int(round(c["dummy"] * area))
    return {"fluid": fluid, "wall": wall, "dummy": dummy, "total": fluid + wall + dummy,
            "n_film": int(round(n_film)), "n_drop": int(round(n_drop)), "exact": False,
            "built_l0": l0c, "left_out": list(sc.info.get("left_out", [])),
            "trimmed": sc.info.get("trimmed"), "walls": sc.info.get("walls"),
            "extent_m": sc.info.get("extent_m")}


def _rough_parts(r: Resolved) -> Dict:
    """Film, drop and wall-layer particles from the scene's sizes alone (volumes and floor
    area over l0^d), with the film's extent and whether it is trimmed."""
    from ..core.symmetry import fraction
    from ..scenes.crown import film_extent
    s, d, l0 = r.scene, r.dim, r.l0
    e, trimmed = film_extent(s["floor"], s["trim"], s["t_end"], s["speed"], s["drop"],
                             s["film"], s["gap"], s["trim_reach"])
    part = fraction(r.numerics.mirror_planes)     # a half or quarter run (core/symmetry.py)
    area = part * ((math.pi * e * e) if d == 3 else 2 * e)   # floor area (length in 2D)
    drop = part * (math.pi / 6 * s["drop"] ** 3 if d == 3 else math.pi / 4 * s["drop"] ** 2)
    layers = math.ceil(s["re_ratio"])
    return {"film": area * s["film"] / l0 ** d, "drop": drop / l0 ** d,
            "walls": area / l0 ** (d - 1) * layers * (1.0 if trimmed else 1.5),
            "layers": layers, "trimmed": trimmed, "extent_m": e}


def rough_total(r: Resolved) -> float:
    """Particles of the scene from its sizes alone (fluid volume and floor area over l0^d)."""
    parts = _rough_parts(r)
    return parts["film"] + parts["drop"] + parts["walls"]


def rough_counts(r: Resolved) -> Dict:
    """``particle_counts`` from the sizes alone, for a scene too large to build even at a
    spacing that still resolves its film: the first wall layer is WALL, the rest DUMMY."""
    parts = _rough_parts(r)
    wall = int(round(parts["walls"] / parts["layers"]))
    dummy = int(round(parts["walls"])) - wall
    fluid = int(round(parts["film"] + parts["drop"]))
    return {"fluid": fluid, "wall": wall, "dummy": dummy, "total": fluid + wall + dummy,
            "n_film": int(round(parts["film"])), "n_drop": int(round(parts["drop"])),
            "exact": False, "built_l0": None,
            "left_out": ["not listed: the scene is too large to build, even coarsely"],
            "trimmed": parts["trimmed"],
            "walls": None, "extent_m": parts["extent_m"]}


def splash_speed(U: float, drop_over_l0: float) -> float:
    """The splash's speed after contact (m/s): SPLASH_SPEED_U U at D/l0 = SPLASH_AT_D_L0,
    growing as (D/l0)^SPLASH_GROWTH (measured, see the module's docstring)."""
    return U * SPLASH_SPEED_U * (max(drop_over_l0, 1.0) / SPLASH_AT_D_L0) ** SPLASH_GROWTH


def steps_to_end(r: Resolved) -> Dict:
    """Steps to t_end. ``steps_at_U``: dt = the smallest limit at v = U all along (a floor);
    ``steps``: that until the drop touches the film (gap / U), then dt at the splash's speed
    (``splash_speed``) and, with the relative Courant limit, a relative speed of
    RELATIVE_SPEED_U U (STEP_MIX x dt where the acoustic limit binds); every frame shortens
    one step."""
    lim = r.limits()
    dt, binding = r.dt()
    frames = len(r.frame_times())
    contact = min(r.scene["gap"] / r.speed, r.t_end)
    v_splash = max(r.speed, splash_speed(r.speed, r.scene["drop"] / r.l0))
    v_relative = None
    if r.numerics.courant_speed == "relative":
        v_relative = RELATIVE_SPEED_U * r.speed
    after = timestep.choose(r.physics, r.numerics, r.model, v_splash, v_relative)
    dt_after = after[0] * (STEP_MIX if after[1] == "acoustic" else 1.0)
    calm = math.ceil(contact / dt - 1e-9)
    steps = calm + math.ceil((r.t_end - contact) / dt_after - 1e-9)
    return {"dt_s": dt, "binding": binding, "limits_s": lim,
            "steps_at_U": int(math.ceil(r.t_end / dt - 1e-9)) + frames,
            "splash_speed_m_s": v_splash, "relative_speed_m_s": v_relative,
            "dt_after_contact_s": dt_after,
            "binding_after_contact": after[1], "steps": int(steps) + frames,
            "steps_before_contact": int(calm)}


def crown_cost(drop_over_l0: float, splashing: bool,
               surface_tension: str = "potential") -> float:
    """A crown step's cost per fluid particle / the bench's: CALM_COST before contact,
    SPLASH_COST x (D/l0 / SPLASH_COST_AT)^SPLASH_COST_GROWTH after it (module docstring),
    times the surface-tension model's SURFACE_TENSION_COST."""
    model = SURFACE_TENSION_COST[surface_tension]
    if not splashing:
        return CALM_COST * model
    return model * SPLASH_COST * (max(drop_over_l0, 1.0) / SPLASH_COST_AT) ** SPLASH_COST_GROWTH


def run_seconds(counts: Dict, calm_steps: int, splash_steps: int, tp: Throughput, dim: int,
                drop_over_l0: float, surface_tension: str = "potential") -> float:
    """A first run's compile (FIRST_RUN_COMPILE_S) + the steps before and after contact, each
    costing (fluid + WALL_COST x (wall + dummy)) particles at the bench's rate per fluid
    particle times ``crown_cost`` of its phase and surface-tension model. 2D steps are taken
    to cost the 3D rate per particle (an upper figure: a 2D particle has fewer neighbours)."""
    weighted = counts["fluid"] + WALL_COST * (counts.get("wall", 0) + counts.get("dummy", 0))
    work = (calm_steps * crown_cost(drop_over_l0, False, surface_tension)
            + splash_steps * crown_cost(drop_over_l0, True, surface_tension))
    return FIRST_RUN_COMPILE_S[dim] + weighted * work / tp.rate


def memory_bytes(total: int, tp: Throughput) -> float:
    return total * tp.bytes_per_particle


def summary(r: Resolved, tp: Throughput, exact_up_to: float = EXACT_UP_TO) -> Dict:
    """Counts, steps, run time and memory of one preset at one quality."""
    counts = particle_counts(r, exact_up_to)
    st = steps_to_end(r)
    d_l0 = r.scene["drop"] / r.l0
    # the member compiled in (sigma > 0); with none the potential's figures stand
    tension = r.model.surface_tension_model if r.model.surface_tension else "potential"
    calm = st["steps_before_contact"]
    secs = run_seconds(counts, calm, st["steps"] - calm, tp, r.dim, d_l0, tension)
    cost_calm, cost_splash = crown_cost(d_l0, False, tension), crown_cost(d_l0, True, tension)
    # a floor: the fewest steps, each in the phase that costs less
    fewest = st["steps_at_U"]
    floor_steps = (fewest, 0) if cost_calm <= cost_splash else (0, fewest)
    return {"particles": counts, **st, "run_seconds": secs, "compile_seconds":
            FIRST_RUN_COMPILE_S[r.dim],
            "run_seconds_at_U": run_seconds(counts, *floor_steps, tp, r.dim, d_l0, tension),
            "crown_cost_calm": cost_calm, "crown_cost_splash": cost_splash,
            "surface_tension_cost": SURFACE_TENSION_COST[tension],
            "memory_bytes": memory_bytes(counts["total"], tp)}


def human_seconds(s: float) -> str:
    if s < 90:
        return f"{s:.0f} s"
    if s < 90 * 60:
        return f"{s / 60:.1f} min"
    if s < 48 * 3600:
        return f"{s / 3600:.1f} h"
    return f"{s / 86400:.1f} d"


def human_count(n: float) -> str:
    if n >= 1e6:
        return f"{n / 1e6:.1f}M"
    if n >= 1e4:
        return f"{n / 1e3:.0f}k"
    return f"{n:,.0f}"


def human_bytes(b: float) -> str:
    for unit, size in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if b >= size:
            return f"{b / size:.3g} {unit}"
    return f"{b:.0f} B"


__all__ = ["Throughput", "throughput", "particle_counts", "steps_to_end", "splash_speed",
           "crown_cost", "run_seconds",
           "memory_bytes", "summary", "human_seconds", "human_count", "human_bytes"]
