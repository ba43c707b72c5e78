"""Surface tension as a family (docs/architecture.md): one module per model behind one small
interface, chosen by name with ``numerics.surface_tension`` and compiled in only when
sigma > 0 (``Model.surface_tension``).

A member is a ``ti.data_oriented`` object with

- ``pair_term``: True if it adds a pair term to the predictor's walk (method.md §3 step 1);
  then ``pair(rij, r)`` (a ``ti.func``, the term of one fluid-fluid pair j of i, r_ij = r_j -
  r_i) and ``finish(acc)`` (a ``ti.func``, the acceleration from the summed terms) are called
  by the predictor under ``ti.static``;
- ``boundary_pressure(dt)``: called right after the number density and pressure at r* (S17,
  M3), before the corrector; a member that acts through the pressure sets it there, one that
  acts in the corrector computes its acceleration there (a no-op else); ``dt`` is the step's,
  0 where the pressure is refreshed for output (what a member carries from step to step, the
  stress's lagged C5, must not advance then);
- ``corrector_term`` (optional, False if absent): True if the corrector adds the member's
  ``acceleration(i)`` (a ``ti.func``) to the pressure gradient's (S18);
- ``attach(floor, symmetry)`` (optional): the simulator's plane floor and mirror planes;
- ``nbytes()``: the memory of its own fields.

Members: ``potential`` (the seed's inter-particle potential, S22-S24, Kondo et al. 2007),
``stress`` (the continuum surface stress, method.md §4c, Lafaurie et al. 1994; stress.py) and
``curvature`` (the Young-Laplace pressure sigma kappa on free-surface particles, Tsujimura,
Kubota & Sato 2023, with kappa from a least-squares fit of the surface; curvature.py;
experimental: it does not hold a drop).
"""
from typing import Dict, Optional, Type

from ..coefficients import Coefficients
from ..grid import CellGrid
from ..params import SURFACE_TENSION_MODELS, Model
from .curvature import CurvatureTension
from .potential import PotentialTension
from .stress import StressTension

MODELS: Dict[str, Type] = {"potential": PotentialTension, "stress": StressTension,
                           "curvature": CurvatureTension}
assert tuple(MODELS) == SURFACE_TENSION_MODELS     # the names params.py validates against


def create(model: Model, grid: CellGrid, coef: Coefficients, floor: Optional[object] = None,
           symmetry: Optional[object] = None) -> Optional[object]:
    """The member ``model.surface_tension_model`` for this model, or None without surface
    tension (sigma = 0: nothing compiled in). ``floor`` and ``symmetry``: the simulator's
    analytic plane floor and mirror planes, for a member whose passes need them."""
    if not model.surface_tension:
        return None
    member = MODELS[model.surface_tension_model](model, grid, coef)
    if hasattr(member, "attach"):
        member.attach(floor, symmetry)
    return member


__all__ = ["MODELS", "create", "PotentialTension", "StressTension", "CurvatureTension"]
