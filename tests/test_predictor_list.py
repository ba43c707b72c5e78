"""The predictor's pairs from the density pass's list (``numerics.predictor_list``,
core/terms.py): after a step, the predictor's accelerations (S12, S14, S22) summed over the
listed pairs at the corrector's new positions equal those of a cell walk at those positions
minus exactly the pairs the corrector's move brought within re. Those pairs are written out
in numpy (the viscosity and potential terms, method.md S12 and S22) and each lies within the
move, dt^2 |a'_i - a'_j| (S20), of re. The collision model's pairs, dummy particles included,
are the walk's. A particle with an incomplete list, and the first step
after a load or an output refresh, walk the cells."""
import numpy as np
import pytest

from crowndemo import backend
from crowndemo.core import DUMMY, FLUID, GONE, Numerics, simulator_for
from crowndemo.core.params import with_values
from crowndemo.scenes import dam_break
from crowndemo.scenes.crown import crown

STEPS = 30


@pytest.fixture(scope="module")
def single_thread():
    backend.init("cpu", seed=1, single_thread=True)
    yield
    backend.init("cpu")


def scenes(dim):
    """A dam break (wall and dummy particles) and a small crown as a quarter on the plane
    floor (mirror images), both with viscosity, surface tension and collisions."""
    dam = dam_break(dim=dim, a=0.02 if dim == 2 else 0.01, l0=2e-3 if dim == 2 else 1e-3,
                    t_end=1.0)
    dam.physics = with_values(dam.physics, sigma=0.0728)
    yield "dam", dam
    if dim == 3:
        c = crown(dim=3, l0=4e-4, film=1.2e-3, drop=4e-3, speed=8.0, gap=4e-4, t_end=4e-4,
                  floor=0.02, symmetry="quarter",
                  numerics=Numerics(wall_model="plane", courant_speed="relative"))
        yield "crown", c


def predictor_accelerations(sim, from_list: bool) -> np.ndarray:
    """a* of the simulated particles (not their mirror images)."""
    sim.predictor.forces(from_list)
    return sim.state.scratch_vec.to_numpy()[: sim.state.count].astype(float)


def close_pairs(sim) -> set:
    """What the last ``forces`` listed for the collision model: per fluid particle its count
    of pairs closer than the collision distance and, where the list holds them all, which."""
    m = sim.state.count
    count = sim.predictor.close_count.to_numpy()[:m]
    index = sim.predictor.close_index.to_numpy()[:m]
    kind = sim.state.kind.to_numpy()[:m]
    slots = index.shape[1]
    return {(i, int(count[i]), frozenset(index[i, : count[i]].tolist())
             if count[i] <= slots else None) for i in np.flatnonzero(kind == FLUID)}


def missed_pair_terms(sim, pos, vel, kind, listed) -> tuple:
    """Per fluid particle, the sum of the predictor's terms over the pairs within re at
    ``pos`` that ``listed`` (a set of (i, j)) lacks, and the least re - r of those pairs
    (inf: none)."""
    c = sim.coef
    re, l0, dim = float(c.re[None]), float(c.l0[None]), sim.state.dim
    visc = float(c.nu[None]) * 2 * dim / (float(c.lambda0[None]) * float(c.n0[None]))
    st = float(c.st_over_m[None])
    terms = np.zeros_like(pos)
    nearest = np.inf
    for i in np.flatnonzero(kind[: sim.state.count] == FLUID):
        rij = pos - pos[i]
        r = np.linalg.norm(rij, axis=1)
        for j in np.flatnonzero((r < re) & (r > 0) & (kind != GONE)):
            if (i, j) in listed or kind[j] == DUMMY:
                continue
            nearest = min(nearest, re - r[j])
            if sim.model.viscosity:
                terms[i] += visc * (vel[j] - vel[i]) * (re / r[j] - 1.0)
            if sim.model.surface_tension and kind[j] == FLUID:
                terms[i] += st * (r[j] - l0) * (r[j] - re) / r[j] * rij[j]
    return terms, nearest


@pytest.mark.parametrize("dim", [2, pytest.param(3, marks=pytest.mark.slow)])   # 3D: a minute
def test_listed_pairs_are_the_walk_less_the_pairs_moved_into_range(single_thread, dim):
    for name, scene in scenes(dim):
        sim = simulator_for(scene)
        assert sim.predictor.takes_list, name
        for _ in range(STEPS):
            sim.step()
        assert sim._lists_ready, name            # this state's next predictor takes the list
        n = sim.state.count + int(sim.state.n_images[None])
        pos = sim.state.pos.to_numpy()[:n].astype(float)
        vel = sim.state.vel.to_numpy()[:n].astype(float)
        kind = sim.state.kind.to_numpy()[:n]
        # the corrector's move of the last step: dt^2 a' (scratch_vec holds a', S18-S20)
        a_corr = sim.state.scratch_vec.to_numpy()[:n].astype(float)
        dt = sim.stats.dt_log[-1]
        move = 2 * dt * dt * np.linalg.norm(a_corr[kind == FLUID], axis=1).max()
        count = sim.pressure.neighbours.count.to_numpy()[:n]
        index = sim.pressure.neighbours.index.to_numpy()[:n]
        listed = {(i, int(j)) for i in np.flatnonzero(kind[: sim.state.count] == FLUID)
                  for j in index[i, : count[i]]}
        if sim.symmetry is not None:
            sim.symmetry.sync_motion()           # as the step does before the predictor
            pos = sim.state.pos.to_numpy()[:n].astype(float)
            vel = sim.state.vel.to_numpy()[:n].astype(float)
        a_list = predictor_accelerations(sim, True)
        close_list = close_pairs(sim)
        sim._build(reorder=False)                # the grid at these positions, for the walk
        assert sim.state.count + int(sim.state.n_images[None]) == n
        a_walk = predictor_accelerations(sim, False)
        # the collision model's pairs (closer than 0.5 l0, dummies included): the same
        assert close_list == close_pairs(sim), name
        terms, nearest = missed_pair_terms(sim, pos, vel, kind, listed)
        m = sim.state.count                      # the simulated particles, images after them
        terms, kind = terms[:m], kind[:m]
        fluid = kind == FLUID
        scale = np.abs(a_walk[fluid]).max()
        assert scale > 1.0, name
        # the walk = the list + the missed pairs' terms, to float rounding
        np.testing.assert_allclose(a_walk[fluid], a_list[fluid] + terms[fluid], rtol=0,
                                   atol=2e-5 * scale, err_msg=name)
        # and each missed pair (often none) lies within the corrector's move of re
        assert nearest == np.inf or nearest <= move * (1 + 1e-6), (name, nearest, move)


def test_the_step_walks_after_a_load_and_an_output_refresh(single_thread):
    _, scene = next(scenes(2))
    sim = simulator_for(scene)
    assert not sim._lists_ready                  # nothing listed yet: the first step walks
    sim.step()
    assert sim._lists_ready
    sim.refresh_pressure()                       # a frame: lists at these positions, but the
    assert not sim._lists_ready                  # next step walks (resume gives the same)
    sim.step()
    assert sim._lists_ready
    sim.load(scene.pos, scene.vel, scene.kind)
    assert not sim._lists_ready


def test_an_incomplete_list_makes_the_next_step_walk(single_thread, monkeypatch):
    from crowndemo.core import neighbours
    monkeypatch.setitem(neighbours.SLOTS, 2, 4)  # most particles have more neighbours
    _, scene = next(scenes(2))
    scene.numerics = with_values(scene.numerics, reorder_every=0)
    sim = simulator_for(scene)
    sim.step()
    assert not sim.pressure.neighbours.complete()
    assert not sim._lists_ready


def test_off_walks_every_step(single_thread):
    _, scene = next(scenes(2))
    scene.numerics = with_values(scene.numerics, predictor_list=False)
    sim = simulator_for(scene)
    assert not sim.predictor.takes_list and not sim.model.predictor_list
    sim.step()
    assert not sim._lists_ready


@pytest.mark.parametrize("dim", [2, pytest.param(3, marks=pytest.mark.slow)])   # 3D: a minute
def test_a_state_saved_between_frames_continues_bit_for_bit(single_thread, dim):
    """A checkpoint taken when the next predictor takes the lists (Ctrl-C between frames)
    carries them, and the mirror images they name: a restored simulator takes the same path."""
    name, scene = list(scenes(dim))[-1]          # 3D: the quarter crown (mirror images)
    a = simulator_for(scene)
    for _ in range(STEPS):
        a.step()
    saved = a.save_state()
    assert "lists" in saved and (dim == 2 or "source" in saved["lists"])
    b = simulator_for(scene)
    b.restore_state(saved)
    assert b._lists_ready
    for _ in range(5):
        a.step()
        b.step()
    for key in ("pos", "vel"):
        x, y = getattr(a.state, key).to_numpy(), getattr(b.state, key).to_numpy()
        n = a.state.count
        assert np.array_equal(x[:n], y[:n]), (name, key)
