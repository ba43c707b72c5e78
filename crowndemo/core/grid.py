"""Dynamic cell grid: bounds follow the live particles, counting sort, neighbour walk.

The grid is rebuilt from scratch whenever positions change: bounds by reduction, cell count per
cell, a blocked prefix sum that runs on the CPU and GPU archs alike (blocks.py; Taichi's
PrefixSumExecutor does not run on the CPU), then a scatter into ``order`` (particle indices in
cell order). Cells have side >= re/k (k = ``cells_per_re``), so every neighbour within re lies
in the (2k + 1)^d cells around; k = 2 visits fewer candidate pairs than k = 1 (BENCHMARKS.md).
If the live particles spread so far that the cells would not fit in ``max_cells``, the cell side
grows: the walk stays exact, only more candidate pairs are visited.
"""

import taichi as ti

from .blocks import BLOCK, blocks_for, exclusive_scan, groups_for, larger, reduce_blocks, smaller
from .state import GONE, ParticleState


@ti.data_oriented
class CellGrid:
    def __init__(self, state: ParticleState, max_cells: int, cells_per_re: int = 2):
        d = self.dim = state.dim
        self.reach = int(cells_per_re)      # cells of side re/reach; walk (2 reach + 1)^d
        self.state = state
        self.max_cells = int(max_cells)     # cells allocated
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
        # positions in cell order, copied at the build: the walk tests distances on this
        # contiguous array and looks up j = order[s] only for the pairs within reach (a
        # quarter of the candidates). Positions must not change between a build and a walk.
        self.sorted_pos = ti.Vector.field(d, float, state.capacity)

    def set_cell_limit(self, cells: int) -> None:
        """Use at most ``cells`` cells (at most those allocated): a run-time value, so that a
        grid allocated larger gives the same cells, and results, as one allocated to fit."""
        self.cell_limit[None] = min(int(cells), self.max_cells)

    def nbytes(self) -> int:
        from .state import field_nbytes
        return sum(field_nbytes(f) for f in (self.cell_count, self.cell_start, self.block_sum,
                                             self.group_sum, self.particle_cell, self.rank,
                                             self.order, self.sorted_pos))

    def build(self, min_side: float, reorder: bool = False) -> None:
        """Rebuild at the current positions; with ``reorder`` permute the particles into cell
        order (every persistent field, through the state's registry)."""
        self._plan(min_side / self.reach)
        self._sort()
        if reorder:
            self.state.permute(self.order)
            self._identity_order()
        self._gather_positions()

    # ---- kernels -------------------------------------------------------------------------
    @ti.kernel
    def _plan(self, min_side: float):
        d = ti.static(self.dim)
        pos, kind = ti.static(self.state.pos, self.state.kind)
        # bounds of the live particles, by blocks (blocks.py: no contended atomics)
        for b in range(blocks_for(self.state.n[None])):
            lo = ti.Vector([3.0e38] * d)
            hi = ti.Vector([-3.0e38] * d)
            for i in range(b * BLOCK, ti.min(self.state.n[None], (b + 1) * BLOCK)):
                if kind[i] != GONE:
                    lo = ti.min(lo, pos[i])
                    hi = ti.max(hi, pos[i])
            self.block_lo[b] = lo
            self.block_hi[b] = hi
        blocks = blocks_for(self.state.n[None])
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
            cells = 1.0
            for k in ti.static(range(d)):
                cells *= (self.hi[k] - self.lo[k]) / h + 2.0
            limit = self.cell_limit[None]
            while cells > limit:
                h *= ti.max(1.01, (cells / limit) ** (1.0 / d))
                cells = 1.0
                for k in ti.static(range(d)):
                    cells *= (self.hi[k] - self.lo[k]) / h + 2.0
            total = 1
            for k in ti.static(range(d)):
                self.origin[k] = self.lo[k] - 0.5 * h
                self.dims[k] = ti.cast(ti.floor((self.hi[k] - self.origin[k]) / h), ti.i32) + 1
                total *= self.dims[k]
            self.side[None] = h
            self.num_cells[None] = total

    @ti.kernel
    def _sort(self):
        pos, kind = ti.static(self.state.pos, self.state.kind)
        for c in range(self.num_cells[None]):
            self.cell_count[c] = 0
        for i in range(self.state.n[None]):
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
        for b in range(blocks_for(cells)):
            run = self.block_sum[b]
            for c in range(b * BLOCK, ti.min(cells, (b + 1) * BLOCK)):
                self.cell_start[c] = run
                run += self.cell_count[c]
        # scatter; parked particles go after the live ones so a permutation keeps them
        for i in range(self.state.n[None]):
            c = self.particle_cell[i]
            if c >= 0:
                self.order[self.cell_start[c] + self.rank[i]] = i
            else:
                self.order[self.n_live[None] + ti.atomic_add(self.n_parked[None], 1)] = i

    @ti.kernel
    def _gather_positions(self):
        for s in range(self.n_live[None]):
            self.sorted_pos[s] = self.state.pos[self.order[s]]

    @ti.kernel
    def _identity_order(self):
        for k in range(self.state.n[None]):
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
        c = ti.Vector([0] * self.dim)
        for k in ti.static(range(self.dim)):
            ck = ti.cast(ti.floor((x[k] - self.origin[k]) / self.side[None]), ti.i32)
            c[k] = ti.min(ti.max(ck, 0), self.dims[k] - 1)
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
        """Call ``task(i, j, rij, r2, acc)`` for every live j != i with r2 = |rij|^2 < re2,
        rij = x_j - x_i. Cells have side >= re/reach, so the (2 reach + 1)^d cells around hold
        every neighbour; rows of cells along axis 0 are contiguous in cell order."""
        self._walk(i, xi, re2, task, acc, False)

    @ti.func
    def for_each_near(self, i, xi, r2_max, task: ti.template(), acc: ti.template()):
        """``for_each_neighbour`` for a radius well under re (the collision distance): each
        row of cells is clipped to the sphere, so only the few cells that reach it are
        visited. (Clipping costs more per row than it saves at radius re: BENCHMARKS.md.)"""
        self._walk(i, xi, r2_max, task, acc, True)

    @ti.func
    def _walk(self, i, xi, re2, task: ti.template(), acc: ti.template(), clip: ti.template()):
        d = ti.static(self.dim)
        c = self.cell_of(xi)
        k = ti.static(self.reach)
        h = self.side[None]
        for off in ti.static(ti.grouped(ti.ndrange(*([(-k, k + 1)] * (d - 1))))):
            row = c
            inside = True
            gap2 = 0.0      # squared distance from xi to the row's cells across axis 0
            for m in ti.static(range(1, d)):
                row[m] = c[m] + off[m - 1]
                if row[m] < 0 or row[m] >= self.dims[m]:
                    inside = False
                if ti.static(clip and off[m - 1] != 0):
                    lo = self.origin[m] + row[m] * h
                    gap = lo - xi[m]                     # the row lies above xi on axis m
                    if ti.static(off[m - 1] < 0):
                        gap = xi[m] - (lo + h)           # below
                    gap2 += ti.max(gap, 0.0) ** 2
            if inside and gap2 < re2:
                first = ti.max(c[0] - k, 0)
                last = ti.min(c[0] + k, self.dims[0] - 1)
                if ti.static(clip):                      # the sphere's chord along axis 0
                    half = ti.sqrt(re2 - gap2)
                    first = ti.max(first, ti.cast(ti.floor((xi[0] - half - self.origin[0]) / h),
                                                  ti.i32))
                    last = ti.min(last, ti.cast(ti.floor((xi[0] + half - self.origin[0]) / h),
                                                ti.i32))
                if first <= last:
                    row[0] = first
                    a = self.linear(row)
                    for s in range(self.cell_start[a], self.cell_start[a + last - first + 1]):
                        rij = self.sorted_pos[s] - xi
                        r2 = rij.dot(rij)
                        if r2 < re2:
                            j = self.order[s]
                            if j != i:
                                task(i, j, rij, r2, acc)
