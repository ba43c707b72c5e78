"""The step's own kernels, not the stand-alone operators of test_operators.py, against exact
values on a perfect cubic lattice (method.md §2-§3): the number density and equation of state
of the density pass (S9, S17, M3), the pressure-gradient corrector in each form (S18-S20, M2),
and the predictor's viscosity and gravity with its velocity and position updates (S14-S16).

Why exact: an interior particle's neighbourhood has the lattice's full symmetry, so
sum_j r_ij w / r^2 = 0 and sum_j (b.r_ij) r_ij w / r^2 = (n0/d) b, sum_j w x_ij^2 = lambda0 n0/d
(test_operators.py). Hence for P = P0 + b.x every form of (M2) gives grad P = b: P_ref (P_i,
Pmin_i or -P_i) multiplies sum_j r_ij w / r^2 = 0. And for u = (z^2, 0, ..) the Laplacian
model (S12) gives (2, 0, ..). Tolerances are float rounding: sums of 12-120 terms in f32.
"""
import itertools
import math

import numpy as np
import pytest

from crowndemo import backend
from crowndemo.core import FLUID, Numerics, Physics, Simulator
from crowndemo.core.lattice import n0_lambda0
from crowndemo.core.params import with_values

L0 = 2.0 ** -9            # ~1.95 mm, exact in binary
RE_RATIO = 2.1
HALF = {2: 7, 3: 5}        # lattice indices -HALF..HALF per axis
RHO, C, NU, G = 998.0, 20.0, 1.0e-3, 9.81


def rtol() -> float:
    return 1e-12 if backend.is_f64() else 2e-5   # f32: ~100 terms of 2^-24 each, at most


class Lattice:
    """A block of fluid particles on the lattice k s l0 (s: a uniform compression or
    stretch) in a simulator whose l0, n0 and lambda0 are those of spacing l0."""

    def __init__(self, dim: int, scale: float = 1.0, gradient: str = "pmin",
                 gravity: float = 0.0, nu: float = 0.0):
        m = HALF[dim]
        self.dim = dim
        self.ks = np.array(list(itertools.product(range(-m, m + 1), repeat=dim)), dtype=float)
        self.pos = self.ks * L0 * scale
        self.re = RE_RATIO * L0
        # a full neighbourhood: at least re from the block's edge
        self.interior = np.max(np.abs(self.ks), axis=1) * scale * L0 <= (m * scale * L0
                                                                         - self.re - 1e-12)
        self.physics = Physics(dim=dim, l0=L0, v_max=C / 5.0, re_ratio=RE_RATIO, rho=RHO,
                               nu=nu, sigma=0.0, gravity=gravity, sound_speed=C)
        self.numerics = with_values(Numerics(), pressure_gradient=gradient)
        n = len(self.pos)
        self.sim = Simulator(self.physics, self.numerics, n)
        self.sim.configure(self.physics, self.numerics, (tuple([-1.0] * dim),
                                                         tuple([1.0] * dim)))
        self.n = n
        self.n0, self.lambda0 = n0_lambda0(dim, L0, self.re)
        self.fdt = np.float64 if backend.is_f64() else np.float32

    def load(self, vel=None) -> None:
        vel = np.zeros_like(self.pos) if vel is None else vel
        self.sim.load(self.pos, vel, np.full(self.n, FLUID, dtype=np.int32))
        self.sim.grid.build(self.re)          # no re-sort: field index i = i-th particle

    def field(self, f) -> np.ndarray:
        return f.to_numpy()[: self.n].astype(float)

    def set_pressure(self, p: np.ndarray) -> None:
        full = np.zeros(self.sim.state.capacity, dtype=self.fdt)
        full[: self.n] = p
        self.sim.state.pressure.from_numpy(full)


def lattice_number_density(dim: int, spacing: float, re: float) -> float:
    """(S9) at an interior particle of the lattice of the given spacing, summed here."""
    reach = int(re / spacing) + 1
    n = 0.0
    for k in itertools.product(range(-reach, reach + 1), repeat=dim):
        r = spacing * math.sqrt(sum(c * c for c in k))
        if 0.0 < r < re:
            n += re / r - 1.0
    return n


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("scale", [0.97, 1.0, 1.03])
def test_density_pass_gives_the_equation_of_state(dim, scale):
    """The density pass (S9 in the step's kernel) and P = c^2 rho (n - n0)/n0 (S17), clamped
    at 0 (a stretched lattice, n < n0, has P = 0; so does the block's surface layer)."""
    lat = Lattice(dim, scale)
    lat.load()
    lat.sim.pressure.density_and_pressure()
    n = lat.field(lat.sim.state.density)
    p = lat.field(lat.sim.state.pressure)
    n_ref = lattice_number_density(dim, scale * L0, lat.re)
    if scale == 1.0:
        assert n_ref == pytest.approx(lat.n0, rel=1e-12)      # the lattice n0 is made of
    else:
        assert (n_ref > lat.n0) == (scale < 1.0)
    np.testing.assert_allclose(n[lat.interior], n_ref, rtol=rtol())
    p_ref = max(C * C * RHO * (n_ref - lat.n0) / lat.n0, 0.0)
    if scale < 1.0:
        assert p_ref > 1e3                     # 3 % compression: kPa, not rounding
        np.testing.assert_allclose(p[lat.interior], p_ref, rtol=rtol() * lat.n0 /
                                   (n_ref - lat.n0))   # n - n0 loses digits of n
    else:                                      # n0 itself rounds to P of a few mPa
        assert np.all(np.abs(p[lat.interior]) <= C * C * RHO * rtol())
    outer = np.max(np.abs(lat.ks), axis=1) == HALF[dim]
    assert np.all(p[outer] == 0.0)             # the surface layer: n < n0, clamped (S17)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("gradient", ["seed", "pmin", "sum"])
def test_corrector_forms_match_a_direct_sum_where_they_differ(dim, gradient):
    """At the block's edge i's neighbourhood is cut, sum_j r_ij w / r^2 != 0, and the forms of
    (M2) part: a' = -(1/rho)(d/n0) sum_j (P_j - P_ref) r_ij w / r^2 (S11, S18), P_ref = P_i
    (seed), min(P_i, P_j over the neighbours) (pmin) or -P_i (sum). Every particle's a' against
    that sum done here in numpy over the lattice's pairs within re (the linear-pressure test
    above cannot tell the forms apart: there P_ref multiplies zero)."""
    lat = Lattice(dim, gradient=gradient)
    lat.load()
    lat.sim.pressure.density_and_pressure()      # the neighbour list at these positions
    b = np.array([3.0e4, -1.2e4, 2.5e4][:dim])
    p = 2.0e3 + lat.pos @ b
    lat.set_pressure(p)
    lat.sim.pressure.correct(1.0e-3)
    a = lat.field(lat.sim.state.scratch_vec)

    rij = lat.pos[None, :, :] - lat.pos[:, None, :]          # r_j - r_i, [i, j]
    r2 = (rij * rij).sum(axis=2)
    near = (r2 > 0.0) & (r2 < lat.re ** 2)
    r2 = np.where(near, r2, 1.0)
    g = rij * np.where(near, (lat.re / np.sqrt(r2) - 1.0) / r2, 0.0)[:, :, None]
    p_ref = {"seed": p, "sum": -p,
             "pmin": np.minimum(p, np.where(near, p[None, :], np.inf).min(axis=1))}[gradient]
    factor = -dim / (lat.n0 * RHO)
    expect = factor * ((p[None, :, None] * g).sum(axis=1) - p_ref[:, None] * g.sum(axis=1))
    edge = np.abs(g.sum(axis=1)).max(axis=1) > 1.0        # where the forms differ
    assert edge.sum() > 0.2 * lat.n
    # f32: terms of size P g rounded at 2^-24, ~100 of them per particle
    scale = abs(factor) * (np.abs(p)[None, :, None] * np.abs(g)).sum(axis=1).max()
    np.testing.assert_allclose(a, expect, rtol=0, atol=rtol() * scale)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("gradient", ["seed", "pmin", "sum"])
def test_corrector_of_a_linear_pressure_is_exact(dim, gradient):
    """P = P0 + b.x: a' = -b/rho in every form (S18); u += dt a' (S19), r += dt^2 a' (S20)."""
    lat = Lattice(dim, gradient=gradient)
    lat.load()
    lat.sim.pressure.density_and_pressure()      # the neighbour list at these positions
    b = np.array([3.0e4, -1.2e4, 2.5e4][:dim])   # Pa/m: ~400 Pa across the block
    lat.set_pressure(2.0e3 + lat.pos @ b)
    dt = 1.0e-3                                   # dt^2 a' ~ 4e-5 m: well above f32's ulp
    lat.sim.pressure.correct(dt)
    a = lat.field(lat.sim.state.scratch_vec)[lat.interior]
    a_ref = -b / RHO
    scale = np.linalg.norm(a_ref)
    # P_ref multiplies sum r_ij w / r^2, zero up to rounding of terms ~ P0 w / r: |P0/b| / l0
    # times the rounding of the others
    tol = rtol() * scale * (1.0 + 2.0e3 / np.linalg.norm(b) / L0)
    assert np.abs(a - a_ref).max() <= tol
    u = lat.field(lat.sim.state.vel)[lat.interior]
    np.testing.assert_allclose(u, dt * a, rtol=rtol(), atol=rtol() * dt * scale)
    moved = lat.field(lat.sim.state.pos)[lat.interior] - lat.pos[lat.interior]
    # positions round at their own size (f32: ~1e-9 m here)
    np.testing.assert_allclose(moved, dt * dt * a, rtol=0, atol=rtol() * np.abs(lat.pos).max())


@pytest.mark.parametrize("dim", [2, 3])
def test_predictor_viscosity_gravity_and_updates(dim):
    """u = (z^2, 0, ..): a* = nu <lap u> + g = (2 nu, 0, .., -g) (S14 with S12); then
    u* = u + dt a* (S15) and r* = r + dt u* (S16)."""
    lat = Lattice(dim, gravity=G, nu=NU)
    vel = np.zeros_like(lat.pos)
    vel[:, 0] = (lat.pos[:, -1] / L0) ** 2 * 1e-3       # m/s; d2u/dz2 = 2e-3 / l0^2
    lat.load(vel)
    lat.sim.predictor.forces()
    a = lat.field(lat.sim.state.scratch_vec)[lat.interior]
    a_ref = np.zeros(dim)
    a_ref[0] = NU * 2.0e-3 / L0 ** 2
    a_ref[-1] = -G
    scale = np.linalg.norm(a_ref)
    # the Laplacian's sum of (u_j - u_i) w rounds at u's size, ~ (HALF l0 / l0)^2 1e-3 m/s
    tol = rtol() * NU * 2.0e-3 / L0 ** 2 * HALF[dim] ** 2
    assert np.abs(a - a_ref).max() <= tol + rtol() * scale
    dt = 1.0e-3
    lat.sim.predictor.run(dt)            # the lattice has no pair under the collision distance
    u_star = lat.field(lat.sim.state.vel)[lat.interior]
    np.testing.assert_allclose(u_star, vel[lat.interior] + dt * a, rtol=rtol(),
                               atol=rtol() * dt * scale)
    moved = lat.field(lat.sim.state.pos)[lat.interior] - lat.pos[lat.interior]
    np.testing.assert_allclose(moved, dt * u_star, rtol=0, atol=rtol() * np.abs(lat.pos).max())
