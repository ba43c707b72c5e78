"""A session: one compiled Simulator per compiled model, reused between runs.

Values that live in run-time fields (speed, film thickness, liquid, end time, safety numbers)
change through ``Simulator.configure`` + ``load``: no kernel is compiled again and no field is
allocated while the capacity suffices. A scene with more particles than the simulator holds
gets a new one, once, with headroom. What the model compiles in (dimension, which terms,
the gradient form) selects the simulator.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING, Dict, List

from .core.params import Model
from .core.step import Simulator, capacity_for, max_particles

if TYPE_CHECKING:
    from .scenes.base import Scene

HEADROOM = 1.25         # capacity of a reallocated simulator, times the scene's particles


def compiled_kernels() -> int:
    """Kernel instances Taichi has compiled (or loaded from its cache) in this process."""
    from taichi.lang import impl
    return impl.get_runtime().get_num_compiled_functions()


class Session:
    """Holds the simulators; ``load(scene)`` returns one configured and loaded with it."""

    def __init__(self, headroom: float = HEADROOM):
        if not headroom >= 1.0:
            raise ValueError(f"headroom = {headroom!r}; allowed: >= 1")
        self.headroom = headroom
        self._sims: Dict[Model, Simulator] = {}
        self.constructions = 0          # Simulators built (each compiles its kernels)
        self.reallocations = 0          # of them, those that replaced a too-small one
        self.events: List[str] = []     # what each load did, for summaries

    def load(self, scene: Scene) -> Simulator:
        """A simulator for ``scene``'s model, configured with its values and loaded with it."""
        model = Model.of(scene.physics, scene.numerics)
        n = capacity_for(scene)         # the particles, and room for any mirror images
        sim = self._sims.get(model)
        if sim is None:
            sim = self._build(scene, n)
            self.events.append(f"new simulator for {n:,} particles")
        elif sim.state.capacity < n:
            old = sim.state.capacity
            self._sims.pop(model)
            room = min(math.ceil(self.headroom * n), max_particles(model))
            sim = self._build(scene, max(n, room))
            self.reallocations += 1
            self.events.append(f"reallocated: {n:,} particles exceed the capacity {old:,}; "
                               f"new capacity {sim.state.capacity:,}")
        else:
            self.events.append(f"reused the compiled simulator ({n:,} of "
                               f"{sim.state.capacity:,} particles)")
        sim.configure(scene.physics, scene.numerics, scene.domain, scene.floor)
        sim.load(scene.pos, scene.vel, scene.kind)
        return sim

    def _build(self, scene, capacity: int) -> Simulator:
        sim = Simulator(scene.physics, scene.numerics, capacity)
        self._sims[Model.of(scene.physics, scene.numerics)] = sim
        self.constructions += 1
        return sim

    @property
    def simulators(self) -> int:
        return len(self._sims)


__all__ = ["Session", "compiled_kernels", "HEADROOM"]
