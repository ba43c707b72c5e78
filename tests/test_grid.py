"""Cell-grid neighbour search against an O(N^2) brute force (method.md §3: cells of side >= re).

A test-only kernel walks ``grid.for_each_neighbour`` for every live particle and writes the
neighbour indices it visits into a 2-D field; numpy compares the sets with all pairs closer
than re. Pairs within a relative 1e-5 of re (where the f32 distance in the kernel and the f64
distance here may disagree) may go either way; every other pair must match exactly.
"""

import numpy as np
import pytest
import taichi as ti

from crowndemo.core import FLUID, GONE, Numerics, Physics, Simulator
from crowndemo.core.grid import CellGrid, min_cells, row_reach, stencil_rows

L0 = 1.0e-3
RE_RATIO = 2.1
RE = RE_RATIO * L0
MAX_NBR = 256
BAND = 1e-5          # relative band around re^2 left undecided


class Walker:
    """Records, for each particle i, the j that for_each_neighbour (or with ``near``, the
    row-clipping for_each_near of the collision model; with ``wide``, the surface stress's
    for_each_wide) visits (count -1: not walked)."""

    def __init__(self, sim: Simulator, near: bool = False, wide: bool = False,
                 grid: CellGrid = None):
        cap = sim.state.capacity
        self.nbr = ti.field(ti.i32, (cap, MAX_NBR))
        self.count = ti.field(ti.i32, cap)
        nbr, count, state = self.nbr, self.count, sim.state
        grid = sim.grid if grid is None else grid

        @ti.func
        def record(i, j, rij, r2, acc: ti.template()):
            if acc < MAX_NBR:
                nbr[i, acc] = j
            acc += 1

        @ti.kernel
        def walk(re2: float):
            for i in range(state.n[None]):
                c = -1
                if state.kind[i] != GONE:
                    c = 0
                    if ti.static(near):
                        grid.for_each_near(i, state.pos[i], re2, record, c)
                    elif ti.static(wide):
                        grid.for_each_wide(i, state.pos[i], re2, record, c)
                    else:
                        grid.for_each_neighbour(i, state.pos[i], re2, record, c)
                count[i] = c

        self._walk = walk

    def pairs(self, re: float):
        """Dict i -> list of j (field indices), and the counts."""
        self._walk(re * re)
        count = self.count.to_numpy()
        nbr = self.nbr.to_numpy()
        assert count.max() <= MAX_NBR, "test set-up: raise MAX_NBR"
        return count, nbr


CAPACITY = 800
BIG = {2: 1 << 18, 3: 1 << 24}   # cells enough for a 100 re spread: the side stays re/reach
SMALL = 64                       # forces the cell side to grow (raised to min_cells in 3D)
REACHES = [1, 2, 3]              # numerics.cells_per_re: cells of side re/k


@pytest.fixture(scope="module")
def sims():
    """One simulator (and walker) per (dim, max_cells, cells_per_re), reloaded by each test:
    building a simulator compiles its kernels, which is most of the cost here."""
    cache = {}

    def get(dim: int, max_cells: int, reach: int):
        if (dim, max_cells, reach) not in cache:
            physics = Physics(dim=dim, l0=L0, v_max=1.0, re_ratio=RE_RATIO, nu=0.0, sigma=0.0,
                              gravity=0.0)
            sim = Simulator(physics, Numerics(cells_per_re=reach), CAPACITY, max_cells)
            cache[dim, max_cells, reach] = (sim, Walker(sim), Walker(sim, near=True))
        return cache[dim, max_cells, reach]
    return get


def load(sims, dim: int, max_cells: int, pos: np.ndarray, kind: np.ndarray,
         near: bool = False, reach: int = Numerics().cells_per_re):
    sim, walker, near_walker = sims(dim, max_cells, reach)
    walker = near_walker if near else walker
    sim.load(pos, np.zeros_like(pos), kind)
    return sim, walker


def brute_force(pos: np.ndarray, kind: np.ndarray, re: float = RE):
    """(sure, maybe) boolean matrices: pairs (i, j), both live, i != j, with r^2 below
    re^2 (1 - BAND) (must be found) and below re^2 (1 + BAND) (may be found)."""
    live = kind != GONE
    d = pos[None, :, :] - pos[:, None, :]
    r2 = (d ** 2).sum(axis=2)
    ok = live[:, None] & live[None, :] & ~np.eye(len(pos), dtype=bool)
    return ok & (r2 < re * re * (1 - BAND)), ok & (r2 < re * re * (1 + BAND))


def check_against_brute_force(sim: Simulator, walker: Walker, pos_f: np.ndarray,
                              kind: np.ndarray, ids=None, radius: float = RE):
    """``ids[k]``: the original particle index held at field index k (identity if None)."""
    n = len(pos_f)
    ids = np.arange(n) if ids is None else ids
    count, nbr = walker.pairs(radius)
    sure, maybe = brute_force(pos_f, kind, radius)
    found = np.zeros((n, n), dtype=bool)
    for k in range(n):
        i = ids[k]
        if kind[i] == GONE:
            assert count[k] == -1
            continue
        js = ids[nbr[k, :count[k]]]
        assert len(set(js.tolist())) == len(js), f"particle {i}: a neighbour visited twice"
        found[i, js] = True
    missing = sure & ~found
    extra = found & ~maybe
    assert not missing.any(), f"missed pairs: {np.argwhere(missing)[:10].tolist()}"
    assert not extra.any(), f"spurious pairs: {np.argwhere(extra)[:10].tolist()}"
    assert (found != sure).sum() <= 2, "too many pairs at the re boundary to be rounding"
    return found


def random_cloud(dim: int, seed: int, n_box: int, box_re: float, far_re: float):
    """Uniform particles in a box box_re*re wide, plus small clusters far_re*re away in
    several directions (2D: +-x, +-y; 3D: +x, -y, +z) and an isolated pair far away."""
    rng = np.random.default_rng(seed)
    centre = np.full(dim, 0.5 * box_re * RE)
    far = far_re * RE
    shifts = ([(far, 0), (-far, 0), (0, far), (0, -far)] if dim == 2
              else [(far, 0, 0), (0, -far, 0), (0, 0, far)])
    parts = [rng.uniform(0.0, box_re * RE, size=(n_box, dim))]
    for shift in shifts:
        parts.append(centre + np.array(shift) + rng.uniform(-RE, RE, size=(12, dim)))
    loner = centre + np.array(shifts[0]) + 0.5 * far * np.eye(dim)[1]
    parts.append(loner[None, :])                                   # one isolated particle
    parts.append(loner[None, :] + 0.6 * RE * np.eye(dim)[0])       # and its only partner
    return np.concatenate(parts)


def as_loaded(sim: Simulator) -> np.ndarray:
    """Positions as the device holds them (f32 or f64), in float64 for the brute force."""
    return sim.state.pos.to_numpy()[: sim.state.count].astype(np.float64)


# sizes: 2D 600 particles in 12 re, 3D 700 in 7 re (about 13 and 9 neighbours each)
CLOUD = {2: dict(n_box=600, box_re=12.0), 3: dict(n_box=700, box_re=7.0)}


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("reach", REACHES)
def test_neighbours_match_brute_force_far_outliers(sims, dim, reach):
    # outliers 100 re away (60 re for cells of side re/3): BIG cells still hold the spread at
    # a cell side of re / reach
    pos = random_cloud(dim, seed=10 + dim, far_re=100.0 if reach < 3 else 60.0, **CLOUD[dim])
    kind = np.full(len(pos), FLUID, dtype=np.int32)
    sim, walker = load(sims, dim, BIG[dim], pos, kind, reach=reach)
    sim.grid.build(RE)
    assert sim.grid.reach == reach
    assert sim.grid.side[None] == pytest.approx(RE / reach, rel=1e-6)
    found = check_against_brute_force(sim, walker, as_loaded(sim), kind)
    assert found[len(pos) - 2, len(pos) - 1] and found[len(pos) - 1, len(pos) - 2]
    assert found.sum(axis=1).mean() > 5


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("reach", REACHES)
def test_neighbours_when_cell_side_must_grow(sims, dim, reach):
    pos = random_cloud(dim, seed=20 + dim, far_re=100.0, **CLOUD[dim])
    kind = np.full(len(pos), FLUID, dtype=np.int32)
    sim, walker = load(sims, dim, SMALL, pos, kind, reach=reach)
    sim.grid.build(RE)
    side = sim.grid.side[None]
    assert side > 10 * RE, "the spread should force a larger cell side"
    # a limit under the padded grid's minimum is raised to it, and the side still fits
    assert sim.grid.max_cells == max(SMALL, min_cells(dim, reach))
    assert sim.grid.num_cells[None] <= sim.grid.max_cells
    check_against_brute_force(sim, walker, as_loaded(sim), kind)


@pytest.mark.parametrize("dim", [2, 3])
def test_gone_particles_are_excluded(sims, dim):
    rng = np.random.default_rng(30 + dim)
    pos = random_cloud(dim, seed=30 + dim, far_re=20.0, **CLOUD[dim])
    kind = rng.choice(np.array([FLUID, FLUID, FLUID, 1, 2, GONE], dtype=np.int32), len(pos))
    kind[-2:] = FLUID
    # a parked particle very far away must not widen the grid either
    pos = np.concatenate([pos, np.full((1, dim), 1.0e4)])
    kind = np.concatenate([kind, np.array([GONE], dtype=np.int32)])
    sim, walker = load(sims, dim, BIG[dim], pos, kind)
    sim.grid.build(RE)
    assert sim.grid.side[None] == pytest.approx(RE / sim.grid.reach, rel=1e-6)
    assert (kind == GONE).sum() > 50
    found = check_against_brute_force(sim, walker, as_loaded(sim), kind)
    assert not found[:, kind == GONE].any() and not found[kind == GONE, :].any()


@pytest.mark.parametrize("dim", [2, 3])
def test_neighbours_after_reorder(sims, dim):
    """build(reorder=True) permutes every field into cell order; neighbour sets by particle
    id are unchanged and the snapshot (id order) gives back the loaded particles."""
    pos = random_cloud(dim, seed=40 + dim, far_re=30.0, **CLOUD[dim])
    rng = np.random.default_rng(40 + dim)
    kind = np.where(rng.uniform(size=len(pos)) < 0.1, GONE, FLUID).astype(np.int32)
    sim, walker = load(sims, dim, BIG[dim], pos, kind)
    before = as_loaded(sim)
    sim.grid.build(RE, reorder=True)
    pid = sim.state.pid.to_numpy()[: len(pos)]
    assert sorted(pid.tolist()) == list(range(len(pos)))
    assert not np.array_equal(pid, np.arange(len(pos))), "random particles should be re-sorted"
    snap = sim.snapshot()
    np.testing.assert_array_equal(snap["pos"].astype(np.float64), before)
    np.testing.assert_array_equal(snap["kind"], kind)
    check_against_brute_force(sim, walker, before, kind, ids=pid)


@pytest.mark.parametrize("dim", [2, 3])
def test_counts_of_an_earlier_build_do_not_linger(sims, dim):
    """A build clears only the cells the previous build counted particles in (the rest are
    zero): after a large cloud, a smaller one elsewhere, in the same simulator, has exact
    neighbours and the cell counts hold exactly its live particles, in the allocated grid
    too; likewise after every particle moves."""
    big = random_cloud(dim, seed=50 + dim, far_re=40.0, **CLOUD[dim])
    sim, walker = load(sims, dim, BIG[dim], big, np.full(len(big), FLUID, dtype=np.int32))
    sim.grid.build(RE)
    rng = np.random.default_rng(50 + dim)
    small = rng.uniform(-3.0 * RE, 3.0 * RE, size=(60, dim)) - 50.0 * RE
    kind = np.where(rng.uniform(size=60) < 0.2, GONE, FLUID).astype(np.int32)
    sim, walker = load(sims, dim, BIG[dim], small, kind)
    for shift in (0.0, 7.3 * RE):       # rebuilt as loaded, then with every particle moved
        pos = small + shift
        sim.state.pos.from_numpy(np.concatenate(
            [pos, np.zeros((sim.state.capacity - len(pos), dim))]).astype(
                sim.state.pos.to_numpy().dtype))
        sim.grid.build(RE)
        live = int((kind != GONE).sum())
        assert sim.grid.n_live[None] == live
        assert int(sim.grid.cell_count.to_numpy().sum()) == live
        check_against_brute_force(sim, walker, as_loaded(sim), kind)


@pytest.mark.parametrize("dim", [2, 3])
def test_coincident_and_non_finite_particles(sims, dim):
    """A particle exactly on another is not its neighbour (w and 1/r^2 would be infinite),
    and a non-finite position (a run blowing up, reported by the health check after the
    step) neither widens the grid to garbage nor is anyone's neighbour."""
    pos = np.zeros((5, dim))
    pos[2, 0] = 0.5 * RE            # a, b coincident at 0; c near both; d far; e at inf
    pos[3, 0] = 20.0 * RE
    kind = np.full(5, FLUID, dtype=np.int32)
    sim, walker = load(sims, dim, BIG[dim], pos, kind)
    p = sim.state.pos.to_numpy()
    p[4] = np.inf
    sim.state.pos.from_numpy(p)
    sim.grid.build(RE)
    assert np.isfinite(sim.grid.side[None]) and sim.grid.side[None] == pytest.approx(
        RE / sim.grid.reach, rel=1e-6)
    assert 0 < sim.grid.num_cells[None] <= sim.grid.max_cells
    count, nbr = walker.pairs(RE)
    found = [sorted(nbr[k, :count[k]].tolist()) for k in range(4)]
    assert found == [[2], [2], [0, 1], []]


def test_single_and_empty_live_sets(sims):
    """One live particle has no neighbours; all parked: nothing is walked."""
    pos = np.array([[0.0, 0.0], [0.5 * RE, 0.0], [3.0, 3.0]])
    kind = np.array([FLUID, GONE, GONE], dtype=np.int32)
    sim, w = load(sims, 2, BIG[2], pos, kind)
    sim.grid.build(RE)
    count, _ = w.pairs(RE)
    assert count[:3].tolist() == [0, -1, -1]
    sim.state.kind.from_numpy(np.full(sim.state.capacity, GONE, dtype=np.int32))
    sim.grid.build(RE)
    count, _ = w.pairs(RE)
    assert count[:3].tolist() == [-1, -1, -1]
    assert sim.grid.n_live[None] == 0


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("radius_l0", [0.5, 0.95, RE_RATIO])
@pytest.mark.parametrize("reach", [2, 3])
def test_row_clipped_walk_matches_brute_force(sims, dim, radius_l0, reach):
    """for_each_near (the collision model's walk, rows clipped to the sphere) finds exactly
    the pairs closer than its radius: the collision distance 0.5 l0, the largest allowed
    (< 1 l0), and re itself; a dense cloud so that close pairs are many."""
    rng = np.random.default_rng(50 + dim)
    n = 600 if dim == 2 else 700
    side = (n ** (1.0 / dim)) * 0.6 * L0          # mean spacing 0.6 l0
    pos = rng.uniform(0.0, side, size=(n, dim))
    kind = np.full(n, FLUID, dtype=np.int32)
    sim, walker = load(sims, dim, BIG[dim], pos, kind, near=True, reach=reach)
    sim.grid.build(RE)
    found = check_against_brute_force(sim, walker, as_loaded(sim), kind,
                                      radius=radius_l0 * L0)
    assert found.sum() > 2 * n, "test set-up: too few pairs to test the clipping"


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("reach", REACHES)
def test_stencil_holds_every_pair_within_re(dim, reach):
    """The walk's stencil (``row_reach``): for random points x in a cell of side
    h = re/k and random y within re of x, y's cell lies in a row the walk visits and within
    that row's reach along axis 0; and the stencil is no larger than it must be: every cell
    it visits can hold such a pair (a point pair at the cells' nearest corners)."""
    rng = np.random.default_rng(60 + 10 * dim + reach)
    h = 1.0 / reach                                    # re = 1
    x = rng.uniform(0.0, h, size=(200_000, dim))
    u = rng.normal(size=(len(x), dim))
    u *= (rng.uniform(size=(len(x), 1)) ** (1.0 / dim)) / np.linalg.norm(u, axis=1)[:, None]
    cell = np.floor((x + u) / h).astype(int)           # y = x + u, |u| < re
    for o in np.unique(cell, axis=0):
        reach_row = row_reach(tuple(o[1:]), reach)
        assert reach_row >= 0 and abs(o[0]) <= reach_row, f"cell offset {o} not walked"
    visited = 0
    for off in np.ndindex(*([2 * reach + 1] * (dim - 1))):
        off = tuple(int(v) - reach for v in off)
        e = row_reach(off, reach)
        if e < 0:
            continue
        visited += 2 * e + 1
        gap = [max(abs(o) - 1, 0) * h for o in (e,) + off]
        assert sum(g * g for g in gap) < 1.0, f"row {off} reaches too far ({e})"
    # the full block less the cells no pair can reach. In 3D for k = 3 those are the cells
    # with two offsets of +-3 and the third +-2 or +-3 (nearest-corner distance
    # sqrt(2^2 + 2^2 + 1) h >= 3 h = re): 3 x 8 + 8 = 32 of 343; for k <= 2 none
    assert visited == {2: {1: 9, 2: 25, 3: 49}, 3: {1: 27, 2: 125, 3: 343 - 32}}[dim][reach]


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("reach", REACHES)
def test_the_walks_table_is_the_stencil(dim, reach):
    """The table of the walk's rows (``stencil_rows``; the unrolled walk compiles a copy of
    the pass for each, the loop walks it at run time): rows in the block's order (offsets on
    axes 1..d-1 increasing), each with its ``row_reach``, and for the walk at re the
    cells the stencil test above counts (all of the (2k + 1)^d block but 32 for k = 3 in 3D);
    the wide walk to 3 l0 visits more."""
    table = stencil_rows(dim, reach)
    offsets = [tuple(r[:-1]) for r in table]
    assert offsets == sorted(set(offsets))
    assert all(r[-1] == row_reach(tuple(r[:-1]), reach) >= 0 for r in table)
    assert (2 * table[:, -1] + 1).sum() == {2: {1: 9, 2: 25, 3: 49},
                                            3: {1: 27, 2: 125, 3: 343 - 32}}[dim][reach]
    wide = stencil_rows(dim, reach * 3.0 / 2.1)
    assert all(r[-1] == row_reach(tuple(r[:-1]), reach * 3.0 / 2.1) >= 0 for r in wide)
    assert (2 * wide[:, -1] + 1).sum() > (2 * reach + 1) ** dim


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("reach", REACHES)
def test_the_walks_loop_visits_the_unrolled_walks_pairs(dim, reach):
    """The walk with its rows in a loop (``rows_in_loop``, the fast-compiling backend's) and
    unrolled (the default): every particle's neighbours, and both exact against the brute
    force; a grown cell side too. (The rows come in the same order, the table test above; the
    order within a cell is the sort's, which threads' atomics set, so two grids' orders may
    differ.)"""
    pos = random_cloud(dim, seed=70 + dim, far_re=30.0, **CLOUD[dim])
    kind = np.full(len(pos), FLUID, dtype=np.int32)
    physics = Physics(dim=dim, l0=L0, v_max=1.0, re_ratio=RE_RATIO, nu=0.0, sigma=0.0,
                      gravity=0.0)
    for max_cells in (BIG[dim], SMALL):
        sim = Simulator(physics, Numerics(cells_per_re=reach), CAPACITY, max_cells)
        walker = Walker(sim)
        sim.load(pos, np.zeros_like(pos), kind)
        other = CellGrid(sim.state, max_cells, reach, rows_in_loop=not sim.grid.rows_in_loop)
        sim.grid.build(RE)
        other.build(RE)
        assert other.side[None] == sim.grid.side[None]
        count, nbr = walker.pairs(RE)
        count_other, nbr_other = Walker(sim, grid=other).pairs(RE)
        assert (count == count_other).all() and count.sum() > 5 * len(pos)
        for i in range(len(pos)):
            assert (np.sort(nbr[i, :count[i]]) == np.sort(nbr_other[i, :count[i]])).all(), \
                f"particle {i}"
        check_against_brute_force(sim, Walker(sim, grid=other), as_loaded(sim), kind)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("reach", REACHES)
@pytest.mark.parametrize("max_cells", ["big", "small"])
def test_wide_walk_matches_brute_force(dim, reach, max_cells):
    """The wide walk (``for_each_wide``) of a grid made for the surface stress's pair support
    H = 3 l0 (Model.wide_walk = 3 / 2.1): every pair within H, none beyond, with the cell side
    re/k and grown under a small cell limit; and the walk at re on the same grid is unchanged."""
    from crowndemo.core.params import stress_pair_support
    support = stress_pair_support(dim, RE_RATIO)
    physics = Physics(dim=dim, l0=L0, v_max=1.0, re_ratio=RE_RATIO, nu=0.0, sigma=0.0728,
                      gravity=0.0)
    sim = Simulator(physics, Numerics(cells_per_re=reach, surface_tension="stress"), CAPACITY,
                    BIG[dim] if max_cells == "big" else SMALL)
    assert sim.grid.wide == pytest.approx(support / RE_RATIO)
    pos = random_cloud(dim, 90 + 10 * dim + reach, n_box=CLOUD[dim]["n_box"] // 3,
                       box_re=CLOUD[dim]["box_re"], far_re=40.0)
    kind = np.full(len(pos), FLUID, dtype=np.int32)
    sim.load(pos, np.zeros_like(pos), kind)
    sim.grid.build(RE)
    check_against_brute_force(sim, Walker(sim, wide=True), as_loaded(sim), kind,
                              radius=support * L0)
    check_against_brute_force(sim, Walker(sim), as_loaded(sim), kind)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("reach", REACHES)
def test_wide_stencil_holds_every_pair_within_its_radius(dim, reach):
    """``row_reach`` for a walk radius of k x 3/2.1 cells (not a whole number): every cell
    offset that a pair within that radius can span lies in a visited row and reach."""
    span = reach * 3.0 / 2.1
    rng = np.random.default_rng(80 + 10 * dim + reach)
    h = 1.0 / reach                                    # re = 1, the radius span h
    x = rng.uniform(0.0, h, size=(200_000, dim))
    u = rng.normal(size=(len(x), dim))
    u *= span * h * (rng.uniform(size=(len(x), 1)) ** (1.0 / dim)) / np.linalg.norm(
        u, axis=1)[:, None]
    cell = np.floor((x + u) / h).astype(int)
    for o in np.unique(cell, axis=0):
        reach_row = row_reach(tuple(o[1:]), span)
        assert reach_row >= 0 and abs(o[0]) <= reach_row, f"cell offset {o} not walked"
