"""The local and bulk density excess (validate/density.py) on constructed particle sets whose
answer is known exactly: a cube of particles whose outer layer is free surface (n < beta n0,
M3), a bulk compressed uniformly and a few clumped particles."""
import numpy as np
import pytest

from crowndemo.validate.density import density_excess, interior_mask

L0, N0, BETA = 1.0e-4, 30.0, 0.98
RE = 2.1 * L0
N = 14                    # particles along each edge


def cube():
    idx = np.stack(np.meshgrid(*[np.arange(N)] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    return idx, (idx + 0.5) * L0


def test_interior_is_beyond_re_of_the_free_surface():
    """Surface = the outer layer; particles within re = 2.1 l0 of it are layers 1 and 2: the
    interior is the cube of layers 3 .. N-4, (N - 6)^3 particles."""
    idx, pos = cube()
    outer = np.any((idx == 0) | (idx == N - 1), axis=1)
    n = np.where(outer, 0.6 * N0, N0)
    inside = interior_mask(pos, n, N0, RE, BETA)
    expect = np.all((idx >= 3) & (idx <= N - 4), axis=1)
    assert np.array_equal(inside, expect) and inside.sum() == (N - 6) ** 3


def test_a_few_clumped_particles_set_the_local_excess_not_the_bulk():
    """The interior compressed by 1 % with 3 particles clumped to 30 %: the local excess is
    0.30; the bulk (99th percentile over 512 interior particles, 3 of them high, below 1 %)
    is 0.01."""
    idx, pos = cube()
    outer = np.any((idx == 0) | (idx == N - 1), axis=1)
    inside = np.all((idx >= 3) & (idx <= N - 4), axis=1)
    n = np.where(outer, 0.6 * N0, 1.01 * N0)
    clumped = np.flatnonzero(inside)[[10, 200, 400]]
    n[clumped] = 1.30 * N0
    d = density_excess(pos, n, N0, RE, BETA)
    assert d.interior == (N - 6) ** 3 == 512 and d.fluid == N ** 3
    assert d.local == pytest.approx(0.30, rel=1e-12)
    assert d.bulk == pytest.approx(0.01, rel=1e-9)
    assert d.bulk_mean == pytest.approx((509 * 0.01 + 3 * 0.30) / 512, rel=1e-9)
    # a layer compressed by 20 % lies in the bulk figure when it holds over 1 % of it
    n[inside & (idx[:, 0] == 3)] = 1.20 * N0            # 64 of 512 interior particles
    assert density_excess(pos, n, N0, RE, BETA).bulk == pytest.approx(0.20, rel=1e-9)
