"""The renderer's particle buffers: Taichi fields sized to the simulator's capacity, filled by
one kernel straight from the particle state (no numpy round trip): fluid particles only (walls,
dummies and particles that left the domain are skipped), positions lifted to 3D (a 2D slice
lies in the plane y = 0), colours from the chosen field. A half or quarter run (symmetry
planes, core/symmetry.py) is drawn whole: each particle with its mirror images."""

from typing import Sequence

import taichi as ti

from ..core.state import FLUID, ParticleState
from .colours import COLOUR_MAP, MILK_HIGH, MILK_LOW, MODE_CODE, ColourScale

SPEED, HEIGHT, PRESSURE, MILK = (MODE_CODE[m] for m in ("speed", "height", "pressure", "milk"))


@ti.data_oriented
class ParticleBuffers:
    def __init__(self, capacity: int, planes: Sequence[int] = ()):
        self.capacity = int(capacity)      # particles of the state; drawn: x copies each
        self.planes = tuple(planes)        # mirror planes (axes: 0 x = 0, 1 y = 0)
        self.copies = [tuple(a for b, a in enumerate(self.planes) if m >> b & 1)
                       for m in range(2 ** len(self.planes))]     # () is the particle itself
        self.pos = ti.Vector.field(3, ti.f32, self.capacity * len(self.copies))
        self.colour = ti.Vector.field(3, ti.f32, self.capacity * len(self.copies))
        self.count = ti.field(ti.i32, shape=())
        self.cmap = ti.Vector.field(3, ti.f32, len(COLOUR_MAP))
        self.cmap.from_numpy(COLOUR_MAP)

    def fill(self, state: ParticleState, scale: ColourScale) -> int:
        """Copy the fluid particles of ``state`` (a ParticleState) and their mirror images;
        returns how many were written."""
        if state.capacity > self.capacity:
            raise ValueError(f"state capacity {state.capacity} exceeds the buffers' "
                             f"{self.capacity}")
        span = scale.hi - scale.lo
        self._fill(state.pos, state.vel, state.pressure, state.kind, state.n, scale.code,
                   scale.lo, 1.0 / span if span > 0 else 0.0)
        return int(self.count[None])

    @ti.func
    def _map(self, t):
        s = ti.math.clamp(t, 0.0, 1.0) * (self.cmap.shape[0] - 1)
        i = ti.min(ti.cast(s, ti.i32), self.cmap.shape[0] - 2)
        f = s - i
        return self.cmap[i] * (1.0 - f) + self.cmap[i + 1] * f

    @ti.kernel
    def _fill(self, pos: ti.template(), vel: ti.template(), pressure: ti.template(),
              kind: ti.template(), n: ti.template(), mode: ti.i32, lo: ti.f32, inv: ti.f32):
        self.count[None] = 0
        for i in range(n[None]):
            if kind[i] == FLUID:
                k = ti.atomic_add(self.count[None], ti.static(len(self.copies)))
                p = ti.cast(pos[i], ti.f32)
                x = ti.Vector([0.0, 0.0, 0.0])
                if ti.static(pos.n == 2):
                    x = ti.Vector([p[0], 0.0, p[1]])
                else:
                    x = ti.Vector([p[0], p[1], p[2]])
                for c in ti.static(range(len(self.copies))):
                    y = x
                    for a in ti.static(self.copies[c]):      # x = 0: axis 0, y = 0: axis 1
                        y[a] = -y[a]
                    self.pos[k + c] = y
                value = x[2]
                if mode == SPEED:
                    value = ti.cast(vel[i].norm(), ti.f32)
                elif mode == PRESSURE:
                    value = ti.cast(pressure[i], ti.f32)
                t = (value - lo) * inv
                c = self._map(t)
                if mode == MILK:
                    c = ti.math.mix(ti.Vector(MILK_LOW), ti.Vector(MILK_HIGH),
                                    ti.math.clamp(t, 0.0, 1.0))
                for m in ti.static(range(len(self.copies))):
                    self.colour[k + m] = c


__all__ = ["ParticleBuffers"]
