"""Potential-model surface tension (method.md §4, S22-S24).

Potential P(r) = C Phi(r), Phi(r) = (1/3)(r - 1.5 l0 + 0.5 re)(r - re)^2 for r <= re, C <= 0;
P'(r) = C (r - l0)(r - re). Force on i = -grad_i P = P'(r) (r_j - r_i)/r, so with C < 0 a pair
attracts for l0 < r < re, repels for r < l0 and does nothing beyond re.

C from (S23): 2 sigma l0^(d-1) = -C sum_{i in column A} sum_{j across the cut} Phi(r_ij).
Every expected value here is computed from these formulas, independently of crowndemo.
"""
import itertools
import math

import numpy as np
import pytest

from crowndemo import backend
from crowndemo.core import FLUID, Numerics, Physics, Simulator
from crowndemo.core.lattice import LatticeConstants, surface_tension_coefficient

SIGMA = 0.0728
RHO = 998.0


def phi_shape(r: float, l0: float, re: float) -> float:
    """Phi = P/C (S22)."""
    return (r - 1.5 * l0 + 0.5 * re) * (r - re) ** 2 / 3.0 if r <= re else 0.0


def cut_sum(dim: int, l0: float, re: float) -> float:
    """Column A = lattice points (0, .., 0, -k), k >= 0, below the cut plane z = l0/2; partners:
    every lattice point with z >= l0 (integer index >= 1). Enumerated generously wide/deep."""
    reach = int(math.ceil(re / l0)) + 2
    total = 0.0
    for k in range(0, reach + 3):                                   # column, going down
        for lateral in itertools.product(range(-reach, reach + 1), repeat=dim - 1):
            for zj in range(1, reach + 2):                          # across the cut
                dz = zj + k
                r = l0 * math.sqrt(sum(c * c for c in lateral) + dz * dz)
                total += phi_shape(r, l0, re)
    return total


def expected_C(dim: int, l0: float, re: float, sigma: float) -> float:
    return -2.0 * sigma * l0 ** (dim - 1) / cut_sum(dim, l0, re)


# ---- (b) the coefficient C -------------------------------------------------------------------
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("re_ratio", [2.1, 3.1, 4.0])
@pytest.mark.parametrize("l0", [1.0e-3, 5.0e-5])
def test_coefficient_matches_cut_energy(dim, re_ratio, l0):
    re = re_ratio * l0
    C = surface_tension_coefficient(dim, l0, re, SIGMA)
    C_ref = expected_C(dim, l0, re, SIGMA)
    assert C < 0.0
    assert C == pytest.approx(C_ref, rel=1e-12)
    # the defining relation itself, written out
    assert 2.0 * SIGMA * l0 ** (dim - 1) == pytest.approx(-C * cut_sum(dim, l0, re), rel=1e-12)


def test_cut_sum_closed_form_2d():
    """2D, re = 2.1 l0, l0 = 1: the pairs across the cut are (0,0)-(0,1) [r=1],
    (0,0)-(+-1,1) [r=sqrt2], (0,0)-(0,2) and (0,-1)-(0,1) [r=2]; (+-1,2), (+-2,1) are at
    sqrt5 > re."""
    l0, re = 1.0, 2.1
    s = phi_shape(1.0, l0, re) + 2 * phi_shape(math.sqrt(2.0), l0, re) + 2 * phi_shape(2.0, l0, re)
    assert cut_sum(2, l0, re) == pytest.approx(s, rel=1e-14)
    assert surface_tension_coefficient(2, l0, re, SIGMA) == pytest.approx(-2 * SIGMA / s, rel=1e-12)


def test_coefficient_scaling_and_zero_sigma():
    """Phi ~ l0^3 at fixed re/l0, so C ~ sigma l0^(d-1) / l0^3; sigma = 0 gives C = 0."""
    for dim in (2, 3):
        c1 = surface_tension_coefficient(dim, 1e-3, 2.1e-3, SIGMA)
        c2 = surface_tension_coefficient(dim, 2e-3, 4.2e-3, 2 * SIGMA)
        assert c2 / c1 == pytest.approx(2.0 * 2.0 ** (dim - 4), rel=1e-12)
        assert surface_tension_coefficient(dim, 1e-3, 2.1e-3, 0.0) == 0.0
    lc = LatticeConstants.compute(3, 1e-3, 2.1, RHO, SIGMA)
    assert lc.C == pytest.approx(expected_C(3, 1e-3, 2.1e-3, SIGMA), rel=1e-12)
    assert lc.mass == pytest.approx(RHO * 1e-9, rel=1e-15)


# ---- (a) two particles -----------------------------------------------------------------------
L0 = 1.0e-3
RE_RATIO = 2.1


def physics(dim: int) -> Physics:
    return Physics(dim=dim, l0=L0, v_max=1.0, re_ratio=RE_RATIO, rho=RHO, nu=0.0, sigma=SIGMA,
                   gravity=0.0)


@pytest.fixture(scope="module", params=[2, 3], ids=["2d", "3d"])
def pair_sim(request):
    dim = request.param
    ph = physics(dim)
    sim = Simulator(ph, Numerics(), 2)
    assert sim.model.surface_tension and not sim.model.viscosity and not sim.model.gravity
    return sim


def load_pair(sim: Simulator, r: float, direction):
    """Particle 0 at the origin, particle 1 at r e. Returns the separation vector as the
    device holds it (f32 rounding included), in float64."""
    dim = sim.physics.dim
    e = np.asarray(direction, dtype=float)[:dim]
    e = e / np.linalg.norm(e)
    pos = np.array([np.zeros(dim), r * e])
    sim.load(pos, np.zeros_like(pos), np.full(2, FLUID, dtype=np.int32))
    held = sim.state.pos.to_numpy()[:2].astype(np.float64)
    return held[1] - held[0]


def expected_acceleration(dim: int, rij: np.ndarray) -> np.ndarray:
    """On particle 0, partner at r_0 + rij: (C/m) (r - l0)(r - re) rij / r."""
    re = RE_RATIO * L0
    C = expected_C(dim, L0, re, SIGMA)
    m = RHO * L0 ** dim
    r = np.linalg.norm(rij)
    return C / m * (r - L0) * (r - re) * rij / r


RATIOS = [0.6, 0.9, 1.2, 1.5, 1.9, 2.05, 2.2, 3.0]


@pytest.mark.parametrize("ratio", RATIOS)
def test_predictor_pair_acceleration(pair_sim, ratio):
    """One predictor call from rest: u* = dt a*, with a* the pair force above (sign and size)."""
    dim = pair_sim.physics.dim
    r = ratio * L0
    rij = load_pair(pair_sim, r, (1.0, 2.0, -0.5))
    dt = 1.0e-5
    pair_sim.grid.build(RE_RATIO * L0)
    pair_sim.predictor.forces()
    pair_sim.predictor.run(dt)
    a = pair_sim.state.vel.to_numpy()[:2] / dt
    a_ref = expected_acceleration(dim, rij)
    if ratio * L0 >= RE_RATIO * L0:
        assert np.all(a == 0.0)                        # beyond re: nothing at all
        return
    tol = 1e-12 if backend.is_f64() else 5e-6   # measured up to 1e-6 (r - re cancels near re)
    np.testing.assert_allclose(a[0], a_ref, rtol=tol, atol=tol * np.abs(a_ref).max())
    np.testing.assert_allclose(a[1], -a_ref, rtol=tol, atol=tol * np.abs(a_ref).max())
    toward = float(a[0] @ rij)                          # > 0: 0 accelerates toward 1
    if ratio > 1.0:
        assert toward > 0.0, "l0 < r < re must attract"
    else:
        assert toward < 0.0, "r < l0 must repel"


@pytest.mark.parametrize("ratio,effect", [(1.5, "attract"), (0.7, "repel"), (2.5, "none")])
def test_one_step_moves_pair(pair_sim, ratio, effect):
    """A whole step (predictor + pressure; two particles are a free surface so P = 0)."""
    r = ratio * L0
    load_pair(pair_sim, r, (0.3, -1.0, 0.8))
    pair_sim.configure(physics(pair_sim.physics.dim), Numerics())
    pos0 = pair_sim.snapshot()["pos"].astype(float)
    dt = pair_sim.step()
    assert dt > 0
    snap = pair_sim.snapshot()
    pos1 = snap["pos"].astype(float)
    assert np.all(snap["pressure"] == 0.0)
    d0 = np.linalg.norm(pos0[1] - pos0[0])
    d1 = np.linalg.norm(pos1[1] - pos1[0])
    v = snap["vel"].astype(float)
    if effect == "none":
        assert np.all(v == 0.0) and np.array_equal(pos0, pos1)
    else:
        # momentum is conserved by a pair force
        np.testing.assert_allclose(v[0] + v[1], 0.0, atol=1e-6 * np.abs(v).max())
        if effect == "attract":
            assert d1 < d0
        else:
            assert d1 > d0
