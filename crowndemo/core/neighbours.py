"""Neighbour list: the neighbours j of each fluid particle found by one cell walk, kept for a
second pass at the same positions (the number density at r* and the pressure gradient at r*,
method.md S17-S18), so the second pass visits ~30 pairs instead of the ~145 candidates of the
5^3 cells around (BENCHMARKS.md). A particle with more neighbours than the list holds is
marked by its count and walks the cells again: the list never drops a pair."""

import taichi as ti

from .state import ParticleState

# entries per particle: a cubic lattice has 12 (2D) / 32 (3D) neighbours within re = 2.1 l0;
# the run aborts past a number-density excess of 0.5 (params.Numerics), so about 18 / 48 fit
# every state it can be in; rarer crowding falls back to the cell walk
SLOTS = {2: 24, 3: 56}


@ti.data_oriented
class NeighbourList:
    def __init__(self, state: ParticleState):
        self.slots = SLOTS[state.dim]
        self.count = ti.field(ti.i32, state.capacity)
        self.index = ti.field(ti.i32, (state.capacity, self.slots))

    def nbytes(self) -> int:
        from .state import field_nbytes
        return field_nbytes(self.count) + field_nbytes(self.index)

    @ti.func
    def add(self, i, j, n):
        """Store j as i's n-th neighbour (when it fits); returns n + 1."""
        if n < ti.static(self.slots):
            self.index[i, n] = j
        return n + 1

    @ti.func
    def fits(self, i) -> bool:
        return self.count[i] <= ti.static(self.slots)


__all__ = ["NeighbourList", "SLOTS"]
