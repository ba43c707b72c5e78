"""Scene builders: particles, parameters and domain for each kind of run."""
from .base import Scene, container_walls, lattice_block, wall_layers
from .reference import circularity, dam_break, equivalent_radius, hydrostatic_tank, square_patch

__all__ = ["Scene", "container_walls", "lattice_block", "wall_layers", "circularity", "dam_break",
           "equivalent_radius", "hydrostatic_tank", "square_patch"]
