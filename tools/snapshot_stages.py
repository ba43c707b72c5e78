"""The step's cost, stage by stage, at the states a recording passed through (BENCHMARKS.md,
"the cell grid of the splash"), reproducible:

    .venv/bin/python tools/snapshot_stages.py 3m-drop seed 0 8 16 [--cells-per-particle K]
        [--set KEY=VALUE ...]

Builds the preset's simulator, loads the snapshots of ``recordings/PRESET/`` at the frames
given (each as a fresh start: positions, velocities, kinds), takes one step (it re-sorts the
particles into cell order) and times the next ``--steps`` stage by stage. It prints, per frame,
seconds a step by stage, the cell side over l0, the cells in use and the mean neighbour count.
``--cells-per-particle`` sets the cell grid's limit (core/step.py, CELLS_PER_PARTICLE) for
this run only; ``--set`` overrides a preset value as in ``crowndemo run``."""
import argparse
import time

import numpy as np


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("preset")
    p.add_argument("quality")
    p.add_argument("frames", type=int, nargs="+")
    p.add_argument("--steps", type=int, default=4)
    p.add_argument("--cells-per-particle", type=int, default=None)
    p.add_argument("--recordings", default="recordings")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    a = p.parse_args()

    from crowndemo import backend, config
    from crowndemo.core import simulator_for
    backend.init(arch="cpu")
    import taichi as ti

    r = config.load(a.preset, a.quality, a.set)
    scene = r.build_scene()
    cells = None if a.cells_per_particle is None else a.cells_per_particle * len(scene.pos)
    sim = simulator_for(scene, max_cells=cells)
    for f in a.frames:
        d = np.load(f"{a.recordings}/{a.preset}/snapshots/frame_{f:05d}.npz")
        sim.load(d["pos"], d["vel"], d["kind"])
        sim.step()
        ti.sync()
        sim.time_stages()
        t = time.perf_counter()
        for _ in range(a.steps):
            sim.step()
        ti.sync()
        per = (time.perf_counter() - t) / a.steps
        g = sim.grid
        count = sim.pressure.neighbours.count.to_numpy()[: sim.state.count]
        stages = ", ".join(f"{k} {v / a.steps:.3f}" for k, v in sim.stage_seconds.items())
        print(f"frame {f} (t = {float(d['time']) * 1e3:.2f} ms): {per:.2f} s a step ({stages}); "
              f"cell side {g.side[None] / r.l0:.2f} l0, {g.num_cells[None]:,} cells, "
              f"{count.mean():.1f} neighbours a particle", flush=True)
        sim.time_stages(False)


if __name__ == "__main__":
    main()
