"""The symmetry-plane and trim measurements of docs/symmetry.md, reproducible:

    .venv/bin/python tools/symmetry_study.py tank|dam|crown2d|quarter|twins|trim

Each prints the figures that docs/symmetry.md quotes: a part of a symmetric scene against the
whole (core/symmetry.py), and the film's speed profile of an untrimmed 2D crown (the trim)."""
import sys
import time

import numpy as np

from crowndemo import backend, config
from crowndemo.core import FLUID, simulator_for
from crowndemo.core.symmetry import mirror_whole
from crowndemo.scenes import dam_break, hydrostatic_tank
from crowndemo.scenes.crown import crown, crown_base_radius
from crowndemo.scenes.symmetric import halve
from crowndemo.validate.cases import dam_break_fronts
from crowndemo.validate.crown_metrics import measure


def tank() -> None:
    W, H, l0 = 0.04, 0.04, 1e-3
    whole = hydrostatic_tank(dim=2, l0=l0, width=W, depth=H, nu=1e-3)
    for name, sc, dx in (("whole", whole, 0.0), ("half", halve(whole, (0,), (W / 2, 0)), W / 2)):
        sim, fits = simulator_for(sc), []

        def frame(s, i):
            s.refresh_pressure()
            snap = s.snapshot()
            p, kind = snap["pos"] + np.array([dx, 0]), snap["kind"]
            inner = (kind == FLUID) & (p[:, 0] > 3 * l0) & (p[:, 0] < W - 3 * l0)
            inner &= (p[:, 1] > 3 * l0) & (p[:, 1] < H - 4 * l0)
            fits.append(np.polyfit(p[inner, 1], snap["pressure"][inner], 1)[1])
        sim.run(0.3, frame_times=np.linspace(0.15, 0.3, 7), on_frame=frame)
        print(f"{name}: {len(sc.pos)} particles, floor pressure {np.mean(fits):.2f} Pa "
              f"(rho g H = {998 * 9.81 * H:.2f}), {sim.stats.steps} steps")


def dam() -> None:
    a, l0 = 0.03, 2.5e-3
    whole = dam_break(dim=3, a=a, l0=l0, channel=0.5)
    for name, sc in (("whole", whole), ("half", halve(whole, (1,), (0, 0.25 * a, 0)))):
        T, z = dam_break_fronts(simulator_for(sc), a, 3.0, every=0.5)
        print(f"{name}: {len(sc.pos)} particles, Z(T = 0, 0.5 .. 3) = {np.round(z, 4)}")


def crown2d() -> None:
    l0, t_end = 1e-4, 1e-3
    for sym in ("full", "half"):
        sc = crown(dim=2, l0=l0, t_end=t_end, symmetry=sym, sound_speed=80.0)
        sim = simulator_for(sc)
        sim.run(t_end)
        snap = sim.whole_snapshot()
        m = measure(snap["pos"][snap["kind"] == FLUID], t_end, 1e-3, 1e-2, l0)
        print(f"{sym}: {sc.counts()['fluid']} fluid, base {m.base_radius * 1e3:.2f} mm, rim "
              f"{m.rim_height * 1e3:.2f} mm, {sim.stats.steps} steps")


def quarter(preset: str = "3m-drop") -> None:
    """Two whole and two quarter runs at draft to t_end, the second of each with its steps cut
    by a frame stop at 0.35 ms (tests/test_symmetry.py's ensemble)."""
    seen = {"quarter": [], "full": []}
    for stops in ((), (3.5e-4,)):
        for sym in ("quarter", "full"):
            r = config.load(preset, "draft", [f"scene.symmetry={sym}"])
            sim = simulator_for(r.build_scene())
            sim.run(r.t_end, frame_times=stops)
            snap = sim.snapshot()
            pos = snap["pos"][snap["kind"] == FLUID]
            parts = [pos] if sym == "quarter" else [
                pos[(sx * pos[:, 0] > 0) & (sy * pos[:, 1] > 0)] * np.array([sx, sy, 1])
                for sx in (1, -1) for sy in (1, -1)]
            for q in parts:
                m = measure(mirror_whole({"pos": q}, (0, 1))["pos"], r.t_end, r.scene["film"],
                            r.scene["drop"], r.l0)
                seen[sym].append((m.base_radius * 1e3, m.rim_height * 1e3, len(q)))
                print(f"{sym} (stops {stops}): base {m.base_radius * 1e3:.2f} mm, rim "
                      f"{m.rim_height * 1e3:.2f} mm, {len(q)} fluid particles "
                      f"({sim.stats.steps} steps)", flush=True)
    quads, quarter = np.array(seen["full"]), np.array(seen["quarter"]).mean(axis=0)
    mean = quads.mean(axis=0)
    print("quadrants' mean", np.round(mean, 3), "largest deviation",
          np.round(np.abs(quads - mean).max(axis=0), 3), "; quarters' mean", np.round(quarter, 3),
          "deviation", np.round(np.abs(quarter - mean), 3))


def twins() -> None:
    """The drift of the splash: the quarter against the whole's quadrant +x +y, particle for
    particle (matched by their start on the lattice), beside the whole's own mirror twins
    (its quadrant +x +y against the other three mirrored), in l0, at frame times."""
    times = [5e-5, 1e-4, 2e-4, 4e-4, 7e-4, 1e-3, 1.5e-3, 2e-3]
    runs = {}
    for sym in ("quarter", "full"):
        r = config.load("3m-drop", "draft", [f"scene.symmetry={sym}"])
        sim = simulator_for(r.build_scene())
        s0 = sim.snapshot()
        keys = map(tuple, np.rint(s0["pos"] / r.l0 * 2).astype(int))   # on the half-l0 grid
        start = dict(zip(s0["id"].tolist(), keys))
        frames = runs[sym] = []

        def keep(s, i):
            snap = s.snapshot()
            f = snap["kind"] == FLUID
            frames.append(dict(zip((start[k] for k in snap["id"][f].tolist()), snap["pos"][f])))
        sim.run(times[-1], times, keep)
    for t, q, w in zip(times, runs["quarter"], runs["full"]):
        to_quarter, twin = [], []
        for k, p in q.items():
            to_quarter.append(np.linalg.norm(p - w[k]))
            for sx, sy in ((-1, 1), (1, -1), (-1, -1)):
                mirrored = w.get((sx * k[0], sy * k[1], k[2]))
                if mirrored is not None:
                    twin.append(np.linalg.norm(w[k] - mirrored * np.array([sx, sy, 1.0])))
        pct = lambda a: " ".join(f"{v:.1e}" for v in np.percentile(np.array(a) / r.l0,
                                                                    (50, 90, 99, 100)))
        print(f"t = {t * 1e3:.2f} ms; [l0] 50/90/99/100th percentiles: quarter against the "
              f"whole {pct(to_quarter)}; whole's twins {pct(twin)}")


def trim() -> None:
    l0, t_end, U = 1e-4, 4e-3, 8.0
    sc = crown(dim=2, l0=l0, t_end=t_end, trim=False, symmetry="half", sound_speed=10 * U)
    sim = simulator_for(sc)

    def frame(s, i):
        snap = s.whole_snapshot()
        f = snap["kind"] == FLUID
        p, u = snap["pos"][f], snap["vel"][f]
        r, speed = np.abs(p[:, 0]), np.linalg.norm(u, axis=1)
        film = p[:, -1] < 1.2e-3
        edges = np.arange(0, 0.045, 0.0025)
        prof = [np.percentile(speed[film & (r >= e) & (r < e + 0.0025)], 99) for e in edges]
        rc = crown_base_radius(s.stats.time - 1e-3 / U, U, 1e-2, 1e-3)
        print(f"t = {s.stats.time * 1e3:.0f} ms, R_c = {rc * 1e3:.1f} mm; 99th percentile film "
              "speed per 2.5 mm of r [m/s]: " + " ".join(f"{v:.2f}" for v in prof))
    sim.run(t_end, frame_times=[1e-3, 2e-3, 3e-3, 4e-3], on_frame=frame)


if __name__ == "__main__":
    backend.init("cpu")
    t0 = time.perf_counter()
    {"tank": tank, "dam": dam, "crown2d": crown2d, "quarter": quarter, "twins": twins,
     "trim": trim}[sys.argv[1]](*sys.argv[2:])
    print(f"({time.perf_counter() - t0:.0f} s)")
