"""The surface stress's curvature correction (C5, core/surface_tension/stress.py, method.md
§4c): the curvature it reads on a smooth ball and a flat face, Newton's third law with it,
and its factor carried through a re-sort and a checkpoint (state.carry). What it does to a
drop is tests/test_surface_stress.py's 3D quick rows (the resting drop's Laplace pressure, the
oscillating drop's frequency).

Expected values come from geometry: a sphere's mean curvature at radius r is 1/r, a
plane's 0; pair forces sum to zero;
a carried field follows its particle.
"""
import numpy as np
import pytest

from crowndemo.core import FLUID, Numerics, Physics, Simulator
from crowndemo.core.params import STRESS_NEIGHBOURHOODS
from crowndemo.core.surface_tension.stress import NORMAL_MIN, TOLMAN_LAG, UNSET

L0 = 1.0e-4
SEED_DELTAS = STRESS_NEIGHBOURHOODS[2.1]["tolman"]     # the seed's neighbourhood, re = 2.1 l0
DELTA = SEED_DELTAS[3]


@pytest.fixture(scope="module")
def sim3():
    phys = Physics(dim=3, l0=L0, v_max=1.0, nu=0.0, sigma=0.0728, gravity=0.0, rho=998.0)
    return Simulator(phys, Numerics(surface_tension="stress", pressure_gradient="sum",
                                    collision=0.0), 18000)


def passes(sim: Simulator, pos: np.ndarray, times: int = 1, dt: float = 1e-6):
    """Load ``pos`` at rest and run the member's passes ``times`` times, steps of ``dt`` (each
    computes the factor s the next one uses; the first sets it); the mean curvature H = (1 -
    s)/(delta l0) C5 read on the last, |g|, the acceleration and the positions as the device
    holds them."""
    sim.load(pos, np.zeros_like(pos), np.full(len(pos), FLUID, dtype=np.int32))
    sim.grid.build(sim.lattice.re)
    for _ in range(times):
        sim.pressure.density_and_pressure(dt)
    n = sim.state.count
    m = sim.surface_tension
    s = m.tolman.to_numpy()[:n].astype(float)
    g = np.linalg.norm(m.colour.to_numpy()[:n].astype(float), axis=1)
    return ((1.0 - s) / (DELTA * L0), g, m.accel.to_numpy()[:n].astype(float),
            sim.state.pos.to_numpy()[:n].astype(float))


def test_the_correction_is_three_dimensional():
    """At re = 2.1 l0: 0 in 2D, where the resting drops read sigma/R without it (VALIDATION.md)."""
    assert SEED_DELTAS[2] == 0.0 and 0.5 < SEED_DELTAS[3] < 1.5


def sphere_points(count: int, r: float) -> np.ndarray:
    """``count`` points spread evenly over a sphere of radius r (a Fibonacci lattice)."""
    k = np.arange(count) + 0.5
    z = 1.0 - 2.0 * k / count
    phi = np.pi * (1.0 + 5.0 ** 0.5) * k
    s = np.sqrt(1.0 - z * z)
    return r * np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)


@pytest.mark.parametrize("R", [8, 12, 16])
def test_mean_curvature_of_a_smooth_ball(sim3, R):
    """A ball of shells l0 apart, the outermost at R - l0/2, each with 4 pi r^2 / l0^2 points
    spread evenly: over the particles whose normals C5 uses (|g| l0 > NORMAL_MIN), the
    |g|-weighted mean of its H is that of 1/r at their radii within 0.5 %. For radial unit
    normals the tangential form, -sum_j n_j . r_t f / sum_j |r_t|^2 f, is the neighbours'
    1/|x_j| averaged with the weight |r_t|^2 f: exact on a sphere but for the spread of the
    neighbours' radii; the form with the whole (n_j - n_i) . r_ij adds (1 - n_i . n_j) r_ij . n_i,
    the normals' turn to second order along the depth, and read +1.3 / +0.6 / +0.3 % here (issue
    23's bound for a curvature is 5 %). A rough surface reads higher (VALIDATION.md, "C5's H
    from the normals' tangential change")."""
    pts = [np.zeros((1, 3))] + [sphere_points(max(int(round(4 * np.pi * r * r)), 1), r)
                                for r in R - 0.5 - np.arange(R)]
    H, g, _, pos = passes(sim3, np.concatenate(pts) * L0)
    on = g * L0 > NORMAL_MIN
    r = np.linalg.norm(pos[on], axis=1)
    assert on.sum() > 4 * np.pi * (R - 1) ** 2          # the outer shell, at least
    assert np.average(H[on], weights=g[on]) == pytest.approx(
        np.average(1.0 / r, weights=g[on]), rel=0.005)


def test_flat_face_has_no_curvature(sim3):
    """The top face of a lattice slab, away from its edges: H = 0 within 0.05/R for the
    smallest drop the cases run (R = 8 l0), as issue 23 asks of a curvature estimate."""
    k = np.arange(16)
    pts = np.stack(np.meshgrid(k, k, np.arange(6), indexing="ij"), -1).reshape(-1, 3) * L0
    H, g, _, pos = passes(sim3, pts.astype(float))
    away = ((pos[:, 0] > 4.5 * L0) & (pos[:, 0] < 10.5 * L0) & (pos[:, 1] > 4.5 * L0)
            & (pos[:, 1] < 10.5 * L0) & (pos[:, 2] > 2.5 * L0) & (g > 0))
    assert away.sum() >= 2 * 36
    assert np.abs(H[away]).max() < 0.05 / (8 * L0)


def test_pair_forces_sum_to_zero_with_the_correction(sim3):
    """Newton's third law with s_i varying from particle to particle: the pair terms (s_i T_i
    + s_j T_j) r_ij f_d stay antisymmetric (float32 rounding against the forces' size)."""
    rng = np.random.default_rng(3)
    k = np.arange(10)
    pts = np.stack(np.meshgrid(k, k, np.arange(8), indexing="ij"), -1).reshape(-1, 3)
    pts = (pts + rng.uniform(-0.25, 0.25, pts.shape)) * L0
    H, g, a, _ = passes(sim3, pts, times=2)
    s = 1.0 - DELTA * L0 * H
    assert np.std(s[g > 0]) > 0.02                     # the factor does vary
    assert np.linalg.norm(a.sum(axis=0)) < 1e-5 * np.abs(a).sum()


def test_the_factor_follows_its_particle(sim3):
    """A re-sort permutes the carried factor with the particles; ``dump`` keeps it and
    ``restore`` of a dump without it (an older checkpoint) leaves it as it is; ``load``
    resets it to unset (its particle's first step sets it)."""
    import taichi as ti
    state = sim3.state
    k = np.arange(6)
    pts = np.stack(np.meshgrid(k, k, k, indexing="ij"), -1).reshape(-1, 3) * L0
    sim3.load(pts.astype(float), np.zeros_like(pts, dtype=float),
              np.full(len(pts), FLUID, dtype=np.int32))
    n = state.count
    assert np.all(sim3.surface_tension.tolman.to_numpy()[:n] == UNSET)
    mark = np.zeros(state.capacity, dtype=sim3.surface_tension.tolman.to_numpy().dtype)
    mark[:n] = 1.0 + np.arange(n) / n                     # a value per particle id
    sim3.surface_tension.tolman.from_numpy(mark)
    order = ti.field(ti.i32, state.capacity)
    order.from_numpy(np.concatenate([np.arange(n)[::-1], np.arange(n, state.capacity)])
                     .astype(np.int32))
    state.permute(order)
    pid = state.pid.to_numpy()[:n]
    np.testing.assert_array_equal(sim3.surface_tension.tolman.to_numpy()[:n], mark[pid])
    saved = state.dump()
    np.testing.assert_array_equal(saved["stress_tolman"], mark[pid])
    assert "stress_tolman" not in state.snapshot()
    older = {k: v for k, v in saved.items() if k != "stress_tolman"}
    sim3.surface_tension.tolman.fill(0.5)
    state.restore(older)
    assert np.all(sim3.surface_tension.tolman.to_numpy()[:n] == 0.5)
    state.restore(saved)
    np.testing.assert_array_equal(sim3.surface_tension.tolman.to_numpy()[:n], mark[pid])


def ball(R: int) -> np.ndarray:
    """A ball of shells l0 apart, the outermost at R - l0/2 (test_mean_curvature_...'s)."""
    return np.concatenate([np.zeros((1, 3))] + [
        sphere_points(max(int(round(4 * np.pi * r * r)), 1), r) for r in R - 0.5 - np.arange(R)])


def test_the_factor_follows_the_curvature_over_its_capillary_time(sim3):
    """C5's lag: the particles of a flat slab (H_A ~ 0 on its face) put into a ball of R =
    12 l0 (H_B = 1/r on its surface): s_i relaxes to the ball's value s_B as the first-order
    lag's exact step response, s_A + (s_B - s_A)(1 - exp(-t/tau)), tau = TOLMAN_LAG sqrt(rho /
    (sigma |H_B|^3)) the capillary time of the new curvature (where |H_B| >= |H_A|, so tau
    stays that one); a pass for output (dt = 0) moves nothing."""
    m = sim3.surface_tension
    pos = ball(12) * L0
    k = np.arange(24)
    slab = np.stack(np.meshgrid(k, k, k, indexing="ij"), -1).reshape(-1, 3)[:len(pos)] * L0
    H_A, _, _, _ = passes(sim3, slab.astype(float))        # the first step sets s_A
    s_A = 1.0 - DELTA * L0 * H_A
    dtype = sim3.state.pos.to_numpy().dtype
    sim3.state.pos.from_numpy(np.concatenate([pos, np.zeros(
        (sim3.state.capacity - len(pos), 3))]).astype(dtype))
    sim3.grid.build(sim3.lattice.re)
    sim3.pressure.density_and_pressure(0.0)               # output: s stays
    n = sim3.state.count
    np.testing.assert_array_equal(m.tolman.to_numpy()[:n], s_A.astype(dtype))
    s_B = m.tolman_next.to_numpy()[:n].astype(float)     # the ball's own s
    g = np.linalg.norm(m.colour.to_numpy()[:n].astype(float), axis=1)
    dt, steps = 2.0e-3, 4
    for _ in range(steps):
        sim3.pressure.density_and_pressure(dt)
    s = m.tolman.to_numpy()[:n].astype(float)
    H_B = (1.0 - s_B) / (DELTA * L0)
    on = (g * L0 > NORMAL_MIN) & (np.abs(H_B) >= np.abs(H_A)) & (np.abs(H_B) > 0.0)
    assert on.sum() > 0.5 * 4 * np.pi * 11.5 ** 2         # most of the outer shell
    tau = TOLMAN_LAG * np.sqrt(998.0 / (0.0728 * np.abs(H_B[on]) ** 3))
    r = np.linalg.norm(pos[on], axis=1)
    assert np.median(tau) == pytest.approx(np.median(
        TOLMAN_LAG * np.sqrt(998.0 * r ** 3 / 0.0728)), rel=0.05)     # the ball's 1/r
    expected = s_B[on] + (s_A[on] - s_B[on]) * np.exp(-steps * dt / tau)
    np.testing.assert_allclose(s[on], expected, atol=2e-5)
    assert np.median(np.abs(s[on] - s_B[on])) > 0.1 * np.median(np.abs(s_A[on] - s_B[on]))
