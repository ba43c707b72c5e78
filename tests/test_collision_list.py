"""The collision model (core/terms.py) on the close pairs that the viscosity and surface-tension
walk lists, against the model written out in numpy over all pairs.

When viscosity or surface tension is on, the predictor's neighbour walk lists each fluid
particle's pairs closer than the collision distance and the collision pass uses that list; a
particle with more than CLOSE_SLOTS such pairs walks the cells instead. The expected values
are the model itself (Koshizuka et al. 1998): for each fluid i, over every j (fluid, wall or
dummy) closer than collision * l0 and approaching (vn = (u_j - u_i).r_ij / r < 0),
du_i = share (1 + e) vn r_ij / r, share = 1/2 against fluid (u_j = u*_j) and 1 against a
wall or dummy (u_j = 0), all from the u* of before the pass (Jacobi).
"""

import numpy as np
import pytest

from crowndemo.core import DUMMY, FLUID, WALL, Numerics, Physics, Simulator
from crowndemo.core.terms import CLOSE_SLOTS

L0 = 1.0e-3


def expected_collisions(pos, u, kind, col_r, e):
    du = np.zeros_like(u)
    for i in np.flatnonzero(kind == FLUID):
        rij = pos - pos[i]
        r = np.linalg.norm(rij, axis=1)
        near = (r < col_r) & (np.arange(len(pos)) != i)
        for j in np.flatnonzero(near):
            u_j = u[j] if kind[j] == FLUID else np.zeros(pos.shape[1])
            vn = (u_j - u[i]) @ rij[j] / r[j]
            if vn < 0:
                share = 0.5 if kind[j] == FLUID else 1.0
                du[i] += share * (1 + e) * vn / r[j] * rij[j]
    return u + du * (kind == FLUID)[:, None]


@pytest.mark.parametrize("dim", [2, 3])
def test_listed_close_pairs_collide_as_the_model(dim):
    rng = np.random.default_rng(7)
    # a jittered lattice (many pairs under 0.5 l0), a tight cluster of CLOSE_SLOTS + 3
    # particles (more close pairs than the list holds: those walk the cells), and wall and
    # dummy particles among the fluid
    side = 8 if dim == 3 else 20
    grid = np.stack(np.meshgrid(*[np.arange(side)] * dim, indexing="ij"), -1).reshape(-1, dim)
    pos = grid * L0 + rng.uniform(-0.45, 0.45, grid.shape) * L0
    cluster = np.full((CLOSE_SLOTS + 3, dim), 0.5 * side * L0) + rng.uniform(
        -0.15, 0.15, (CLOSE_SLOTS + 3, dim)) * L0
    pos = np.concatenate([pos, cluster])
    kind = np.full(len(pos), FLUID, np.int32)
    kind[rng.choice(len(grid), len(grid) // 8, replace=False)] = WALL
    kind[rng.choice(len(grid), len(grid) // 8, replace=False)] = DUMMY
    vel = rng.normal(0.0, 0.3, pos.shape) * (kind == FLUID)[:, None]

    phys = Physics(dim=dim, l0=L0, v_max=1.0, nu=1.0e-6, sigma=0.0728, gravity=0.0)
    num = Numerics(collision=0.5, restitution=0.2)
    sim = Simulator(phys, num, len(pos))
    assert sim.predictor.lists_close_pairs
    sim.configure(phys, num, ([-0.1] * dim, [0.1] * dim))
    sim.load(pos, vel, kind)
    # the predictor's two passes, by hand: u* (viscosity and surface tension), then collisions
    sim.grid.build(sim.lattice.re, reorder=False)
    sim.predictor.forces()
    sim.predictor.accelerate(1.0e-5)
    u_star = sim.state.vel.to_numpy()[: len(pos)].astype(float)
    counts = sim.predictor.close_count.to_numpy()[: len(pos)]
    assert counts.max() > CLOSE_SLOTS                       # some particles walk the cells
    assert ((counts > 0) & (counts <= CLOSE_SLOTS)).sum() > 10   # and many use the list
    sim.predictor.collide()
    got = sim.state.vel.to_numpy()[: len(pos)]
    want = expected_collisions(pos.astype(np.float32).astype(float), u_star, kind, 0.5 * L0, 0.2)
    changed = np.linalg.norm(want - u_star, axis=1) > 1e-6
    assert changed.sum() > 10
    np.testing.assert_allclose(got, want, rtol=0, atol=2e-6)
