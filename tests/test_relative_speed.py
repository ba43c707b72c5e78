"""The relative form of the Courant limit (``numerics.courant_speed: relative``):
the largest speed of a fluid particle relative to its non-dummy neighbours within re, walls at
rest (core/relative_speed.py), and the limits it feeds (core/timestep.py).

Exact values: a block in uniform motion has no relative speed (every force of the step is
Galilean invariant); a lattice in simple shear u_x = gamma z has 2 gamma l0 (the farthest pair
along z within re = 2.1 l0 is 2 l0 apart); a fluid particle beside a wall particle at rest has
its own speed. A jittered lattice with wall and dummy particles is checked against the
definition written out in numpy over all pairs, as the predictor's walk measures it (viscosity
or surface tension on) and as the pass of its own does (through the neighbour list, the cell
walk, a list too short) alike.
"""
import math

import numpy as np
import pytest

from crowndemo.core import DUMMY, FLUID, WALL, Numerics, Physics, Simulator, neighbours
from crowndemo.core import timestep
from crowndemo.core.params import Model, ParameterError, with_values

L0 = 1.0e-3
RE = 2.1 * L0


def lattice(dim: int, side: int) -> np.ndarray:
    g = np.stack(np.meshgrid(*[np.arange(side)] * dim, indexing="ij"), -1).reshape(-1, dim)
    return g * L0


CAPACITY = 1024      # every scene here fits: one simulator (one compile) per set-up
_sims = {}


def relative_speed(pos, vel, kind, numerics=None, path="predictor") -> float:
    """Load the particles and measure: by the predictor's walk (viscosity and surface tension
    on, as in the crown scenes), or by the pass of its own (neither on) after the density
    pass has listed the neighbours."""
    dim = pos.shape[1]
    liquid = {} if path == "predictor" else {"nu": 0.0, "sigma": 0.0}
    phys = Physics(dim=dim, l0=L0, v_max=1.0, gravity=0.0, **liquid)
    num = numerics or Numerics(courant_speed="relative")
    key = (dim, num, path, neighbours.SLOTS[dim])
    if key not in _sims:
        _sims[key] = Simulator(phys, num, CAPACITY)
        _sims[key].configure(phys, num, ([-1.0] * dim, [1.0] * dim))
    sim = _sims[key]
    sim.load(pos, vel, kind)
    sim.grid.build(sim.lattice.re)
    if path == "predictor":
        assert sim.predictor.measures_relative_speed and sim.relative_speed is None
        sim.predictor.forces()
        return sim.predictor.relative_speed()
    assert not sim.predictor.measures_relative_speed
    sim.pressure.density_and_pressure()
    return sim.relative_speed.measure()


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


# the pass of its own serves models without viscosity and surface tension (no shipped preset):
# checked in 2D, where its three ways compile in seconds; the predictor's walk in 2D and 3D
@pytest.mark.parametrize("dim, how", [(2, "predictor"), (3, "predictor"), (2, "list"),
                                      (2, "walk"), (2, "short list")])
def test_jittered_lattice_matches_the_definition(dim, how, monkeypatch):
    rng = np.random.default_rng(11)
    pos = lattice(dim, 14 if dim == 2 else 7)
    pos = pos + rng.uniform(-0.3, 0.3, pos.shape) * L0
    kind = np.full(len(pos), FLUID, np.int32)
    kind[rng.choice(len(pos), len(pos) // 6, replace=False)] = WALL
    kind[rng.choice(len(pos), len(pos) // 6, replace=False)] = DUMMY
    vel = rng.normal(0.0, 2.0, pos.shape) * (kind == FLUID)[:, None]
    numerics = Numerics(courant_speed="relative", neighbour_list=how != "walk")
    if how == "short list":
        monkeypatch.setitem(neighbours.SLOTS, dim, 3)    # most particles walk the cells
    got = relative_speed(pos, vel, kind, numerics, "predictor" if how == "predictor" else "pass")
    assert got == pytest.approx(expected(pos, vel, kind), rel=1e-5)


@pytest.mark.parametrize("path", ["predictor", "pass"])
def test_the_plane_floor_is_at_rest(path):
    numerics = Numerics(courant_speed="relative", wall_model="plane")
    kind = np.array([FLUID], np.int32)
    vel = np.array([[4.0, -1.0]])          # 2D: the floor is the plane y = 0
    near = relative_speed(np.array([[0.0, 0.5 * L0]]), vel, kind, numerics, path)
    assert near == pytest.approx(math.sqrt(17.0), rel=1e-6)
    # an isolated particle higher than re above the floor's wall layer: no pair at all
    far = relative_speed(np.array([[0.0, 3.0 * L0]]), vel, kind, numerics, path)
    assert far == 0.0


def test_not_compiled_without_it():
    phys = Physics(dim=2, l0=L0, v_max=1.0)
    sim = Simulator(phys, Numerics(), 100)
    assert sim.relative_speed is None and not sim.predictor.measures_relative_speed
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
