"""Viscosity as a family (docs/architecture.md): the predictor's viscous pair term, chosen by
name with ``numerics.viscosity`` and compiled in only when nu > 0 (``Model.viscosity``).

A member holds, for the predictor's walk (terms.py) under ``ti.static``:

- ``factor(dim)``: the constant in front of the pair sum, over lambda0 n0 (a Python float);
- ``pair(du, rij, r2, w)``: one pair's term, du = u_j - u_i (a ``ti.func``);
- ``floor(u, v_floor, vn_floor)``: the analytic plane floor's wall layer at rest (u_j = 0),
  from its tables v_floor = sum w and vn_floor = sum w (z_ij / r)^2 (plane_floor.py).

Its stiffness, which scales the viscous time-step limit, is params.VISCOUS_STIFFNESS's.

Members:

- ``laplacian``: the seed's Laplacian model (S12), nu 2d/(lambda0 n0) sum (u_j - u_i) w.
  In the interior it is nu lap u. Its rate of work, summed over the pairs, is
  -nu 2d/(lambda0 n0) 1/2 sum |u_j - u_i|^2 w -> -mu |grad u|^2 per volume: with no pairs
  across a free surface it dissipates mu |grad u|^2, where the Navier-Stokes equations
  with a stress-free surface dissipate 2 mu e:e (e the strain rate). For an irrotational flow
  (grad u = e) that is half: a free drop's oscillation decays at half Lamb's rate
  (VALIDATION.md, "The decay is not Lamb's").
- ``central``: the pair term along r_ij (the central form of SPH viscosity, Monaghan 2005,
  Rep. Prog. Phys. 68: 1703, §6; written here with the MPS weight and its lambda0),
  nu 2d(d+2)/(lambda0 n0) sum ((u_j - u_i).r_ij) r_ij / r^2 w (method.md V1). In the
  interior it is nu (lap u + 2 grad div u) (the isotropic fourth moment of the unit vectors,
  1/(d(d+2)) (delta delta + 2 perms)), nu lap u for an incompressible flow; its pair forces
  are central, so it keeps angular momentum and a rigid rotation feels none; its rate of
  work is -nu 2d(d+2)/(lambda0 n0) 1/2 sum ((u_j - u_i).e)^2 w -> -mu (2 e:e + (div u)^2),
  Lamb's dissipation with no surface term to miss (Colagrossi et al., Phys. Rev. E 84,
  026705, 2011, analyse SPH's viscous terms at a free surface).
"""
from __future__ import annotations

from typing import Dict

import taichi as ti

from .operators import laplacian_pair
from .params import VISCOSITY_MODELS


class LaplacianViscosity:
    """nu 2d/(lambda0 n0) sum (u_j - u_i) w (S12; the seed's)."""

    @staticmethod
    def factor(dim: int) -> float:
        return 2.0 * dim

    @staticmethod
    @ti.func
    def pair(du, rij, r2, w):
        return laplacian_pair(du, w)

    @staticmethod
    @ti.func
    def floor(u, v_floor, vn_floor):
        return -u * v_floor


class CentralViscosity:
    """nu 2d(d+2)/(lambda0 n0) sum ((u_j - u_i).r_ij) r_ij / r^2 w (method.md V1)."""

    @staticmethod
    def factor(dim: int) -> float:
        return 2.0 * dim * (dim + 2)

    @staticmethod
    @ti.func
    def pair(du, rij, r2, w):
        return du.dot(rij) / r2 * w * rij

    @staticmethod
    @ti.func
    def floor(u, v_floor, vn_floor):
        # the layer's sum of w e e^T is diagonal (the layer's lattice is symmetric about the
        # normal): vn_floor along the normal (the last axis), (v_floor - vn_floor)/(d - 1)
        # along each axis of the plane
        dim = ti.static(u.n)
        a = -u * (v_floor - vn_floor) / (dim - 1)
        a[dim - 1] = -u[dim - 1] * vn_floor
        return a


MODELS: Dict[str, type] = {"laplacian": LaplacianViscosity, "central": CentralViscosity}
assert tuple(MODELS) == VISCOSITY_MODELS     # the names params.py validates against


def member(name: str) -> type:
    """The viscosity member called ``name`` (VISCOSITY_MODELS)."""
    return MODELS[name]


__all__ = ["MODELS", "member", "LaplacianViscosity", "CentralViscosity"]
