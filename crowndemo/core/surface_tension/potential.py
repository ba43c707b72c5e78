"""The seed's surface tension: the inter-particle potential (method.md §4, S22-S24, Kondo et
al. 2007), a pair force in the predictor's walk. Its coefficient C comes from the lattice
cut (S23, core/lattice.py) and is held as C/m in ``Coefficients.st_over_m``."""
import taichi as ti

from ..coefficients import Coefficients
from ..grid import CellGrid
from ..params import Model


@ti.func
def surface_tension_pair(rij, r, l0, re):
    """Minus the gradient of the inter-particle potential (S22) for one pair, per unit C:
    (r - l0)(r - re) r_ij / r with r_ij = r_j - r_i (method.md §4 sign note).
    Times C/m (C <= 0) it attracts for l0 < r < re and repels for r < l0."""
    return (r - l0) * (r - re) / r * rij


@ti.data_oriented
class PotentialTension:
    """a_i = (C/m) sum_j (r_ij - l0)(r_ij - re) (r_j - r_i)/r_ij over fluid j (S24, sign per
    method.md §4)."""
    name = "potential"
    pair_term = True

    def __init__(self, model: Model, grid: CellGrid, coef: Coefficients):
        self.coef = coef

    @ti.func
    def pair(self, rij, r):
        return surface_tension_pair(rij, r, self.coef.l0[None], self.coef.re[None])

    @ti.func
    def finish(self, acc):
        return self.coef.st_over_m[None] * acc

    def boundary_pressure(self, dt: float = 0.0) -> None:
        """The potential acts through the predictor only."""

    def nbytes(self) -> int:
        return 0
