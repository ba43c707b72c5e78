"""Dynamic cell grid: bounds follow the live particles, counting sort, neighbour walk.

The grid is rebuilt from scratch whenever positions change: bounds by reduction, cell count per
cell, a blocked prefix sum that runs on the CPU and GPU archs alike (blocks.py; Taichi's
PrefixSumExecutor does not run on the CPU), then a scatter into ``order`` (particle indices in
cell order). Cells have side h >= re/k (k = ``cells_per_re``), so every neighbour within re
lies within k cells on each axis. The walk visits only the cells of that (2k + 1)^d block that
can hold a point within re of the particle's own cell (a stencil fixed when the grid is made:
all 125 for k = 2, 311 of 343 for k = 3), row by row along axis 0, where cells are contiguous
in cell order. The walk unrolls its rows (a copy of the pair task for each), or, where the
backend compiles fast (``--fast-compile``, ``$CROWNDEMO_FAST_COMPILE``: first and short runs,
the test suite), loops over a small table of them at run time: one copy of the task, so the 3D
kernels compile in a fraction of the time, and the crown steps 5-15 % slower (BENCHMARKS.md,
"The walk's rows in a loop"). The collision's walk (clipped rows, a small task) unrolls always.
The grid is padded with k empty cells on every side, so a row never needs a bounds test.
A grid made ``wide`` (> 1) also has a second, wider walk (``for_each_wide``) to wide x re, for a
pass whose pair kernel reaches beyond re (the surface stress's divergence, C3): its stencil is
the cells within ceil(k wide) of the centre that can hold such a point, and the padding is that
wide; the walks at re are the same as without it.
If the live particles spread so far that the cells would not fit in ``max_cells``, the cell side
grows: the walk stays exact, only more candidate pairs are visited.
"""

import itertools
import math
import warnings
from typing import Iterable, Optional

import numpy as np
import taichi as ti

from ..backend import fast_compiling
from .blocks import BLOCK, blocks_for, exclusive_scan, groups_for, larger, reduce_blocks, smaller
from .state import GONE, ParticleState


# the walk unrolls its rows on purpose (49 for cells_per_re = 3 in 3D) unless it loops over
# them (``rows_in_loop``): Taichi's warning past 32 unrolled iterations says nothing a user can
# act on
warnings.filterwarnings("ignore", message="You are unrolling more than", category=SyntaxWarning)


FAR = 1.0e30       # |coordinate| beyond this (inf, NaN fails the test too) is not a bound


def row_reach(off: Iterable[int], k: float) -> int:
    """How far along axis 0 the walk's row at cell offset ``off`` (axes 1..d-1) reaches, in
    cells of side h = re/k (k cells per walk radius; not a whole number for the wide walk): the
    largest |o_0| such that the cell at (o_0, off) can hold a point within k h of a point of
    the centre cell, sum_m (max(|o_m| - 1, 0) h)^2 < (k h)^2; -1 when no cell of the row can. A
    larger h (the side grown under the cell limit) only shrinks the true set, so the stencil
    holds for every h >= re/k."""
    across = sum(max(abs(int(o)) - 1, 0) ** 2 for o in off)
    if across >= k * k:
        return -1
    reach = 0
    while reach < math.ceil(k) and reach * reach + across < k * k:
        reach += 1
    return reach


def cells_spanned(span: float) -> int:
    """The whole cells a walk of ``span`` cells (fractional for the wide walk) covers on each
    side of its own: ceil(span)."""
    return int(math.ceil(span - 1e-9))


def span_cells(cells_per_re: int, wide: float = 1.0) -> int:
    """The cells a walk to wide x re spans on each side of its own: ceil(k wide)."""
    return cells_spanned(cells_per_re * max(wide, 1.0))


def stencil_rows(dim: int, span: float) -> np.ndarray:
    """The rows of the walk to ``span`` cells that can hold a neighbour, in the order the
    walk visits them: (offsets on axes 1..dim-1, row_reach) per row."""
    k = cells_spanned(span)
    rows = [off + (row_reach(off, span),)
            for off in itertools.product(range(-k, k + 1), repeat=dim - 1)
            if row_reach(off, span) >= 0]
    return np.array(rows, dtype=np.int32).reshape(len(rows), dim)


def min_cells(dim: int, cells_per_re: int, wide: float = 1.0) -> int:
    """The fewest cells a grid needs: one cell with its padding and one to spare per axis, so
    that a growing cell side always ends within the limit."""
    return (2 * span_cells(cells_per_re, wide) + 3) ** dim


@ti.data_oriented
class CellGrid:
    def __init__(self, state: ParticleState, max_cells: int, cells_per_re: int = 2,
                 wide: float = 1.0, rows_in_loop: Optional[bool] = None):
        d = self.dim = state.dim
        # None: loop over the rows where the backend compiles fast (module docstring)
        self.rows_in_loop = fast_compiling() if rows_in_loop is None else bool(rows_in_loop)
        self.reach = int(cells_per_re)      # cells of side re/reach; walk (2 reach + 1)^d
        self.wide = max(float(wide), 1.0)   # for_each_wide's radius over re
        self.pad = span_cells(self.reach, self.wide)   # empty cells on every side
        self.state = state
        self.max_cells = max(int(max_cells), min_cells(d, self.reach, self.wide))   # allocated
        self.cell_limit = ti.field(ti.i32, shape=())   # cells used at most (<= max_cells)
        self.cell_limit[None] = self.max_cells
        self.lo = ti.field(float, d)
        self.hi = ti.field(float, d)
        self.origin = ti.field(float, d)
        self.dims = ti.field(ti.i32, d)
        self.side = ti.field(float, shape=())
        self.num_cells = ti.field(ti.i32, shape=())
        self.n_live = ti.field(ti.i32, shape=())
        self.n_parked = ti.field(ti.i32, shape=())
        self.n_counted = ti.field(ti.i32, shape=())    # particles the last count placed
        self.cell_count = ti.field(ti.i32, self.max_cells)
        self.cell_start = ti.field(ti.i32, self.max_cells + 1)
        self.block_sum = ti.field(ti.i32, blocks_for(self.max_cells))
        self.group_sum = ti.field(ti.i32, groups_for(blocks_for(self.max_cells)))
        particle_blocks = blocks_for(state.capacity)
        self.block_lo = ti.Vector.field(d, float, particle_blocks)
        self.block_hi = ti.Vector.field(d, float, particle_blocks)
        self.group_lo = ti.Vector.field(d, float, groups_for(particle_blocks))
        self.group_hi = ti.Vector.field(d, float, groups_for(particle_blocks))
        self.live_lo = ti.Vector.field(d, float, shape=())
        self.live_hi = ti.Vector.field(d, float, shape=())
        self.particle_cell = ti.field(ti.i32, state.capacity)
        self.rank = ti.field(ti.i32, state.capacity)
        self.order = ti.field(ti.i32, state.capacity)   # particle indices in cell order
        # positions in cell order, written by the build's scatter: the walk tests distances on this
        # contiguous array and looks up j = order[s] only for the pairs within reach (a
        # quarter of the candidates). Positions must not change between a build and a walk.
        self.sorted_pos = ti.Vector.field(d, float, state.capacity)
        # the stencils' rows for the walk's loop (rows_in_loop), filled at the first build (no
        # kernel launch while the simulator's fields are being made)
        self.rows = self.wide_rows = None
        self._unfilled = []                 # (field, table) still to copy to the device
        if self.rows_in_loop:
            tables = (stencil_rows(d, self.reach), stencil_rows(d, self.reach * self.wide))
            self.rows, self.wide_rows = (ti.field(ti.i32, shape=t.shape) for t in tables)
            self._unfilled = list(zip((self.rows, self.wide_rows), tables))

    def set_cell_limit(self, cells: int) -> None:
        """Use at most ``cells`` cells (at most those allocated): a run-time value, so that a
        grid allocated larger gives the same cells, and results, as one allocated to fit."""
        self.cell_limit[None] = max(min(int(cells), self.max_cells),
                                    min_cells(self.dim, self.reach, self.wide))

    def nbytes(self) -> int:
        from .state import field_nbytes
        return sum(field_nbytes(f) for f in (self.cell_count, self.cell_start, self.block_sum,
                                             self.group_sum, self.particle_cell, self.rank,
                                             self.order, self.sorted_pos))

    def build(self, min_side: float, reorder: bool = False) -> None:
        """Rebuild at the current positions; with ``reorder`` permute the particles into cell
        order (every persistent field, through the state's registry)."""
        for field, table in self._unfilled:
            field.from_numpy(table)
        self._unfilled = []
        self._plan(min_side / self.reach)
        self._sort()
        if reorder:
            self.state.permute(self.order)
            self._identity_order()

    # ---- kernels -------------------------------------------------------------------------
    @ti.kernel
    def _plan(self, min_side: float):
        d = ti.static(self.dim)
        pos, kind = ti.static(self.state.pos, self.state.kind)
        # bounds of the live particles, by blocks (blocks.py: no contended atomics)
        for b in range(blocks_for(self.state.in_grid())):
            lo = ti.Vector([3.0e38] * d)
            hi = ti.Vector([-3.0e38] * d)
            for i in range(b * BLOCK, ti.min(self.state.in_grid(), (b + 1) * BLOCK)):
                # a non-finite position (a run blowing up, which the health check after the
                # step reports) must not make the cell side and dimensions garbage
                if kind[i] != GONE and (ti.abs(pos[i]) < FAR).all():
                    lo = ti.min(lo, pos[i])
                    hi = ti.max(hi, pos[i])
            self.block_lo[b] = lo
            self.block_hi[b] = hi
        blocks = blocks_for(self.state.in_grid())
        reduce_blocks(self.block_lo, blocks, self.group_lo, self.live_lo, smaller, self._far_up)
        reduce_blocks(self.block_hi, blocks, self.group_hi, self.live_hi, larger, self._far_down)
        for _ in range(1):   # serial: cell side and dimensions that fit in max_cells
            for k in ti.static(range(d)):
                self.lo[k] = self.live_lo[None][k]
                self.hi[k] = self.live_hi[None][k]
            h = min_side
            if self.lo[0] > self.hi[0]:       # no live particle
                for k in ti.static(range(d)):
                    self.lo[k] = 0.0
                    self.hi[k] = 0.0
            pad = ti.static(self.pad)      # empty cells on every side (module docstring)
            cells = 1.0
            for k in ti.static(range(d)):
                cells *= (self.hi[k] - self.lo[k]) / h + 2.0 + 2.0 * pad
            limit = self.cell_limit[None]
            while cells > limit:
                h *= ti.max(1.01, (cells / limit) ** (1.0 / d))
                cells = 1.0
                for k in ti.static(range(d)):
                    cells *= (self.hi[k] - self.lo[k]) / h + 2.0 + 2.0 * pad
            total = 1
            for k in ti.static(range(d)):
                self.origin[k] = self.lo[k] - (0.5 + pad) * h
                self.dims[k] = ti.cast(ti.floor((self.hi[k] - self.origin[k]) / h),
                                       ti.i32) + 1 + pad
                total *= self.dims[k]
            self.side[None] = h
            self.num_cells[None] = total

    @ti.kernel
    def _sort(self):
        pos, kind = ti.static(self.state.pos, self.state.kind)
        # cell_count is zero but in the cells the last count placed a particle in
        for i in range(self.n_counted[None]):
            c = self.particle_cell[i]
            if c >= 0:
                self.cell_count[c] = 0
        for i in range(self.state.in_grid()):
            if kind[i] != GONE:
                c = self.linear(self.cell_of(pos[i]))
                self.particle_cell[i] = c
                self.rank[i] = ti.atomic_add(self.cell_count[c], 1)
            else:
                self.particle_cell[i] = -1
        # exclusive prefix sum of cell_count into cell_start: sums per block of cells, their
        # scan (blocks.py), then the scan inside each block
        cells = self.num_cells[None]
        for b in range(blocks_for(cells)):
            s = 0
            for c in range(b * BLOCK, ti.min(cells, (b + 1) * BLOCK)):
                s += self.cell_count[c]
            self.block_sum[b] = s
        exclusive_scan(self.block_sum, blocks_for(cells), self.group_sum, self.n_live)
        for _ in range(1):
            self.cell_start[cells] = self.n_live[None]
            self.n_parked[None] = 0
            self.n_counted[None] = self.state.in_grid()
        for b in range(blocks_for(cells)):
            run = self.block_sum[b]
            for c in range(b * BLOCK, ti.min(cells, (b + 1) * BLOCK)):
                self.cell_start[c] = run
                run += self.cell_count[c]
        # scatter; parked particles go after the live ones so a permutation keeps them
        for i in range(self.state.in_grid()):
            c = self.particle_cell[i]
            if c >= 0:
                slot = self.cell_start[c] + self.rank[i]
                self.order[slot] = i
                self.sorted_pos[slot] = pos[i]
            else:
                self.order[self.n_live[None] + ti.atomic_add(self.n_parked[None], 1)] = i

    @ti.kernel
    def _identity_order(self):
        for k in range(self.state.in_grid()):
            self.order[k] = k

    @ti.func
    def _far_up(self):
        return ti.Vector([3.0e38] * self.dim)

    @ti.func
    def _far_down(self):
        return ti.Vector([-3.0e38] * self.dim)

    # ---- functions used by the passes ----------------------------------------------------
    @ti.func
    def cell_of(self, x):
        """The cell of x, kept off the padding (a live particle's cell always is)."""
        c = ti.Vector([0] * self.dim)
        for k in ti.static(range(self.dim)):
            ck = ti.cast(ti.floor((x[k] - self.origin[k]) / self.side[None]), ti.i32)
            c[k] = ti.min(ti.max(ck, self.pad), self.dims[k] - 1 - self.pad)
        return c

    @ti.func
    def linear(self, c):
        idx = c[self.dim - 1]
        for m in ti.static(range(self.dim - 1)):
            k = self.dim - 2 - m
            idx = idx * self.dims[k] + c[k]
        return idx

    @ti.func
    def for_each_neighbour(self, i, xi, re2, task: ti.template(), acc: ti.template()):
        """Call ``task(i, j, rij, r2, acc)`` for every live j with 0 < r2 = |rij|^2 < re2,
        rij = x_j - x_i, at the positions of the last ``build``; re2 at most the square of the
        ``min_side`` it was given (the stencil of the module docstring holds up to that)."""
        self._walk(i, xi, re2, task, acc, False, self.reach)

    @ti.func
    def for_each_wide(self, i, xi, r2, task: ti.template(), acc: ti.template()):
        """``for_each_neighbour`` to a radius sqrt(r2) of at most ``wide`` times the
        ``min_side`` of the last build (a grid made with ``wide`` > 1)."""
        self._walk(i, xi, r2, task, acc, False, self.reach * self.wide)

    @ti.func
    def for_each_near(self, i, xi, r2_max, task: ti.template(), acc: ti.template()):
        """``for_each_neighbour`` for a radius well under re (the collision distance): each
        row of cells is clipped to the sphere, so only the few cells that reach it are
        visited. (Clipping costs more per row than it saves at radius re: BENCHMARKS.md.)"""
        self._walk(i, xi, r2_max, task, acc, True, self.reach)

    def _rows_for(self, span: float) -> ti.Field:
        """The table of rows of the walk to ``span`` cells (the grid's two walks)."""
        return self.rows if span == self.reach else self.wide_rows

    @ti.func
    def _walk(self, i, xi, re2, task: ti.template(), acc: ti.template(), clip: ti.template(),
              span: ti.template()):
        """The stencil's rows for a walk radius of ``span`` cells of side re/reach."""
        d = ti.static(self.dim)
        c = self.cell_of(xi)
        h = self.side[None]
        stride = ti.Vector([1] * d)       # of the cell index along each axis
        for m in ti.static(range(1, d)):
            stride[m] = stride[m - 1] * self.dims[m - 1]
        centre = self.linear(c)
        if ti.static(self.rows_in_loop and not clip):
            rows = ti.static(self._rows_for(span))
            for r in range(rows.shape[0]):      # a loop at run time: one copy of the task
                reach = rows[r, d - 1]
                first = centre - reach          # the row's first cell
                for m in ti.static(range(1, d)):
                    first += rows[r, m - 1] * stride[m]
                self._row(i, xi, re2, self.cell_start[first],
                          self.cell_start[first + 2 * reach + 1], task, acc)
        else:
            # one unrolled copy of the task per row that can hold a neighbour (the table's rows)
            for row in ti.static(stencil_rows(d, span).tolist()):
                off, reach = ti.static(tuple(row[:-1]), row[-1])
                first = centre - reach         # the row's first cell
                for m in ti.static(range(1, d)):
                    first += off[m - 1] * stride[m]
                if ti.static(clip):
                    self._clipped_row(i, xi, re2, c, h, off, first, reach, task, acc)
                else:
                    self._row(i, xi, re2, self.cell_start[first],
                              self.cell_start[first + 2 * reach + 1], task, acc)

    @ti.func
    def _clipped_row(self, i, xi, re2, c, h, off: ti.template(), first, reach: ti.template(),
                     task: ti.template(), acc: ti.template()):
        """The row's cells that reach the sphere of radius sqrt(re2) around xi."""
        gap2 = 0.0      # squared distance from xi to the row's cells across axis 0
        for m in ti.static(range(1, self.dim)):
            if ti.static(off[m - 1] != 0):
                lo = self.origin[m] + (c[m] + off[m - 1]) * h
                gap = lo - xi[m]                     # the row lies above xi on axis m
                if ti.static(off[m - 1] < 0):
                    gap = xi[m] - (lo + h)           # below
                gap2 += ti.max(gap, 0.0) ** 2
        if gap2 < re2:
            half = ti.sqrt(re2 - gap2)               # the sphere's chord along axis 0
            lo0 = ti.max(-reach, ti.cast(ti.floor((xi[0] - half - self.origin[0]) / h),
                                         ti.i32) - c[0])
            hi0 = ti.min(reach, ti.cast(ti.floor((xi[0] + half - self.origin[0]) / h),
                                        ti.i32) - c[0])
            if lo0 <= hi0:
                self._row(i, xi, re2, self.cell_start[first + reach + lo0],
                          self.cell_start[first + reach + hi0 + 1], task, acc)

    @ti.func
    def _row(self, i, xi, re2, begin, end, task: ti.template(), acc: ti.template()):
        """``task`` for the particles in cell-order slots [begin, end) within reach of xi."""
        for s in range(begin, end):
            rij = self.sorted_pos[s] - xi
            r2 = rij.dot(rij)
            # 0 < r2: i itself, and a particle exactly on it (w = inf, 1/r^2; the collision
            # model keeps pairs apart), are not neighbours
            if r2 < re2 and r2 > 0.0:
                task(i, self.order[s], rij, r2, acc)
