"""The sound-speed study of issue 21: one crown preset run to its draft end time at several
sound speeds c = k U and spacings l0, in 2D and 3D, measuring at each point the crown (base
radius, rim height, sheet coherence: crown_metrics), the density excess (local and bulk:
density.py), the energy lost, the fastest particle against c, the steps and the wall time.

    python -m crowndemo.validate.sound_speed run --dim 2 --l0 1e-4 --factor 10 \\
        --out reports/sound_speed.jsonl       # one point, appended as a JSON line
    python -m crowndemo.validate.sound_speed study --out reports/sound_speed.jsonl
                                              # every point of GRID not yet in the file,
                                              # one at a time (each in its own process)
    python -m crowndemo.validate.sound_speed table reports/sound_speed.jsonl

A point is a run of the preset with ``--set dim=.. --set quality.draft.l0=..
--set scene.sound_speed=k U``. A run that goes unstable is a data point (where and why it
stopped), not an error. Wall times depend on what else the machine runs; the steps and the
particle-steps (every particle, walls included, times the steps) do not.
"""
from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import textwrap
import time
from pathlib import Path
from typing import Dict, Iterable, List, Optional, Sequence

import numpy as np

PRESET = "3m-drop"
QUALITY = "draft"
FACTORS = (5.0, 10.0, 20.0)
REFERENCE_FACTOR = 20.0           # the errors are against the run at this c / U
GRID = [(2, 3.3e-4), (2, 1.0e-4), (3, 3.3e-4)]   # (dim, l0): D/l0 = 30.3, 100, 30.3
# single points after the grid (dim, l0, c/U): between the seed's 5 and 10 where 5 fails, and
# the default at D/l0 = 111, the seed's resolution (issue 21: D/l0 from 30 to at least 110)
CHECKS = [(2, 1.0e-4, 7.0), (2, 9.0e-5, 10.0)]
FRAME_EVERY = 1.0e-4              # s between looks at the density excess and the crown
ERROR_FROM = 4.0e-4               # s: the crown errors are taken from here on (a wall stands)


def point_sets(dim: int, l0: float, factor: float, speed: float,
               extra: Sequence[str] = ()) -> List[str]:
    """The --set overrides of one point."""
    return [f"dim={dim}", f"quality.{QUALITY}.l0={l0:g}",
            f"scene.sound_speed={factor * speed:.6g}", *extra]


def run_point(dim: int, l0: float, factor: float, preset: str = PRESET,
              extra: Sequence[str] = ()) -> Dict:
    """Run one point of the study; returns its figures (JSON-ready)."""
    from .. import config
    from ..core import FLUID, InstabilityError, simulator_for
    from ..scenes.crown import crown_base_radius
    from .crown_metrics import measure
    from .density import density_excess
    from .verdicts import film_limit

    speed = config.load(preset, QUALITY).speed
    sets = point_sets(dim, l0, factor, speed, extra)
    r = config.load(preset, QUALITY, sets)
    s = r.scene
    t0 = time.perf_counter()
    scene = r.build_scene()
    sim = simulator_for(scene)
    setup_s = time.perf_counter() - t0
    edge = film_limit(scene.info, l0)
    t_contact = s["gap"] / r.speed
    frames = sorted({t_contact} | {k * FRAME_EVERY for k in range(1, int(
        r.t_end / FRAME_EVERY + 1e-9) + 1)})
    looks: List[Dict] = []
    at_contact: Dict = {}
    first: Dict = {}
    beta = r.numerics.free_surface_beta(dim)

    look_s = [0.0]

    def look(sim_, i=None) -> None:
        t_look = time.perf_counter()
        try:
            _look(sim_)
        finally:
            look_s[0] += time.perf_counter() - t_look

    def _look(sim_) -> None:
        if abs(sim_.stats.time - t_contact) < 1e-12 and not at_contact:
            at_contact.update(steps=sim_.stats.steps, time=sim_.stats.time)
        sim_.refresh_pressure()
        snap = sim_.snapshot()
        fluid = snap["kind"] == FLUID
        pos = snap["pos"][fluid]
        d = density_excess(pos, snap["number_density"][fluid], sim_.lattice.n0,
                           sim_.lattice.re, beta)
        m = measure(pos, sim_.stats.time, s["film"], s["drop"], l0, edge=edge,
                    planes=sim_.model.mirror_planes)
        looks.append({"time": sim_.stats.time, "density": d.as_dict(), "crown": m.as_dict()})

    def on_step(sim_) -> None:
        if not first:
            first["s"] = time.perf_counter() - t_run

    outcome, stopped_at = "ran to the end", None
    t_run = time.perf_counter()
    try:
        sim.run(r.t_end, frame_times=frames, on_frame=look, on_step=on_step)
    except InstabilityError as e:
        outcome, stopped_at = f"stopped: {e.what}", e.time
        look(sim)
    wall = time.perf_counter() - t_run - look_s[0]      # stepping only: the looks apart
    st, h = sim.stats, sim.stats.health
    last = looks[-1]
    cm = last["crown"]
    t_after = last["time"] - t_contact
    yw = crown_base_radius(t_after, r.speed, s["drop"], s["film"]) if t_after > 0 else math.nan
    total = int(len(scene.pos))
    steps_after = st.steps - at_contact.get("steps", st.steps)
    return {
        "preset": preset, "dim": dim, "l0": l0, "D_l0": s["drop"] / l0, "factor": factor,
        "U": r.speed, "c": r.physics.c, "t_end": r.t_end, "outcome": outcome,
        "drop": s["drop"], "film": s["film"], "t_contact": t_contact,
        "stopped_at": stopped_at, "t_reached": st.time,
        "particles": total, "fluid": int(scene.counts()["fluid"]), "steps": st.steps,
        "steps_to_contact": at_contact.get("steps"), "steps_after_contact": steps_after,
        "dt_after_contact": (t_after / steps_after if steps_after > 0 and t_after > 0
                             else None),
        "particle_steps": total * st.steps, "binding": dict(st.binding),
        "wall_s": wall, "first_step_s": first.get("s"), "setup_s": setup_s,
        "look_s": look_s[0],
        "base_radius": cm["base_radius"], "rim_height": cm["rim_height"],
        "sheet_coherence": cm["sheet_coherence"], "crown": cm["crown"],
        "yarin_weiss": yw,
        "peak_local_excess": st.peak_max_density_excess,
        "peak_bulk_excess": max((lk["density"]["bulk"] for lk in looks
                                 if math.isfinite(lk["density"]["bulk"])), default=None),
        "peak_frame_local_excess": max(lk["density"]["local"] for lk in looks),
        "peak_speed": st.peak_max_speed, "peak_mach": st.peak_max_speed / r.physics.c,
        "energy_start": st.energy_start, "energy_end": h.energy,
        "energy_loss": (1.0 - h.energy / st.energy_start) if st.energy_start else None,
        "looks": looks, "sets": sets,
    }


def read_points(path: Path) -> List[Dict]:
    if not path.is_file():
        return []
    return [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()
            if line.strip()]


def _key(dim: int, l0: float, factor: float) -> tuple:
    return (dim, round(l0, 12), round(factor, 6))


def study(out: Path, grid: Iterable = GRID, factors: Sequence[float] = FACTORS,
          checks: Iterable = CHECKS, extra: Sequence[str] = ()) -> None:
    """Every point of grid x factors, then of ``checks``, not yet in ``out``, one at a time,
    each in a process of its own (a fresh Taichi, the run's memory returned)."""
    points = [(dim, l0, k) for dim, l0 in grid for k in factors] + list(checks)
    for dim, l0, k in points:
        done = {_key(p["dim"], p["l0"], p["factor"]) for p in read_points(out)}
        if _key(dim, l0, k) in done:
            continue
        cmd = [sys.executable, "-m", "crowndemo.validate.sound_speed", "run", "--dim", str(dim),
               "--l0", repr(l0), "--factor", repr(k), "--out", str(out)]
        for e in extra:
            cmd += ["--set", e]
        print(" ".join(cmd), file=sys.stderr, flush=True)
        subprocess.run(cmd, check=True)


def _f(x: Optional[float], fmt: str, scale: float = 1.0) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    return format(x * scale, fmt)


def _series(p: Dict, key: str) -> Dict[float, float]:
    """One crown figure per look time (ms, rounded), from ERROR_FROM on, finite values only."""
    out = {}
    for lk in p["looks"]:
        v = lk["crown"].get(key)
        if lk["time"] >= ERROR_FROM - 1e-12 and v is not None and math.isfinite(v):
            out[round(lk["time"] * 1e3, 6)] = v
    return out


def error_against(p: Dict, ref: Dict, key: str) -> Optional[float]:
    """The median over the looks both runs made (from ERROR_FROM on) of |x / x_ref - 1|: a
    median, since one frame's figure can jump (a sheet of ejecta skimming the film is taken
    for the crown's foot for a frame or two)."""
    a, b = _series(p, key), _series(ref, key)
    both = [abs(a[t] / b[t] - 1.0) for t in a if t in b and b[t] != 0]
    return float(np.median(both)) if both else None


def yarin_weiss_ratio(p: Dict) -> Optional[float]:
    """The base radius over Yarin & Weiss's, mean over the looks with tau = (t - t_contact)
    U / D > 0.25 (as the crown-base cases of validate)."""
    from ..scenes.crown import crown_base_radius
    t_c = p["t_contact"]
    ratios = [lk["crown"]["base_radius"] / crown_base_radius(lk["time"] - t_c, p["U"],
                                                              p["drop"], p["film"])
              for lk in p["looks"] if (lk["time"] - t_c) * p["U"] / p["drop"] > 0.25
              and lk["crown"].get("base_radius") is not None
              and math.isfinite(lk["crown"]["base_radius"])]
    return float(np.mean(ratios)) if ratios else None


def _stepping_s(p: Dict) -> float:
    """Wall time of the steps after the first (which compiles the kernels), the looks apart."""
    return p["wall_s"] - (p.get("first_step_s") or 0.0)


def table(points: List[Dict]) -> str:
    """The study as a Markdown table; errors against the REFERENCE_FACTOR run of the same
    dim and l0 (``error_against``)."""
    ref = {(p["dim"], round(p["l0"], 12)): p for p in points
           if abs(p["factor"] - REFERENCE_FACTOR) < 1e-9 and p["outcome"] == "ran to the end"}
    out = ["| dim | D/l0 | c/U | outcome | t reached (ms) | base r, rim h at t (mm) | "
           "base / Yarin-Weiss | error base, rim vs 20 U | coherence at t | "
           "peak excess local / bulk | energy lost | peak v / c | steps | particle-steps | "
           "wall (s) |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for p in sorted(points, key=lambda p: (p["dim"], -p["l0"], p["factor"])):
        r = ref.get((p["dim"], round(p["l0"], 12)))
        err = "-"
        if r is not None and r is not p and p["outcome"] == "ran to the end":
            eb, eh = error_against(p, r, "base_radius"), error_against(p, r, "rim_height")
            err = f"{_f(eb, '.1%')}, {_f(eh, '.1%')}"
        elif r is p:
            err = "(reference)"
        outcome = ("end" if p["outcome"] == "ran to the end" else p["outcome"].replace("|", "/"))
        out.append(
            f"| {p['dim']} | {p['D_l0']:.0f} | {p['factor']:g} | {outcome} | "
            f"{p['t_reached'] * 1e3:.3g} | {_f(p['base_radius'], '.1f', 1e3)}, "
            f"{_f(p['rim_height'], '.1f', 1e3)} | {_f(yarin_weiss_ratio(p), '.3f')} | "
            f"{err} | {_f(p['sheet_coherence'], '.3f')} | "
            f"{_f(p['peak_local_excess'], '.3f')} / {_f(p['peak_bulk_excess'], '.3f')} | "
            f"{_f(p['energy_loss'], '.1%')} | {_f(p['peak_mach'], '.2f')} | {p['steps']:,} | "
            f"{p['particle_steps']:.3g} | {_stepping_s(p):.0f}{'' if 'look_s' in p else '*'} |")
    if any("look_s" not in p for p in points):
        out += ["", "\\* the looks' measuring included (these points ran before the study "
                "timed them apart)."]
    return "\n".join(out)


SECTION = "## Sound speed"
COMMAND = "python -m crowndemo.validate.sound_speed study --out reports/sound_speed.jsonl"


def section(points: List[Dict], machine: str) -> str:
    """The VALIDATION.md section of the study: how it was made, then the table."""
    return "\n".join([
        SECTION, "", textwrap.fill(
        f"Written by `python -m crowndemo.validate.sound_speed table FILE --record` from the "
        f"points of `{COMMAND}` ({PRESET}, its {QUALITY} rung's end time, "
        f"`--set dim=.. --set quality.{QUALITY}.l0=.. --set scene.sound_speed=k U`), one point "
        f"at a time; {machine}. Errors are against the c = {REFERENCE_FACTOR:g} U run at the "
        f"same dim and l0: the median over the looks from {ERROR_FROM * 1e3:g} ms on (every "
        f"{FRAME_EVERY * 1e3:g} ms) of |x / x_ref - 1|. The base radius against Yarin & Weiss is "
        "the mean over the looks with tau > 0.25 after contact. Coherence: the raised liquid in "
        "the one body linked at 1.6 l0 (crown_metrics). Excess: the peak n/n0 - 1 over every "
        "step (local, what the health check watches) and the peak over the looks of its 99th "
        "percentile over the fluid with no free-surface particle within re (bulk; density.py). "
        "Energy lost: 1 - E/E_start, kinetic + gravitational. Wall: the steps after the first "
        "(which compiles), the looks apart; other developers' jobs shared the 2 cores, so wall "
        "times are inflated by an unknown, varying factor: the steps and the particle-steps "
        "(every particle, walls included, x steps) are the cost that does not depend on the "
        "load.", width=95), "",
        table(points), ""])


def record_section(path: Path, points: List[Dict], machine: str) -> None:
    """Replace (or append) the study's section of the Markdown file ``path``: from its heading
    to the next heading of the same level."""
    text = path.read_text(encoding="utf-8") if path.is_file() else ""
    new = section(points, machine)
    lines = text.splitlines()
    try:
        start = lines.index(SECTION)
    except ValueError:
        body = text.rstrip("\n") + "\n\n" + new
    else:
        end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("## ")),
                   len(lines))
        body = "\n".join(lines[:start] + new.splitlines() + [""] + lines[end:])
    path.write_text(body.rstrip("\n") + "\n", encoding="utf-8")


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m crowndemo.validate.sound_speed",
                                 description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="what", required=True)
    one = sub.add_parser("run", help="run one point and append it to --out")
    one.add_argument("--dim", type=int, choices=(2, 3), required=True)
    one.add_argument("--l0", type=float, required=True)
    one.add_argument("--factor", type=float, required=True, help="c / U")
    one.add_argument("--preset", default=PRESET)
    one.add_argument("--out", type=Path, required=True)
    one.add_argument("--set", action="append", default=[], dest="sets")
    many = sub.add_parser("study", help="every point of the grid not yet in --out")
    many.add_argument("--out", type=Path, required=True)
    many.add_argument("--set", action="append", default=[], dest="sets")
    tab = sub.add_parser("table", help="the points of a file as a Markdown table")
    tab.add_argument("file", type=Path)
    tab.add_argument("--record", nargs="?", const=Path("VALIDATION.md"), type=Path,
                     metavar="MD", help="replace the study's section of MD (VALIDATION.md)")
    a = ap.parse_args(argv)
    if a.what == "table":
        points = read_points(a.file)
        if a.record:
            from ..machine import machine_line
            record_section(a.record, points, machine_line())
        else:
            print(table(points))
        return 0
    if a.what == "study":
        study(a.out, extra=a.sets)
        return 0
    from .. import backend
    backend.init()
    p = run_point(a.dim, a.l0, a.factor, a.preset, a.sets)
    from ..strictjson import finite_or_none
    a.out.parent.mkdir(parents=True, exist_ok=True)
    with open(a.out, "a", encoding="utf-8") as f:
        f.write(json.dumps(finite_or_none(p)) + "\n")
    print(table([p]), file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
