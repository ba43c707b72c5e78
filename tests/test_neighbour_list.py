"""The neighbour list (core/neighbours.py) changes no result. From one state of a moving
dam break, the pressure-gradient accelerations (S18) computed from the list, by the cell walk
(no list) and by a list too short for most particles (they fall back to the walk) agree to
float rounding: a missed or doubled neighbour would change a particle's sum by ~1/30. The
compiler may fuse the list's and the walk's arithmetic differently, so equality is to f32
rounding, not to the bit. The list's slot-major memory layout holds the same lists.
"""
import numpy as np
import pytest

from crowndemo import backend
from crowndemo.core import FLUID, ParameterError, neighbours, simulator_for
from crowndemo.core.params import with_values
from crowndemo.scenes import dam_break

STEPS = 40


@pytest.fixture(scope="module")
def single_thread():
    backend.init("cpu", seed=1, single_thread=True)
    yield
    backend.init("cpu")          # back to the session default (resets Taichi)


def scene(dim: int, neighbour_list: bool):
    s = dam_break(dim=dim, a=0.02 if dim == 2 else 0.01, l0=2e-3 if dim == 2 else 1e-3,
                  t_end=1.0)
    s.numerics = with_values(s.numerics, neighbour_list=neighbour_list)
    return s


def accelerations(sim) -> np.ndarray:
    """-grad P / rho (S18) at the current positions, in storage order, fluid rows only."""
    sim.grid.build(sim.lattice.re)
    sim.pressure.density_and_pressure()
    sim.pressure.correct(0.0)           # dt = 0: computes a' into scratch_vec, moves nothing
    kind = sim.state.kind.to_numpy()[: sim.state.count]
    return sim.state.scratch_vec.to_numpy()[: sim.state.count][kind == FLUID]


def in_use(sim) -> np.ndarray:
    """Each fluid particle's listed neighbours in storage order, -1 past its count (slots
    past the count hold what earlier steps left)."""
    lst = sim.pressure.neighbours
    n = sim.state.count
    index, count = lst.index.to_numpy()[:n], lst.count.to_numpy()[:n]
    kind = sim.state.kind.to_numpy()[:n]
    used = np.arange(index.shape[1])[None, :] < count[:, None]
    return np.where(used, index, -1)[kind == FLUID]


@pytest.mark.parametrize("dim", [2, 3])
def test_list_walk_and_fallback_give_the_same_gradient(single_thread, monkeypatch, dim):
    listed = simulator_for(scene(dim, True))
    for _ in range(STEPS):
        listed.step()
    saved = listed.save_state()
    a_list = accelerations(listed)
    counts = listed.pressure.neighbours.count.to_numpy()[: listed.state.count]
    kind = listed.state.kind.to_numpy()[: listed.state.count]
    counts = counts[kind == FLUID]
    # a cubic lattice has 12 (2D) / 32 (3D) neighbours within 2.1 l0; fewer at the surface
    assert counts.max() <= neighbours.SLOTS[dim]
    assert np.median(counts) >= (8 if dim == 2 else 20)

    def from_saved(neighbour_list: bool):
        s = scene(dim, neighbour_list)
        sim = simulator_for(s)
        sim.restore_state(saved)
        return sim

    a_walk = accelerations(from_saved(False))
    # the slot-major layout ($CROWNDEMO_LIST_LAYOUT, for GPUs): the same lists, slot by slot
    monkeypatch.setenv(neighbours.LAYOUT_VARIABLE, "slot")
    slot = from_saved(True)
    a_slot = accelerations(slot)
    assert slot.pressure.neighbours.layout == "slot"
    n_slots = neighbours.SLOTS[dim]
    assert slot.pressure.neighbours.index.shape == (listed.state.capacity, n_slots)
    # stored slot-major: the outer level of the field's layout runs over the slots; the
    # default is one row-major block, a particle's slots together
    assert slot.pressure.neighbours.index.snode.parent(2).shape == (n_slots,)
    default = listed.pressure.neighbours.index.snode
    assert default.parent().shape == (listed.state.capacity, n_slots)
    assert default.parent(2).shape == ()            # the root: one block, no outer level
    for_slot, for_listed = in_use(slot), in_use(listed)
    assert np.array_equal(for_slot, for_listed) and (for_slot >= 0).sum() > 10 * len(counts)
    monkeypatch.delenv(neighbours.LAYOUT_VARIABLE)
    monkeypatch.setitem(neighbours.SLOTS, dim, 4)   # most particles overflow: cell walk
    short = from_saved(True)
    a_short = accelerations(short)
    short_counts = short.pressure.neighbours.count.to_numpy()[: short.state.count][kind == FLUID]
    assert (short_counts > 4).mean() > 0.9, "the fallback should be taken"
    scale = np.abs(a_walk).max()
    assert scale > 1.0, "the column should be under pressure"
    tol = 1e-5 * scale
    assert np.abs(a_list - a_walk).max() < tol
    assert np.abs(a_short - a_walk).max() < tol
    assert np.abs(a_slot - a_list).max() < tol


def test_a_bad_list_layout_is_refused(monkeypatch):
    monkeypatch.setenv(neighbours.LAYOUT_VARIABLE, "diagonal")
    with pytest.raises(ParameterError, match=neighbours.LAYOUT_VARIABLE):
        neighbours.layout_from_environment()
