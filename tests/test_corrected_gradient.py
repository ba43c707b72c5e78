"""The corrected pressure gradient (M2c, method.md): a' = -(1/rho)(d/n0) sum_j (P_i L_i + P_j
L_j) r_ij w / r^2, L_i = (tr M_i / d) M_i^-1, M_i = sum_j w r_ij r_ij^T / r^2, against exact
values.

Why exact: the pair force is antisymmetric, so for any velocity field u = G x + b the power
sum_i a'_i . u_i is -(1/2) sum_ij f_ij . G r_ij over ordered pairs, and each particle's share
P_i tr(L_i G M_i) = P_i (tr M_i / d) tr G since M_i L_i = (tr M_i / d) I. So the pressure's
power on a uniform velocity gradient is tr(G) / (n0 rho) sum_i P_i tr M_i whatever the
particles' arrangement: nothing on a shear or a rotation, the pressure's own work on an
expansion. The sum form (L = I) gives sum_i P_i G : M_i, which on a disordered set is not nil
on a shear: the fabric's anisotropy acts as a shear stress.
"""
import itertools

import numpy as np
import pytest

from crowndemo import backend
from crowndemo.core import FLUID, Numerics, Physics, Simulator
from crowndemo.core.lattice import n0_lambda0
from crowndemo.core.params import ParameterError, with_values

L0 = 2.0 ** -9
RE_RATIO = 2.1
RHO, C = 998.0, 20.0
HALF = {2: 8, 3: 6}


def block(dim: int, gradient: str, seed: int = 3):
    """A block of fluid particles on a lattice compressed to 0.95 l0 (n > n0 inside, so C1's
    omega is 0 there and L_i is the fabric's whole correction), each moved at random by up to
    0.15 l0 per axis: a disordered set whose fabric is not isotropic."""
    m = HALF[dim]
    ks = np.array(list(itertools.product(range(-m, m + 1), repeat=dim)), dtype=float)
    rng = np.random.default_rng(seed)
    pos = (ks * 0.95 + rng.uniform(-0.15, 0.15, ks.shape)) * L0
    physics = Physics(dim=dim, l0=L0, v_max=C / 5.0, re_ratio=RE_RATIO, rho=RHO, nu=0.0,
                      sigma=0.0, gravity=0.0, sound_speed=C)
    numerics = with_values(Numerics(), pressure_gradient=gradient)
    sim = Simulator(physics, numerics, len(pos))
    sim.configure(physics, numerics, (tuple([-1.0] * dim), tuple([1.0] * dim)))
    sim.load(pos, np.zeros_like(pos), np.full(len(pos), FLUID, dtype=np.int32))
    sim.grid.build(RE_RATIO * L0)          # no re-sort: field index i = i-th particle
    return sim, pos


def pressure_acceleration(sim, pos, p) -> np.ndarray:
    """The corrector's a' (S18) for the pressures ``p`` at these positions."""
    sim.pressure.density_and_pressure()
    fdt = np.float64 if backend.is_f64() else np.float32
    full = np.zeros(sim.state.capacity, dtype=fdt)
    full[: len(pos)] = p
    sim.state.pressure.from_numpy(full)
    sim.pressure.correct(1.0e-6)
    return sim.state.scratch_vec.to_numpy()[: len(pos)].astype(float)


def fabric_and_interior(dim: int, pos: np.ndarray):
    """tr M_i (= sum_j w over the pairs) and the particles whose neighbourhood is whole and
    whose number density is above n0 (omega = 0), summed here in numpy."""
    re = RE_RATIO * L0
    rij = pos[None, :, :] - pos[:, None, :]
    r = np.sqrt((rij * rij).sum(axis=2))
    near = (r > 0.0) & (r < re)
    w = np.where(near, re / np.where(near, r, 1.0) - 1.0, 0.0)
    n = w.sum(axis=1)
    n0, _ = n0_lambda0(dim, L0, re)
    inner = np.max(np.abs(pos), axis=1) <= (HALF[dim] * 0.95 - 0.15) * L0 - re
    return n, inner & (n > n0), n0


@pytest.mark.parametrize("dim", [2, 3])
def test_the_pressure_does_no_work_on_a_shear_or_a_rotation(dim):
    """sum_i a'_i . G x_i = tr(G)/(n0 rho) sum_i P_i tr M_i for any G (the module's docstring),
    for a pressure field as uneven as the drops' (a background and a random part) on the
    interior particles: nil on a shear and on a rotation, the expansion's work on an
    expansion. The sum form on the same particles does work on the shear."""
    sim, pos = block(dim, "corrected")
    trace_m, inner, n0 = fabric_and_interior(dim, pos)
    assert inner.sum() >= 100
    rng = np.random.default_rng(7)
    p = np.where(inner, 150.0 + 40.0 * rng.standard_normal(len(pos)), 0.0)
    a = pressure_acceleration(sim, pos, p)
    shear = np.zeros((dim, dim))
    shear[0, 1] = shear[1, 0] = 1.0
    shear[0, 0], shear[1, 1] = 0.7, -0.7
    rotation = np.zeros((dim, dim))
    rotation[0, 1], rotation[1, 0] = 1.0, -1.0
    power = {k: float((a * (pos @ g.T)).sum()) for k, g in
             (("shear", shear), ("rotation", rotation), ("expansion", np.eye(dim)))}
    expansion = dim / (n0 * RHO) * float((p * trace_m).sum())
    assert power["expansion"] == pytest.approx(expansion, rel=1e-9 if backend.is_f64()
                                               else 1e-4)
    # rounding: f32 sums of ~10^3-10^4 terms of either sign (measured: 1e-8 of the expansion's)
    tol = (1e-12 if backend.is_f64() else 1e-5) * expansion
    assert abs(power["shear"]) <= tol
    assert abs(power["rotation"]) <= tol

    sim_sum, _ = block(dim, "sum")
    a_sum = pressure_acceleration(sim_sum, pos, p)
    sum_shear = float((a_sum * (pos @ shear.T)).sum())
    # the disorder's fabric anisotropy, a fraction of a percent, acts as a shear stress
    assert abs(sum_shear) > 1e-3 * expansion


@pytest.mark.parametrize("dim", [2, 3])
def test_momentum_and_a_linear_pressure(dim):
    """The pairs are antisymmetric: sum_i a'_i = 0 for any pressure. And on the lattice (no
    disorder, spacing l0: L = I inside) a linear pressure P0 + b.x reads its gradient, a' =
    -b/rho, as the sum form's does (test_step_terms.py), where i's neighbours' neighbourhoods
    are whole too (2 re from the block's edge: a neighbour's L_j near the edge is not I)."""
    sim, pos = block(dim, "corrected")
    _, inner, _ = fabric_and_interior(dim, pos)
    rng = np.random.default_rng(11)
    p = np.where(inner, 150.0 + 40.0 * rng.standard_normal(len(pos)), 0.0)
    a = pressure_acceleration(sim, pos, p)
    assert np.abs(a.sum(axis=0)).max() <= 1e-4 * np.abs(a).sum(axis=0).max()

    m = HALF[dim]
    ks = np.array(list(itertools.product(range(-m, m + 1), repeat=dim)), dtype=float)
    lattice = ks * L0
    sim.load(lattice, np.zeros_like(lattice), np.full(len(lattice), FLUID, dtype=np.int32))
    sim.grid.build(RE_RATIO * L0)
    b = np.array([3.0e4, -1.2e4, 2.5e4][:dim])
    a = pressure_acceleration(sim, lattice, 2.0e3 + lattice @ b)
    deep = np.max(np.abs(ks), axis=1) * L0 <= m * L0 - 2 * RE_RATIO * L0 - 1e-12
    assert deep.sum() >= 1
    np.testing.assert_allclose(a[deep], np.broadcast_to(-b / RHO, a[deep].shape),
                               rtol=0, atol=(1e-9 if backend.is_f64() else 2e-3)
                               * np.linalg.norm(b) / RHO)


@pytest.mark.parametrize("changes", [{"wall_model": "plane"}, {"mirror_planes": (0,)}])
def test_corrected_form_refused_where_its_fabric_misses_neighbours(changes):
    """Its fabric sums particles only: the analytic floor's layers and a symmetry plane's
    images are not in it, so the form is refused there, naming the key."""
    numerics = with_values(Numerics(), pressure_gradient="corrected", **changes)
    with pytest.raises(ParameterError, match="pressure_gradient"):
        numerics.validate("test")
