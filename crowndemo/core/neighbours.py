"""Neighbour list: the neighbours j of each fluid particle found by one cell walk, kept for a
second pass at the same positions (the number density at r* and the pressure gradient at r*,
method.md S17-S18), so the second pass visits ~30 pairs instead of the ~145 candidates of the
5^3 cells around (BENCHMARKS.md). A particle with more neighbours than the list holds is
marked by its count and walks the cells again: the list never drops a pair."""

import os
from typing import Optional

import taichi as ti

from .params import ParameterError
from .state import ParticleState

# entries per particle: a cubic lattice has 12 (2D) / 32 (3D) neighbours within re = 2.1 l0;
# the run aborts past a number-density excess of 0.5 (params.Numerics), so about 18 / 48 fit
# every state it can be in; rarer crowding falls back to the cell walk
SLOTS = {2: 24, 3: 56}


# memory order of the list, index[i, m] either way: "particle" keeps a particle's slots together
# (a CPU thread reads its own row); "slot" keeps slot m of consecutive particles together, so
# the threads of a GPU warp read one contiguous line per slot. Not yet measured on a GPU
# (BENCHMARKS.md, "GPU figures"): the default is "particle"; $CROWNDEMO_LIST_LAYOUT selects.
LAYOUTS = ("particle", "slot")
LAYOUT_VARIABLE = "CROWNDEMO_LIST_LAYOUT"


def layout_from_environment() -> str:
    layout = os.environ.get(LAYOUT_VARIABLE, "") or "particle"
    if layout not in LAYOUTS:
        raise ParameterError(LAYOUT_VARIABLE, layout, ", ".join(LAYOUTS), source="environment")
    return layout


@ti.data_oriented
class NeighbourList:
    def __init__(self, state: ParticleState, layout: Optional[str] = None):
        self.slots = SLOTS[state.dim]
        self.layout = layout or layout_from_environment()
        if self.layout not in LAYOUTS:
            raise ParameterError("layout", self.layout, ", ".join(LAYOUTS), source="NeighbourList")
        self.count = ti.field(ti.i32, state.capacity)
        # set when some particle of the last listing had more neighbours than slots (its
        # list is incomplete: a pass that cannot walk the cells must not use the lists)
        self.overflow = ti.field(ti.i32, shape=())
        self.index = ti.field(ti.i32)           # [particle, slot] in either layout
        if self.layout == "slot":
            ti.root.dense(ti.j, self.slots).dense(ti.i, state.capacity).place(self.index)
        else:       # as ti.field(ti.i32, (capacity, slots)): one row-major block
            ti.root.dense(ti.ij, (state.capacity, self.slots)).place(self.index)

    def nbytes(self) -> int:
        from .state import field_nbytes
        return field_nbytes(self.count) + field_nbytes(self.index) + field_nbytes(self.overflow)

    @ti.func
    def add(self, i, j, n):
        """Store j as i's n-th neighbour (when it fits); returns n + 1."""
        if n < ti.static(self.slots):
            self.index[i, n] = j
        return n + 1

    def complete(self) -> bool:
        """Every list of the last listing holds all its neighbours (a read-back)."""
        return int(self.overflow[None]) == 0

    @ti.func
    def fits(self, i) -> bool:
        return self.count[i] <= ti.static(self.slots)


__all__ = ["NeighbourList", "SLOTS", "LAYOUTS", "layout_from_environment"]
