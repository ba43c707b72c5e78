"""Bit-reproducible CPU runs: one thread, fixed seed (backend.init(single_thread=True)).

Two fresh simulators of the same small 2D dam break, stepped the same number of times in one
process, must give identical positions and velocities to the last bit. The default backend
(multi-threaded, f32) is put back afterwards for the other test files.
"""
import numpy as np
import pytest

from crowndemo import backend
from crowndemo.core import simulator_for
from crowndemo.scenes import dam_break

STEPS = 50


@pytest.fixture
def single_thread_backend():
    backend.init("cpu", seed=1, single_thread=True)
    yield backend.current()
    backend.init("cpu")          # back to the session default (resets Taichi)


def run_once() -> dict:
    scene = dam_break(dim=2, a=0.02, l0=2e-3, t_end=1.0)
    sim = simulator_for(scene)
    for _ in range(STEPS):
        sim.step()
    out = sim.snapshot()
    out["time"] = sim.stats.time
    return out


def test_two_runs_are_bit_identical(single_thread_backend):
    assert single_thread_backend.single_thread and single_thread_backend.seed == 1
    first = run_once()
    second = run_once()
    assert first["time"] == second["time"] > 0
    moved = np.abs(first["pos"] - dam_break(dim=2, a=0.02, l0=2e-3).pos).max()
    assert moved > 0, "the dam break should have moved in 50 steps"
    assert np.abs(first["vel"]).max() > 0
    for key in ("pos", "vel", "pressure", "number_density", "kind"):
        assert np.array_equal(first[key], second[key]), key
