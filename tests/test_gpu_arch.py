"""The step on the GPU archs: CUDA where there is one, and Taichi's Vulkan backend, which Mesa's
software driver (lavapipe, installed by ``make`` for the renderer) runs where there is no GPU.
So the GPU code path (one device task per kernel loop, no CPU-thread spreading; PTX or
SPIR-V instead of the CPU's code) is checked on every machine, and on CUDA where a session has
a GPU. An arch that Taichi does not find is skipped, saying why.

- The health reductions against numpy on a state with particles outside the domain: the
  counts of parked particles per exit reason are exact integers, the maximum speed and kinetic
  energy float sums. (On Vulkan an atomic add on the counters once zeroed whole reductions:
  the crown's drop fell at 8 m/s while the health report said 0.)
- The ``quick-2d`` and ``quick`` (3D) crowns, 20 steps, on the GPU arch and on the CPU: the
  same discrete equations on both, so the runs differ by float32 rounding only (summation
  order, fused multiply-adds), amplified over the steps; a missing term or a broken pass
  differs at order one. The CPU side compiles with ``fast_compile`` (the same equations; the
  3D step compiles in a fraction of the time).
"""
import numpy as np
import pytest

from crowndemo import backend, config
from crowndemo.backend import BackendError
from crowndemo.core import FLUID, simulator_for
from crowndemo.core.coefficients import Coefficients
from crowndemo.core.health import Health, exit_reasons
from crowndemo.core.state import ParticleState

STEPS = 20
PRESETS = ("quick-2d", "quick")
ROUNDING = 1e-3      # relative: float32 rounding amplified over 20 steps is far below this


def crown_run(preset: str = "quick-2d") -> dict:
    r = config.load(preset, "draft", [])
    sim = simulator_for(r.build_scene())
    for _ in range(STEPS):
        sim.step()
    snap = sim.snapshot()
    order = np.argsort(snap["id"])
    return {"snap": {k: v[order] for k, v in snap.items()}, "time": sim.stats.time,
            "health": sim.stats.health, "mass": float(sim.coef.mass[None]), "l0": r.l0,
            "rho_c2": sim.physics.rho * sim.physics.c ** 2}


def parked_state() -> dict:
    """3000 particles (three reduction blocks) in the unit square, the domain [0.2, 0.8]^2:
    the report after one health measurement."""
    rng = np.random.default_rng(5)
    n = 3000
    pos = rng.uniform(0.0, 1.0, (n, 2)).astype(np.float32)
    vel = rng.normal(0.0, 2.0, (n, 2)).astype(np.float32)
    state = ParticleState(2, 4096)
    state.load(pos, vel, np.full(n, FLUID, np.int32))
    coef = Coefficients(2)
    coef.domain_lo[None] = [0.2, 0.2]
    coef.domain_hi[None] = [0.8, 0.8]
    coef.mass[None] = 1.0
    coef.n0[None] = 1.0
    health = Health(state, coef)
    health.reset()
    return {"pos": pos, "vel": vel, "report": health.measure()}


GPU_ARCHS = ("vulkan", "cuda")


@pytest.fixture(scope="module")
def runs():
    """Per GPU arch: the parked-state report and the crown runs, or why it was skipped; and
    the CPU's crown runs."""
    out = {}
    try:
        for arch in GPU_ARCHS:
            try:
                backend.init(arch)
            except BackendError as e:
                out[arch] = f"no {arch} device for Taichi: {e}"
                continue
            out[(arch, "parked")] = parked_state()
            out.update({(arch, p): crown_run(p) for p in PRESETS})
        if any((a, "parked") in out for a in GPU_ARCHS):
            backend.init("cpu", fast_compile=True)
            out.update({("cpu", p): crown_run(p) for p in PRESETS})
    finally:
        backend.init("cpu")          # the session's backend (resets Taichi)
    return out


def on(runs: dict, arch: str, what: str):
    if arch in runs:
        pytest.skip(runs[arch])
    return runs[(arch, what)]


@pytest.mark.parametrize("arch", GPU_ARCHS)
def test_health_reductions_on_the_gpu_arch(runs, arch):
    parked = on(runs, arch, "parked")
    pos, vel, report = parked["pos"], parked["vel"], parked["report"]
    # the exit reason as Health gives it: the last axis out wins, lo before hi on an axis
    reason = np.zeros(len(pos), int)
    for k in range(2):
        reason[pos[:, k] < 0.2] = 1 + 2 * k
        reason[pos[:, k] > 0.8] = 2 + 2 * k
    names = exit_reasons(2)
    expected = {names[r]: int((reason == r).sum()) for r in range(1, 5) if (reason == r).any()}
    assert report.left == expected and report.left_total == int((reason > 0).sum())
    inside = reason == 0
    u2 = (vel[inside].astype(np.float64) ** 2).sum(axis=1)
    assert report.max_speed == pytest.approx(np.sqrt(u2.max()), rel=1e-6)
    assert report.kinetic == pytest.approx(0.5 * u2.sum(), rel=1e-4)
    assert report.nonfinite == 0


@pytest.mark.parametrize("arch", GPU_ARCHS)
@pytest.mark.parametrize("preset", PRESETS)
def test_crown_steps_on_the_gpu_arch_match_the_cpu(runs, arch, preset):
    gpu, cpu = on(runs, arch, preset), runs[("cpu", preset)]
    assert gpu["time"] == pytest.approx(cpu["time"], rel=ROUNDING)   # the same dt, step by step
    a, b = gpu["snap"], cpu["snap"]
    assert np.array_equal(a["kind"], b["kind"])
    fluid = b["kind"] == FLUID
    assert np.abs(a["pos"] - b["pos"]).max() < ROUNDING * gpu["l0"]
    speed = np.linalg.norm(b["vel"][fluid], axis=1).max()
    assert speed > 7.0                  # the drop falls at U = 8 m/s: the run is under way
    assert np.abs(a["vel"] - b["vel"])[fluid].max() < ROUNDING * speed
    # P = rho c^2 (n - n0)/n0 (S17): a number density off by a fraction eps moves P by
    # rho c^2 eps, so the pressures agree on that scale
    assert np.abs(b["pressure"][fluid]).max() > 0.0
    assert np.abs(a["pressure"] - b["pressure"])[fluid].max() < ROUNDING * gpu["rho_c2"]
    # the health report on the GPU arch: what numpy reads from the same particles
    u = np.linalg.norm(a["vel"][a["kind"] == FLUID].astype(np.float64), axis=1)
    assert gpu["health"].max_speed == pytest.approx(u.max(), rel=1e-5)
    assert gpu["health"].kinetic == pytest.approx(0.5 * gpu["mass"] * (u ** 2).sum(), rel=1e-4)
    assert gpu["health"].max_speed == pytest.approx(cpu["health"].max_speed, rel=ROUNDING)
