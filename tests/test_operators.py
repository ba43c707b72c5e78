"""MPS operators on a perfect cubic lattice (method.md §2, S9-S13).

On a cubic lattice the neighbourhood of an interior particle has the full cubic symmetry, so
for any weight w(r):
  - sum_j w r_ij r_ij^T / r^2 = (n0/d) I     => (S11) of a.r is exactly a;
  - sum_j w r_ij = 0, sum_j w |r_ij|^2 = lambda0 n0, sum_j w x_ij^2 = lambda0 n0 / d
                                             => (S12) of |r|^2 is exactly 2d, of x^2 exactly 2.
These are exact identities, so the tolerances below are float-rounding sized. The spacing is a
power of two and the lattice is centred on the origin, so positions and the quadratic fields
are exact in f32; only the weights and the sums round.
"""
import itertools
import math

import numpy as np
import pytest
import taichi as ti

from crowndemo import backend
from crowndemo.core import FLUID, Numerics, Physics, Simulator
from crowndemo.core.lattice import n0_lambda0

L0 = 2.0 ** -9          # ~1.95 mm, exact in binary
RE_RATIO = 2.1
HALF = {2: 7, 3: 5}      # lattice indices -HALF..HALF per axis: 15^2 = 225, 11^3 = 1331 particles


def rtol() -> float:
    return 1e-13 if backend.is_f64() else 4e-6   # measured: a few ulps (<5e-7 in f32)


# ---- independent brute-force lattice sums ----------------------------------------------------
def brute_n0_lambda0(dim: int, l0: float, re: float):
    """n0 = sum w(|k l0|), lambda0 = sum |k l0|^2 w / n0 over integer k != 0 (S9, S13)."""
    reach = int(re / l0) + 2
    n0 = 0.0
    second = 0.0
    for k in itertools.product(range(-reach, reach + 1), repeat=dim):
        if all(c == 0 for c in k):
            continue
        r = l0 * math.sqrt(sum(c * c for c in k))
        if r < re:
            w = re / r - 1.0
            n0 += w
            second += r * r * w
    return n0, second / n0


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("re_ratio", [1.5, 2.1, 3.1, 4.0])
@pytest.mark.parametrize("l0", [1.0, 1.0e-3])
def test_n0_lambda0_match_brute_force(dim, re_ratio, l0):
    re = re_ratio * l0
    n0, lam = n0_lambda0(dim, l0, re)
    n0_ref, lam_ref = brute_n0_lambda0(dim, l0, re)
    assert n0 == pytest.approx(n0_ref, rel=1e-12)
    assert lam == pytest.approx(lam_ref, rel=1e-12)


def test_n0_lambda0_closed_form_2d():
    """2D, re = 2.1 l0: neighbours at l0 (4), sqrt2 l0 (4), 2 l0 (4)."""
    l0, re = 1.0e-3, 2.1e-3
    ws = {1.0: 2.1 - 1.0, math.sqrt(2.0): 2.1 / math.sqrt(2.0) - 1.0, 2.0: 2.1 / 2.0 - 1.0}
    n0_ref = 4.0 * sum(ws.values())
    lam_ref = 4.0 * sum(r * r * w for r, w in ws.items()) * l0 ** 2 / n0_ref
    n0, lam = n0_lambda0(2, l0, re)
    assert n0 == pytest.approx(n0_ref, rel=1e-12)
    assert lam == pytest.approx(lam_ref, rel=1e-12)


# ---- the operators on a lattice --------------------------------------------------------------
class LatticeCase:
    def __init__(self, dim: int):
        m = HALF[dim]
        ks = np.array(list(itertools.product(range(-m, m + 1), repeat=dim)), dtype=np.int64)
        self.dim, self.ks = dim, ks
        self.pos = ks.astype(np.float64) * L0
        self.re = RE_RATIO * L0
        # at least re from the lattice edge: m - |k|_inf >= re/l0 -> |k|_inf <= m - 3
        self.interior = np.max(np.abs(ks), axis=1) <= m - math.ceil(RE_RATIO)
        physics = Physics(dim=dim, l0=L0, v_max=1.0, re_ratio=RE_RATIO, nu=0.0, sigma=0.0,
                          gravity=0.0)
        numerics = Numerics()
        n = len(self.pos)
        self.sim = Simulator(physics, numerics, n)
        self.sim.configure(physics, numerics, (tuple([-1.0] * dim), tuple([1.0] * dim)))
        self.sim.load(self.pos, np.zeros_like(self.pos), np.full(n, FLUID, dtype=np.int32))
        self.sim.grid.build(self.re)          # reorder=False: field index i = i-th particle
        self.n = n
        self.phi = ti.field(float, n)
        self.out_s = ti.field(float, n)
        self.out_v = ti.Vector.field(dim, float, n)
        self.n0, self.lambda0 = n0_lambda0(dim, L0, self.re)

    def set_phi(self, values: np.ndarray) -> None:
        fdt = np.float64 if backend.is_f64() else np.float32
        self.phi.from_numpy(np.asarray(values, dtype=fdt))


@pytest.fixture(scope="module", params=[2, 3], ids=["2d", "3d"])
def case(request):
    return LatticeCase(request.param)


def test_order_kept(case):
    """Without reorder the field index is the load order (what the other tests rely on)."""
    np.testing.assert_array_equal(case.sim.state.pid.to_numpy()[:case.n], np.arange(case.n))
    np.testing.assert_array_equal(case.sim.state.pos.to_numpy()[:case.n],
                                  case.pos.astype(case.sim.state.pos.to_numpy().dtype))


def test_number_density_interior_is_n0(case):
    case.sim.operators.number_density(case.out_s)
    n = case.out_s.to_numpy()
    assert case.interior.sum() > 0
    np.testing.assert_allclose(n[case.interior], case.n0, rtol=rtol(), atol=0)


def test_number_density_all_particles_brute_force(case):
    """Every particle, edges included: (S9) summed in numpy over all pairs."""
    case.sim.operators.number_density(case.out_s)
    n = case.out_s.to_numpy()
    diff = case.pos[None, :, :] - case.pos[:, None, :]
    r = np.sqrt((diff ** 2).sum(axis=2))
    w = np.where((r > 0) & (r < case.re), case.re / np.where(r > 0, r, 1.0) - 1.0, 0.0)
    ref = w.sum(axis=1)
    np.testing.assert_allclose(n, ref, rtol=rtol(), atol=0)
    outer = np.max(np.abs(case.ks), axis=1) == HALF[case.dim]
    assert np.all(ref[outer] < 0.9 * case.n0)   # sanity: the outer layer is deficient


@pytest.mark.parametrize("a", [(1.3, -0.7, 2.1), (0.0, 0.0, -5.0), (1.0, 0.0, 0.0)])
def test_gradient_of_linear_field_is_exact(case, a):
    a = np.array(a[:case.dim], dtype=float)
    case.set_phi(case.pos @ a)
    case.sim.operators.gradient(case.phi, case.out_v)
    g = case.out_v.to_numpy()[case.interior]
    err = np.abs(g - a[None, :]).max()
    assert err <= rtol() * np.linalg.norm(a), (err, g[:3])


def test_gradient_of_constant_is_zero(case):
    case.set_phi(np.full(case.n, 3.25))
    case.sim.operators.gradient(case.phi, case.out_v)
    assert np.all(case.out_v.to_numpy() == 0.0)      # phi_j - phi_i is exactly 0


def test_laplacian_of_r2_is_2d(case):
    case.set_phi((case.pos ** 2).sum(axis=1))
    case.sim.operators.laplacian(case.phi, case.out_s)
    lap = case.out_s.to_numpy()[case.interior]
    np.testing.assert_allclose(lap, 2.0 * case.dim, rtol=rtol(), atol=0)


@pytest.mark.parametrize("axis", [0, -1])
def test_laplacian_of_x2_is_2(case, axis):
    case.set_phi(case.pos[:, axis] ** 2)
    case.sim.operators.laplacian(case.phi, case.out_s)
    lap = case.out_s.to_numpy()[case.interior]
    np.testing.assert_allclose(lap, 2.0, rtol=rtol(), atol=0)


def test_laplacian_of_linear_field_is_zero(case):
    a = np.array([1.3, -0.7, 2.1][:case.dim])
    case.set_phi(case.pos @ a)
    case.sim.operators.laplacian(case.phi, case.out_s)
    lap = case.out_s.to_numpy()[case.interior]
    # scale: one term of the sum is ~ |a| l0 w, times 2d/(lambda0 n0) ~ 2d/(l0^2 n0)
    scale = np.linalg.norm(a) / L0
    assert np.abs(lap).max() <= rtol() * scale
