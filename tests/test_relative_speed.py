"""The relative form of the Courant limit (``numerics.courant_speed: relative``):
the largest speed of a fluid particle relative to its non-dummy neighbours within re, walls at
rest, measured by the predictor's neighbour walk (core/terms.py), and the limits it feeds
(core/timestep.py).

Exact values: a block in uniform motion has no relative speed (every force of the step is
Galilean invariant); a lattice in simple shear u_x = gamma z has 2 gamma l0 (the farthest pair
along z within re = 2.1 l0 is 2 l0 apart); a fluid particle beside a wall particle at rest has
its own speed. A jittered lattice with wall and dummy particles is checked against the
definition written out in numpy over all pairs, with viscosity and surface tension on (as in
the crown scenes) and with neither (the walk then runs for the relative speed alone).
"""
import math

import numpy as np
import pytest

from crowndemo.core import DUMMY, FLUID, WALL, Numerics, Physics, Simulator
from crowndemo.core import timestep
from crowndemo.core.params import Model, ParameterError, with_values

L0 = 1.0e-3
RE = 2.1 * L0


def lattice(dim: int, side: int) -> np.ndarray:
    g = np.stack(np.meshgrid(*[np.arange(side)] * dim, indexing="ij"), -1).reshape(-1, dim)
    return g * L0


CAPACITY = 1024      # every scene here fits: one simulator (one compile) per set-up
_sims = {}


def simulator(dim: int, numerics=None, terms: str = "terms") -> Simulator:
    """A simulator with viscosity and surface tension ("terms") or neither ("alone"), no
    gravity, in a 2 m box; one per set-up (one compile)."""
    liquid = {} if terms == "terms" else {"nu": 0.0, "sigma": 0.0}
    phys = Physics(dim=dim, l0=L0, v_max=1.0, gravity=0.0, **liquid)
    num = numerics or Numerics(courant_speed="relative")
    key = (dim, num, terms)
    if key not in _sims:
        _sims[key] = Simulator(phys, num, CAPACITY)
        _sims[key].configure(phys, num, ([-1.0] * dim, [1.0] * dim))
    return _sims[key]


def relative_speed(pos, vel, kind, numerics=None, terms="terms") -> float:
    """Load the particles and measure by the predictor's walk."""
    sim = simulator(pos.shape[1], numerics, terms)
    sim.load(pos, vel, kind)
    sim.grid.build(sim.lattice.re)
    assert sim.predictor.measures_relative_speed and sim.predictor.needs_neighbours
    sim.predictor.forces()
    return sim.predictor.relative_speed()


def expected(pos, vel, kind) -> float:
    top = 0.0
    for i in np.flatnonzero(kind == FLUID):
        r = np.linalg.norm(pos - pos[i], axis=1)
        near = (r < RE) & (kind != DUMMY) & (np.arange(len(pos)) != i)
        u_j = np.where((kind[near] == FLUID)[:, None], vel[near], 0.0)
        if near.any():
            top = max(top, np.linalg.norm(u_j - vel[i], axis=1).max())
    return top


@pytest.mark.parametrize("dim", [2, 3])
def test_uniform_motion_has_no_relative_speed(dim):
    pos = lattice(dim, 10 if dim == 2 else 6)
    vel = np.tile(np.array([7.0, -3.0, 2.0][:dim]), (len(pos), 1))
    kind = np.full(len(pos), FLUID, np.int32)
    assert relative_speed(pos, vel, kind) == 0.0


@pytest.mark.parametrize("dim", [2, 3])
def test_simple_shear_gives_two_gamma_l0(dim):
    gamma = 1000.0                            # 1/s
    pos = lattice(dim, 10 if dim == 2 else 6)
    vel = np.zeros_like(pos)
    vel[:, 0] = gamma * pos[:, -1]
    kind = np.full(len(pos), FLUID, np.int32)
    assert relative_speed(pos, vel, kind) == pytest.approx(2.0 * gamma * L0, rel=1e-5)


def test_a_wall_particle_is_at_rest_and_a_dummy_does_not_count():
    pos = np.array([[0.0, 0.0], [0.0, -L0], [0.0, -2.0 * L0], [5 * L0, 0.0], [5 * L0, -L0]])
    kind = np.array([FLUID, WALL, DUMMY, FLUID, DUMMY], np.int32)
    vel = np.array([[3.0, 0.0], [0, 0], [0, 0], [9.0, 0.0], [0, 0]])
    # particle 0 beside a wall particle: 3 m/s; particle 3 has only a dummy within re
    assert relative_speed(pos, vel, kind) == pytest.approx(3.0, rel=1e-6)


# without viscosity and surface tension (no shipped preset) checked in 2D only: a 3D compile
# costs CI half a minute
@pytest.mark.parametrize("dim, terms", [(2, "terms"), (3, "terms"), (2, "alone")])
def test_jittered_lattice_matches_the_definition(dim, terms):
    rng = np.random.default_rng(11)
    pos = lattice(dim, 14 if dim == 2 else 7)
    pos = pos + rng.uniform(-0.3, 0.3, pos.shape) * L0
    kind = np.full(len(pos), FLUID, np.int32)
    kind[rng.choice(len(pos), len(pos) // 6, replace=False)] = WALL
    kind[rng.choice(len(pos), len(pos) // 6, replace=False)] = DUMMY
    vel = rng.normal(0.0, 2.0, pos.shape) * (kind == FLUID)[:, None]
    got = relative_speed(pos, vel, kind, terms=terms)
    assert got == pytest.approx(expected(pos, vel, kind), rel=1e-5)


@pytest.mark.parametrize("terms", ["terms", "alone"])
def test_the_plane_floor_is_at_rest(terms):
    numerics = Numerics(courant_speed="relative", wall_model="plane")
    kind = np.array([FLUID], np.int32)
    vel = np.array([[4.0, -1.0]])          # 2D: the floor is the plane y = 0
    near = relative_speed(np.array([[0.0, 0.5 * L0]]), vel, kind, numerics, terms)
    assert near == pytest.approx(math.sqrt(17.0), rel=1e-6)
    # an isolated particle higher than re above the floor's wall layer: no pair at all
    far = relative_speed(np.array([[0.0, 3.0 * L0]]), vel, kind, numerics, terms)
    assert far == 0.0


def test_a_step_in_uniform_motion_is_bound_by_the_approach_limit():
    """No relative speed, so the Courant limit is out of play and |u| dt = C_a l0 binds
    (c = 15 m/s: the acoustic limit l0 / c is longer, and |u| < c keeps the health check
    quiet). The walk runs for this alone."""
    sim = simulator(2, terms="alone")
    fast = Physics(dim=2, l0=L0, v_max=1.0, gravity=0.0, nu=0.0, sigma=0.0, sound_speed=15.0)
    base = sim.physics
    sim.configure(fast, sim.numerics)
    try:
        pos = lattice(2, 10)
        u = np.array([6.0, -8.0])                 # |u| = 10 m/s
        sim.load(pos, np.tile(u, (len(pos), 1)), np.full(len(pos), FLUID, np.int32))
        dt = sim.step()
    finally:
        sim.configure(base, sim.numerics)
    assert dt == pytest.approx(0.5 * L0 / 10.0, rel=1e-5)
    assert sim.stats.binding["approach"] == 1


def test_not_compiled_without_it():
    phys = Physics(dim=2, l0=L0, v_max=1.0, nu=0.0, sigma=0.0)
    sim = Simulator(phys, Numerics(collision=0.0), 100)
    assert not sim.predictor.measures_relative_speed and not sim.predictor.needs_neighbours
    assert sim.predictor.rel2 is None
    assert not Model.of(phys, Numerics()).relative_courant


def test_limits_with_the_relative_speed():
    phys = Physics(dim=3, l0=L0, v_max=8.0)
    rel = Numerics(courant_speed="relative")
    model = Model.of(phys, rel)
    lim = timestep.limits(phys, rel, model, speed=20.0, relative_speed=5.0)
    assert lim["courant"] == pytest.approx(0.2 * L0 / 5.0)
    assert lim["approach"] == pytest.approx(0.5 * L0 / 20.0)
    # not measured yet (before the first step): the speed bounds the relative speed
    assert timestep.limits(phys, rel, model, 20.0)["courant"] == pytest.approx(0.2 * L0 / 20.0)
    seed = Numerics()
    lim = timestep.limits(phys, seed, Model.of(phys, seed), speed=20.0, relative_speed=5.0)
    assert lim["courant"] == pytest.approx(0.2 * L0 / 20.0) and "approach" not in lim
    with pytest.raises(ParameterError, match="courant_speed"):
        with_values(seed, courant_speed="both").validate()
