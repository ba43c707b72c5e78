"""The explicit MPS solver (method.md), dimension-generic: 2D and 3D share every kernel."""
from typing import TYPE_CHECKING, Optional

from .health import HealthReport, InstabilityError
from .lattice import LatticeConstants
from .params import Model, Numerics, ParameterError, Physics
from .state import DUMMY, FLUID, GONE, WALL
from .step import RunStats, Simulator, capacity_for

if TYPE_CHECKING:
    from ..scenes.base import Scene

__all__ = ["HealthReport", "InstabilityError", "LatticeConstants", "Model", "Numerics",
           "ParameterError", "Physics", "RunStats", "Simulator", "FLUID", "WALL", "DUMMY", "GONE",
           "simulator_for"]


def simulator_for(scene: "Scene", capacity: Optional[int] = None,
                  max_cells: Optional[int] = None) -> Simulator:
    """A simulator sized for a scene, configured with its parameters and loaded with it."""
    sim = Simulator(scene.physics, scene.numerics, capacity or capacity_for(scene), max_cells)
    sim.configure(scene.physics, scene.numerics, scene.domain, scene.floor)
    sim.load(scene.pos, scene.vel, scene.kind)
    return sim
