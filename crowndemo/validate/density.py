"""The number-density excess n/n0 - 1 of one frame, measured two ways (issue 21):

- local: the largest over the fluid particles, what the health check watches (core/health.py).
  It is set by a few particles clumped where the drop meets the film or on the free surface;
- bulk: the 99th percentile over the interior fluid particles, those with a full
  neighbourhood: no free-surface particle (n < beta n0, M3 of method.md) within re of them
  (and not on the free surface themselves). It measures the compression of the liquid, which
  the equation of state P = c^2 rho (n - n0)/n0 (S17) keeps near (U/c)^2.

``n`` is the snapshot's number density (S9) at the frame's positions (Simulator.refresh_pressure)."""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from .clusters import close_pairs

BULK_PERCENTILE = 99.0


@dataclass
class DensityExcess:
    local: float          # max n/n0 - 1 over the fluid
    bulk: float           # BULK_PERCENTILE-th percentile of n/n0 - 1 over the interior fluid
    bulk_mean: float      # mean of n/n0 - 1 over the interior fluid
    interior: int         # interior fluid particles
    fluid: int

    def as_dict(self) -> dict:
        return asdict(self)


def interior_mask(pos: np.ndarray, n: np.ndarray, n0: float, re: float,
                  beta: float) -> np.ndarray:
    """Fluid particles (rows of ``pos``, number densities ``n``) with no free-surface particle
    (n < beta n0) within ``re``, themselves included."""
    surface = np.asarray(n) < beta * n0
    i, j = close_pairs(pos, re)
    near = surface.copy()
    near[i[surface[j]]] = True
    near[j[surface[i]]] = True
    return ~near


def density_excess(pos: np.ndarray, n: np.ndarray, n0: float, re: float,
                   beta: float) -> DensityExcess:
    """Local and bulk excess of the fluid particles ``pos`` with number densities ``n``."""
    pos, n = np.asarray(pos, dtype=float), np.asarray(n, dtype=float)
    if len(n) == 0:
        return DensityExcess(math.nan, math.nan, math.nan, 0, 0)
    excess = n / n0 - 1.0
    inside = interior_mask(pos, n, n0, re, beta)
    bulk = excess[inside]
    if len(bulk) == 0:
        return DensityExcess(float(excess.max()), math.nan, math.nan, 0, len(n))
    return DensityExcess(float(excess.max()), float(np.percentile(bulk, BULK_PERCENTILE)),
                         float(bulk.mean()), int(len(bulk)), int(len(n)))


__all__ = ["DensityExcess", "density_excess", "interior_mask", "BULK_PERCENTILE"]
