"""Taichi's offline cache (README, `run`): the kernels a run compiles are written when it
exits, and the next run with the same fields loads them instead of compiling them again.

Taichi writes its cache when its program is finished. Interpreter shutdown alone did not
always finish it (it depends on the order in which objects are collected: a simulator's
kernels were compiled afresh by every run); ``backend`` finishes it at exit. Two runs of a
small 2D simulator in fresh processes, with the cache in a folder of the test's own: the first
writes the step's kernels, the second compiles nothing (writes no new entry).
"""
import os
import subprocess
import sys

SCRIPT = """
import numpy as np
from crowndemo import backend
backend.init("cpu")
from crowndemo.core import FLUID, Numerics, Physics, Simulator
g = np.stack(np.meshgrid(np.arange(6), np.arange(6), indexing="ij"), -1).reshape(-1, 2) * 1e-3
phys = Physics(dim=2, l0=1e-3, v_max=1.0)
sim = Simulator(phys, Numerics(), len(g))
sim.configure(phys, Numerics(), ([-1.0] * 2, [1.0] * 2))
sim.load(g, np.zeros_like(g), np.full(len(g), FLUID, np.int32))
sim.step()
"""


def test_a_run_writes_its_kernels_and_the_next_loads_them(tmp_path):
    cache = tmp_path / "ticache"
    env = dict(os.environ, TI_OFFLINE_CACHE_FILE_PATH=str(cache))

    def run() -> set:
        done = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True,
                              text=True, timeout=600)
        assert done.returncode == 0, done.stderr[-2000:]
        return {p.name for p in cache.glob("*.tic")}

    first = run()
    assert len(first) >= 10, f"only {len(first)} kernels cached"   # the step has dozens
    assert run() == first            # nothing compiled again, so nothing new written
