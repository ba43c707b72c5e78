"""tools/mode_power_study.py's numpy forces (VALIDATION.md "Where the mode's energy goes"): the
split of the mode's energy among the forces is only as good as these sums, so they are held to
the method's exact values and to the step's own kernel:

- its pairs (validate/clusters.close_pairs) are every pair closer than re, each once;
- the sum form (method.md M2) of a linear pressure field on the perfect lattice is -grad P /
  rho exactly in the interior (the lattice's second moment, sum_j w x^2 / r^2 = n0 / d), of a
  uniform one zero, and its pair forces are equal and opposite (momentum kept) for any P;
- its viscous terms (V1, S12) are the predictor's on a disordered ball, to float rounding;
- the pressure's zeroth-order part is nil in the lattice's interior and the whole sum form for
  a uniform pressure, with the push on a flat face that C4's factor balances.
"""
import importlib.util
import itertools
import os

import numpy as np
import pytest

from crowndemo import backend
from crowndemo.core import FLUID
from crowndemo.core.lattice import lattice_offsets, weight
from crowndemo.validate.clusters import close_pairs
from viscous_probe import L0, RE_RATIO, RHO, disordered_ball, probe_simulator

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
_spec = importlib.util.spec_from_file_location(
    "mode_power_study", os.path.join(ROOT, "tools", "mode_power_study.py"))
tool = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(tool)


def test_pairs_are_every_pair_within_re_once():
    """The tool's pairs (validate/clusters.close_pairs): every pair closer than re, once."""
    x = np.random.default_rng(0).uniform(0.0, 10 * L0, (300, 3))
    re = RE_RATIO * L0
    i, j, d2 = close_pairs(x, re, with_d2=True)
    found = {(min(a, b), max(a, b)) for a, b in zip(i.tolist(), j.tolist())}
    d = np.linalg.norm(x[:, None] - x[None], axis=2)
    brute = {(a, b) for a, b in zip(*np.nonzero(d < re)) if a < b}
    assert found == brute and len(i) == len(found)
    np.testing.assert_allclose(np.sqrt(d2), d[i, j])


def _block(dim: int):
    """A perfect lattice block of half-width m spacings, and its interior (the points whose
    neighbourhood within re lies inside the block)."""
    m = 6 if dim == 2 else 4
    x = np.array(list(itertools.product(range(-m, m + 1), repeat=dim)), dtype=float) * L0
    return m, x, np.max(np.abs(x), axis=1) <= (m - RE_RATIO) * L0 + 1e-12


@pytest.mark.parametrize("dim", [2, 3])
def test_sum_form_of_a_linear_pressure_is_its_gradient(dim):
    sim = probe_simulator(dim, 8, "central")
    m, x, interior = _block(dim)
    k = np.arange(1.0, dim + 1.0) * 1.0e5                       # grad P [Pa/m]
    zero = np.zeros_like(x)
    acc = tool.forces(sim, x, zero, 50.0 + x @ k, "central")["pressure"]
    np.testing.assert_allclose(acc[interior], np.tile(-k / RHO, (interior.sum(), 1)),
                               rtol=1e-9)
    uniform = tool.forces(sim, x, zero, np.full(len(x), 50.0), "central")["pressure"]
    np.testing.assert_allclose(uniform[interior], 0.0, atol=1e-9 * np.abs(k / RHO).max())
    p = np.random.default_rng(2).uniform(0.0, 100.0, len(x))
    acc = tool.forces(sim, x, zero, p, "central")["pressure"]
    np.testing.assert_allclose(acc.sum(axis=0), 0.0, atol=1e-12 * np.abs(acc).max() * len(x))


@pytest.mark.parametrize("dim", [2, 3])
def test_zeroth_order_part_of_the_sum_form(dim):
    """The pressure's zeroth-order part, 2 P_i sum_j g_ij: nil in the lattice's interior for
    any P (sum_j g_ij = 0 by the lattice's symmetry); the whole sum form for a uniform P (then
    P_j - P_i = 0), at the block's faces too; on a face particle d 2 P G / (n0 rho) outward,
    G = the half-lattice's sum of g's normal part, the push C4 balances (its factor
    n0 / (2 d G l0) = 1.016 in 2D, 1.011 in 3D: surface_tension/stress.py)."""
    sim = probe_simulator(dim, 8, "central")
    m, x, interior = _block(dim)
    zero = np.zeros_like(x)
    p = np.random.default_rng(5).uniform(0.0, 100.0, len(x))
    part = tool.forces(sim, x, zero, p, "central")["zeroth"]
    np.testing.assert_allclose(part[interior], 0.0, atol=1e-9 * np.abs(part).max())
    uniform = tool.forces(sim, x, zero, np.full(len(x), 50.0), "central")
    np.testing.assert_allclose(uniform["zeroth"], uniform["pressure"],
                               atol=1e-12 * np.abs(uniform["pressure"]).max())
    # the middle of the top face: its push along the last axis, outward
    face = np.all(np.abs(x[:, :-1]) < 0.5 * L0, axis=1) & (x[:, -1] > (m - 0.5) * L0)
    q = lattice_offsets(dim, 1.0, RE_RATIO)       # in l0
    w = weight(np.linalg.norm(q, axis=1), RE_RATIO)
    below = q[:, -1] < 0
    G = -float((q[below, -1] * w[below] / (q[below] ** 2).sum(axis=1)).sum())
    n0 = float(w.sum())
    assert n0 / (2 * dim * G) == pytest.approx({2: 1.016, 3: 1.011}[dim], abs=1e-3)
    expected = dim * 2.0 * 50.0 * G / (n0 * RHO * L0)
    assert uniform["zeroth"][face][0, -1] == pytest.approx(expected, rel=1e-9)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("viscosity", ["central", "laplacian"])
def test_viscous_terms_are_the_predictors(dim, viscosity):
    x = disordered_ball(dim, 4.0, 0.15)
    v = np.random.default_rng(3).normal(0.0, 0.1, x.shape)
    sim = probe_simulator(dim, len(x), viscosity)
    sim.load(x, v, np.full(len(x), FLUID, dtype=np.int32))
    sim.grid.build(RE_RATIO * L0)            # no re-sort: field index i = i-th particle
    sim.predictor.forces()
    kernel = sim.state.scratch_vec.to_numpy()[: len(x)].astype(float)
    numpy_sum = tool.forces(sim, x, v, np.zeros(len(x)), viscosity)["viscosity"]
    rtol = 1e-10 if backend.is_f64() else 2e-4
    np.testing.assert_allclose(numpy_sum, kernel, rtol=rtol, atol=rtol * np.abs(kernel).max())


@pytest.mark.parametrize("dim", [2, 3])
def test_corrected_form_is_the_correctors(dim):
    """With the corrected gradient form (M2c) the tool's pressure force is the corrector's a'
    on a disordered ball (its surface's L_i faded to I by omega, the interior's the fabric's
    correction), to float rounding."""
    from crowndemo.core.params import with_values
    from crowndemo.core import Simulator
    x = disordered_ball(dim, 4.0, 0.15)
    sim = probe_simulator(dim, len(x), "central")
    numerics = with_values(sim.numerics, pressure_gradient="corrected")
    sim = Simulator(sim.physics, numerics, len(x))
    sim.configure(sim.physics, numerics, (tuple([-1.0] * dim), tuple([1.0] * dim)))
    sim.load(x, np.zeros_like(x), np.full(len(x), FLUID, dtype=np.int32))
    sim.grid.build(RE_RATIO * L0)            # no re-sort: field index i = i-th particle
    sim.pressure.density_and_pressure()
    p = np.random.default_rng(4).uniform(50.0, 150.0, len(x))
    full = np.zeros(sim.state.capacity, dtype=sim.state.pressure.to_numpy().dtype)
    full[: len(x)] = p
    sim.state.pressure.from_numpy(full)
    sim.pressure.correct(1.0e-6)
    kernel = sim.state.scratch_vec.to_numpy()[: len(x)].astype(float)
    numpy_sum = tool.forces(sim, x, np.zeros_like(x), p, "central")["pressure"]
    rtol = 1e-10 if backend.is_f64() else 2e-4
    np.testing.assert_allclose(numpy_sum, kernel, rtol=rtol, atol=rtol * np.abs(kernel).max())


def test_face_balance_factor_of_the_study_tools():
    """lattice.face_balance_factor, the study tools' ``--c4-factor lattice``: C4's factor
    n0 / (2 d G l0) from the lattice sums, the value above at re = 2.1 l0, and larger in a wider
    neighbourhood, where the half-lattice's push G grows slower than n0 (the lattice sums
    written out at 3.1 l0 in 2D: n0 = 18.9764, G = 4.0898)."""
    from crowndemo.core.lattice import face_balance_factor
    assert face_balance_factor(2, 2.1) == pytest.approx(1.016, abs=1e-3)
    assert face_balance_factor(3, 2.1) == pytest.approx(1.011, abs=1e-3)
    assert face_balance_factor(2, 3.1) == pytest.approx(18.9764 / (4 * 4.0898), rel=1e-4)


def test_stiffness_fit_recovers_a_damped_oscillators_spring_and_damper():
    """The stiffness split (VALIDATION.md "The mode's stiffness, force by force"): for a damped
    oscillator q = exp(-gamma t) cos(omega t), M q_ddot = -K q - C q_dot with K = M (omega^2 +
    gamma^2) and C = 2 M gamma; the spring's and the damper's generalised forces, each with a
    steady part, are fitted back to (K, 0) and (0, C), and their sum to (K, C)."""
    M, omega, gamma = 2.5e-7, 760.0, 45.0
    t = np.linspace(0.0, 5 * 2 * np.pi / omega, 201)
    q = np.exp(-gamma * t) * np.cos(omega * t)
    q_dot = np.exp(-gamma * t) * (-gamma * np.cos(omega * t) - omega * np.sin(omega * t))
    K, C = M * (omega ** 2 + gamma ** 2), 2.0 * M * gamma
    spring, damper = -K * q + 3e-3, -C * q_dot - 1e-3
    for force, want in ((spring, (K, 0.0)), (damper, (0.0, C)), (spring + damper, (K, C))):
        got = tool.fit_stiffness(q, q_dot, force)
        assert got[0] == pytest.approx(want[0], rel=1e-9, abs=1e-9 * K)
        assert got[1] == pytest.approx(want[1], rel=1e-9, abs=1e-9 * C)


@pytest.mark.parametrize("dim", [2, 3])
def test_mode_coordinate_of_a_ball_stretched_along_the_mode(dim):
    """mode_coordinate: a lattice ball mapped by x -> (I + q G_hat) x (G_hat symmetric
    traceless, |G_hat| = 1) reads q to O(q^2) (second order: 1e-6 at q = 1e-3), and for the
    velocity u = q_dot G_hat x it reads q_dot; a rotation reads nothing."""
    from crowndemo.scenes.drop import ball
    x0 = ball(dim, 1.0, 0.1)
    x0 = x0 - x0.mean(axis=0)
    G_hat = np.diag([1.0, -1.0]) if dim == 2 else np.diag([-0.5, -0.5, 1.0])
    G_hat = G_hat / np.linalg.norm(G_hat)
    q, q_dot = 1e-3, 7.0
    d = x0 @ (np.eye(dim) + q * G_hat).T
    got_q, got_rate = tool.mode_coordinate(d, q_dot * d @ G_hat.T, G_hat)
    assert got_q == pytest.approx(q, abs=2 * q * q)
    assert got_rate == pytest.approx(q_dot, rel=2 * q)
    spin = np.zeros((dim, dim))
    spin[0, 1], spin[1, 0] = 1.0, -1.0
    assert abs(tool.mode_coordinate(x0, x0 @ spin.T, G_hat)[1]) < 1e-12


@pytest.mark.parametrize("dim", [2, 3])
def test_surface_pairs_normaliser_of_the_study_tools(dim):
    """``--surface-pairs`` (tools/stress_surface_study.py, VALIDATION.md "The mode's
    stiffness, force by force"): its unweighted cut sum is the member's, a = 1 / (K_d sum)
    (lattice.stress_normaliser); the flat lattice's layers' omega (C1) are 1 on the face and,
    one layer in, the number density's deficit over 2 (1 - beta): in 3D that layer lacks only
    the neighbour two spacings out (w = 2.1/2 - 1), in 2D also none other within 2.1 l0; so
    the weighted sum keeps the face's own pairs and a share omega_1 of its pairs with the
    layer beneath, and the ratio (a's factor) exceeds 1 (``product``; ``mean`` less so)."""
    import sys
    sys.path.insert(0, os.path.join(ROOT, "tools"))
    import stress_surface_study as study
    from crowndemo.core import Numerics
    from crowndemo.core.lattice import (n0_lambda0, stress_gradient_norm, stress_normaliser,
                                        stress_pair_kernel, stress_pair_support)
    beta = Numerics().free_surface_beta(dim)
    plain, weighted = study.cut_sums(dim, 2.1, beta)
    h = stress_pair_support(dim, 1.0, 2.1)
    K_d = stress_gradient_norm(dim, 1.0, 2.1, stress_pair_kernel, h)
    assert 1.0 / (K_d * plain) == pytest.approx(stress_normaliser(dim, 1.0, 2.1), rel=1e-12)
    n0 = n0_lambda0(dim, 1.0, 2.1)[0]
    omega = study._layer_omega(dim, 2.1, beta, 3)
    assert omega[0] == 1.0
    assert omega[1] == pytest.approx((2.1 / 2.0 - 1.0) / n0 / (2.0 * (1.0 - beta)), rel=1e-12)
    assert omega[2] == 0.0
    assert study.surface_pairs_ratio(dim, 2.1, beta) > 1.0
    # the mean weight, (omega_i + omega_j)/2 >= omega_i omega_j for omega in [0, 1], keeps
    # more of the cut: its factor lies between 1 and the product's
    assert 1.0 < study.surface_pairs_ratio(dim, 2.1, beta, "mean") < study.surface_pairs_ratio(
        dim, 2.1, beta, "product")


@pytest.mark.parametrize("dim", [2, 3])
def test_surface_pairs_band_of_the_study_tools(dim):
    """``--pair-band B`` (tools/stress_surface_study.py): the pairs' omega = clamp((1 -
    n/n0) / B, 0, 1), so the flat lattice's layer one in (deficit (2.1/2 - 1)/n0, the one
    neighbour two spacings out it lacks) takes deficit / B, and the face (which lacks half its
    neighbourhood, a deficit over 1/4) keeps omega 1 at B = 1/4; the wider the band, the less
    of the face's pairs with that layer the weighted cut keeps, so the larger a's factor."""
    import sys
    sys.path.insert(0, os.path.join(ROOT, "tools"))
    import stress_surface_study as study
    from crowndemo.core import Numerics
    from crowndemo.core.lattice import n0_lambda0
    n0 = n0_lambda0(dim, 1.0, 2.1)[0]
    band = 0.25
    omega = study._layer_omega(dim, 2.1, 1.0 - band / 2.0, 3)
    assert omega[0] == 1.0
    assert omega[1] == pytest.approx((2.1 / 2.0 - 1.0) / n0 / band, rel=1e-12)
    own = Numerics().free_surface_beta(dim)
    assert study.surface_pairs_ratio(dim, 2.1, own, "mean") < study.surface_pairs_ratio(
        dim, 2.1, 1.0 - band / 2.0, "mean")
