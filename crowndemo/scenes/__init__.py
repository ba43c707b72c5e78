"""Scene builders: particles, parameters and domain for each kind of run."""
from ..core.lattice import wall_layers
from .base import Scene, container_walls, lattice_block
from .crown import crown, crown_base_radius
from .reference import (circularity, dam_break, equivalent_radius, hydrostatic_tank,
                        layer_middle, momentum_deficit, shear_amplitude, shear_wave,
                        sliding_layer, square_patch)

__all__ = ["Scene", "circularity", "container_walls", "crown", "crown_base_radius", "dam_break",
           "equivalent_radius", "hydrostatic_tank", "lattice_block", "layer_middle",
           "momentum_deficit", "shear_amplitude", "shear_wave", "sliding_layer", "square_patch",
           "wall_layers"]
