"""Scene builders: particles, parameters and domain for each kind of run."""
from .base import Scene, container_walls, lattice_block, wall_layers
from .crown import crown, crown_base_radius
from .reference import circularity, dam_break, equivalent_radius, hydrostatic_tank, square_patch

__all__ = ["crown", "crown_base_radius", "Scene", "container_walls", "lattice_block", "wall_layers", "circularity", "dam_break",
           "equivalent_radius", "hydrostatic_tank", "square_patch"]
