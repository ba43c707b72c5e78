"""Constants of the explicit MPS model computed on a perfect cubic lattice (host side).

n0 and lambda0 (method.md S13) and the surface-tension coefficient C (S23) depend only on the
dimension, l0 and re, so they are computed here from lattice offsets, never from a scene.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from . import params
from .params import (STRESS_NEIGHBOURHOODS, ParameterError, stress_neighbourhood,
                     stress_surface_pairs)

# l0 at which the lattice sums (l0^-1 .. l0^3, and rho l0^3) stay finite, non-zero floats; a
# user's spacing is checked against its command's own, narrower range first (cli/info_lattice.py)
L0_FLOAT_RANGE = (1.0e-100, 1.0e100)


def weight(r: np.ndarray, re: float) -> np.ndarray:
    """w(r) = re/r - 1 for 0 < r < re, else 0 (S10)."""
    r = np.asarray(r, dtype=float)
    out = np.zeros_like(r)
    inside = (r > 0) & (r < re)
    out[inside] = re / r[inside] - 1.0
    return out


def potential_shape(r: np.ndarray, l0: float, re: float) -> np.ndarray:
    """Phi(r) = P(r)/C = (1/3)(r - 1.5 l0 + 0.5 re)(r - re)^2 for r <= re, else 0 (S22)."""
    r = np.asarray(r, dtype=float)
    return np.where(r <= re, (r - 1.5 * l0 + 0.5 * re) * (r - re) ** 2 / 3.0, 0.0)


def wall_layers(re_ratio: float) -> int:
    """Layers of wall + dummy particles so that wall particles see a full neighbourhood (§5)."""
    return int(math.ceil(re_ratio - 1e-9))


def lattice_offsets(dim: int, l0: float, reach: float) -> np.ndarray:
    """All lattice vectors k*l0 (k integer, k != 0) with |k l0| < reach."""
    m = int(math.ceil(reach / l0))
    ks = np.array(list(itertools.product(range(-m, m + 1), repeat=dim)), dtype=float)
    ks = ks[np.any(ks != 0, axis=1)] * l0
    return ks[np.linalg.norm(ks, axis=1) < reach]


def n0_lambda0(dim: int, l0: float, re: float) -> tuple[float, float]:
    """Reference number density n0 (S9 on the lattice) and lambda0 (S13)."""
    r = np.linalg.norm(lattice_offsets(dim, l0, re), axis=1)
    w = weight(r, re)
    n0 = float(w.sum())
    return n0, float((r ** 2 * w).sum() / n0)


def cut_potential_sum(dim: int, l0: float, re: float) -> float:
    """sum_{i in A} sum_{j across} Phi(r_ij) for a plane cut midway between lattice layers (S23).

    A is the lattice column (0, ..., 0, -k l0), k >= 0, below the cut at z = l0/2; the partners
    j are every lattice point with z >= l0 within re of it.
    """
    m = int(math.ceil(re / l0))
    total = 0.0
    for k in range(m + 1):                      # column particles deeper than re see nothing
        zi = -k * l0
        for off in lattice_offsets(dim, l0, re):
            if zi + off[-1] > 0.5 * l0:           # partner on the other side of the cut
                total += float(potential_shape(np.linalg.norm(off), l0, re))
    return total


def surface_tension_coefficient(dim: int, l0: float, re: float, sigma: float) -> float:
    """C of the potential model (S23): 2 sigma l0^(d-1) = -C sum_A sum_j Phi(r_ij); C <= 0."""
    if sigma == 0.0:
        return 0.0
    return -2.0 * sigma * l0 ** (dim - 1) / cut_potential_sum(dim, l0, re)


def surface_weight(n, n0: float, beta: float):
    """omega = clamp((1 - n/n0) / (2 (1 - beta)), 0, 1) (C1, method.md §4c): numpy's twin of
    pressure.surface_weight, for the study tools and lattice sums."""
    return np.clip((1.0 - np.asarray(n, dtype=float) / n0) / (2.0 * (1.0 - beta)), 0.0, 1.0)


def stress_kernel(r: np.ndarray, re: float) -> np.ndarray:
    """f(r) = (1 - r/re)^3 for r < re, else 0: the surface-stress model's pair weight (method.md
    §4c, C1): r_ij f(r) is a Wendland C2 kernel's gradient, bounded where w/r^2 is not."""
    r = np.asarray(r, dtype=float)
    return np.where(r < re, (1.0 - np.minimum(r, re) / re) ** 3, 0.0)


def stress_pair_support(dim: int, l0: float, re_ratio: float) -> float:
    """H: the support of the divergence's pair weight (C3) in ``dim`` at re = ``re_ratio`` l0,
    its neighbourhood's (params.STRESS_NEIGHBOURHOODS: 3 l0, or 4.1 l0 in 3D at 3.1 l0); read
    at each call, so a study that sets it moves every reader."""
    return params.stress_pair_support(dim, re_ratio) * l0


def stress_pair_kernel(r: np.ndarray, h: float) -> np.ndarray:
    """f_d(r) = (1 - (r/h)^4)^2 for r < h, else 0, h = H (stress_pair_support): the
    divergence's pair weight (C3). Zero with zero slope at h, so the tension a flat surface
    carries hardly depends on how closely its outer layer sits (within 5 % for spacings
    0.95-1.15 l0; VALIDATION.md, "The pair kernel's edge"); the pair force r f_d(r) grows with
    r up to 0.58 h = 1.74 l0, so a tension along the surface pulls two particles less as they
    close (no clumping at the lattice spacing). The step's kernel also has a repulsive core
    below l0 (surface_tension/stress.py), where no lattice pair lies: the lattice sums here do
    not see it."""
    r = np.asarray(r, dtype=float)
    return np.where(r < h, (1.0 - (np.minimum(r, h) / h) ** 4) ** 2, 0.0)


def stress_gradient_norm(dim: int, l0: float, re: float, kernel=stress_kernel,
                         support: float = None) -> float:
    """K = d / sum_j r^2 f(r) on the lattice, over the offsets within ``support`` (re if not
    given; f = kernel(r, support)): the normalisation that makes the pair sum K sum_j (phi_j -
    phi_i) r_ij f(r_ij) the exact gradient of a linear phi (C1, C3)."""
    h = re if support is None else support
    r = np.linalg.norm(lattice_offsets(dim, l0, h), axis=1)
    return dim / float((r ** 2 * kernel(r, h)).sum())


def colour_gradient_column(dim: int, l0: float, re: float) -> np.ndarray:
    """|g_k| for the layers k = 0, 1, ... of a lattice half-space z <= 0 (layer k at z = -k l0,
    down to the first one deeper than re, where g = 0): g_i = K sum_j r_ij f(r_ij) over the
    lattice points j within re of i (method.md §4c, C1), here along the last axis."""
    offs = lattice_offsets(dim, l0, re)
    f = stress_kernel(np.linalg.norm(offs, axis=1), re)
    K = stress_gradient_norm(dim, l0, re)
    m = int(math.ceil(re / l0))
    out = np.zeros(m + 1)
    for k in range(m + 1):
        present = -k * l0 + offs[:, -1] <= 0.5 * l0 * 1e-6       # j in the half-space
        out[k] = abs(K * float((offs[present, -1] * f[present]).sum()))
    return out


def layer_number_densities(dim: int, re_ratio: float, layers: int) -> np.ndarray:
    """n of the layers k = 0 .. layers - 1 of a flat lattice half-space z <= 0 (layer k at z = -k
    l0, S9) over n0: the free surface's number-density deficit layer by layer."""
    offs = lattice_offsets(dim, 1.0, re_ratio)
    w = weight(np.linalg.norm(offs, axis=1), re_ratio)
    return np.array([w[offs[:, -1] <= k + 1e-9].sum() for k in range(layers)]) / w.sum()


def surface_band_weight(n_over_n0, band: float):
    """omega = clamp((1 - n/n0) / band, 0, 1): the surface pairs' weight of a particle (C3
    with stress_pairs: surface, method.md §4c); numpy's twin of stress.py's."""
    return np.clip((1.0 - np.asarray(n_over_n0, dtype=float)) / band, 0.0, 1.0)


def stress_cut_sums(dim: int, re_ratio: float, layer_weights=None, pair_weight=None
                    ) -> tuple[float, float]:
    """The sum form's (C3) cut sum across a flat lattice face, l0 = 1: sum_k sum_{r_x > 0} r_x^2
    f_d(r) (|g_k| + |g_k'|) over the face's layers k and their partners j = i + r in layer k'
    (|r| < H), as it is and with each term times the pair's weight, pair_weight(w_k, w_k')
    (default their mean, C3's surface pairs) of ``layer_weights`` (w of the layers k = 0, 1,
    ...; None: the plain sum twice)."""
    h = stress_pair_support(dim, 1.0, re_ratio)
    offs = lattice_offsets(dim, 1.0, h)
    f = stress_pair_kernel(np.linalg.norm(offs, axis=1), h)
    g = colour_gradient_column(dim, 1.0, re_ratio)
    m = len(g) - 1
    if layer_weights is None:
        layer_weights = np.ones(m + int(math.ceil(h)) + 2)
    plain = weighted = 0.0
    for k in range(m + 1):
        for off, ff in zip(offs, f):
            kj = k - int(round(off[-1]))           # j's layer (z_j = -kj)
            if off[0] > 0 and kj >= 0:
                gj = g[kj] if kj <= m else 0.0
                term = off[0] ** 2 * ff * (g[k] + gj)
                plain += term
                wk, wj = layer_weights[k], layer_weights[kj]
                weighted += term * (0.5 * (wk + wj) if pair_weight is None
                                    else pair_weight(wk, wj))
    return plain, weighted


def stress_normaliser(dim: int, l0: float, re: float) -> float:
    """a of the surface-stress model (method.md §4c, C2): the factor that makes the flat
    lattice surface carry sigma. Across a cut normal to x through the half-space, the sum form
    of the divergence (C3) transmits, per unit length of the surface (and depth in 2D),
    a sigma l0 K_d sum_k sum_{r_x > 0} r_x^2 f_d(r) (|g_k| + |g_k'|) (j = i + r in layer k',
    |r| < H; ``stress_cut_sums``); a makes that sigma. Dimensionless (l0 = 1 here)."""
    ratio = re / l0
    K = stress_gradient_norm(dim, 1.0, ratio, stress_pair_kernel,
                             stress_pair_support(dim, 1.0, ratio))
    return 1.0 / (K * stress_cut_sums(dim, ratio)[0])


def _surface_layers(dim: int, re_ratio: float, band: float) -> np.ndarray:
    """C3b's omega of a flat lattice face's layers k = 0, 1, ... (as many as its cut sum
    reaches)."""
    layers = len(colour_gradient_column(dim, 1.0, re_ratio)) + int(
        math.ceil(stress_pair_support(dim, 1.0, re_ratio))) + 1
    return surface_band_weight(layer_number_densities(dim, re_ratio, layers), band)


def surface_pairs_ratio(dim: int, re_ratio: float, band: float) -> float:
    """a's factor with stress_pairs: surface (C3b: C3's pairs times the mean of their
    particles' ``surface_band_weight``): the flat lattice face's plain cut sum over its
    weighted one, so that the face still carries sigma (C3b's L_i has a mean gain of 1 along
    the face, so it adds nothing here)."""
    plain, weighted = stress_cut_sums(dim, re_ratio, _surface_layers(dim, re_ratio, band))
    return plain / weighted


def face_balance_factor(dim: int, re_ratio: float) -> float:
    """F = n0 / (2 d G l0), G the lattice half-space's sum of -r_z w / r^2 over the offsets
    below a face particle (S11's pair term): the factor at which the sum form's push of a
    uniform pressure P on a flat lattice face's particle, 2 d P G / n0, equals the pull rho
    l0 F a_i.g_i/|g_i| that C4 sets its pressure from (method.md §4c). 1.016 / 1.011 (2D /
    3D) at 2.1 l0, 1.160 / 1.187 at 3.1 l0. Dimensionless."""
    q = lattice_offsets(dim, 1.0, re_ratio)
    w = weight(np.linalg.norm(q, axis=1), re_ratio)
    below = q[:, -1] < 0
    G = -float((q[below, -1] * w[below] / (q[below] ** 2).sum(axis=1)).sum())
    return float(w.sum()) / (2 * dim * G)


def stress_constants(dim: int, re_ratio: float, pairs: str = "all") -> tuple[float, float]:
    """The stress member's (C4's F, C5's delta in l0) at ``re_ratio`` with C3's ``pairs``
    (params.STRESS_NEIGHBOURHOODS, STRESS_PAIRS; a ParameterError for a neighbourhood it has
    none for)."""
    own = STRESS_NEIGHBOURHOODS[stress_neighbourhood(re_ratio)]
    factor = own["c4_factor"][dim]
    if factor == "lattice":
        factor = face_balance_factor(dim, re_ratio)
    if pairs != "all":
        own = stress_surface_pairs(re_ratio)
    delta = own["tolman"][dim]
    return float(factor), float(delta)


def stress_pairs_scale(dim: int, re_ratio: float, pairs: str = "all") -> float:
    """a's factor for C3's ``pairs``: 1 for all of them; for the surface pairs the flat lattice
    face's (``surface_pairs_ratio``, so the face carries sigma) times the tension factor that
    the neighbourhood measured on drops (params.STRESS_NEIGHBOURHOODS' "surface_pairs")."""
    if pairs == "all":
        return 1.0
    return surface_pairs_ratio(dim, re_ratio, params.STRESS_SURFACE_BAND) * float(
        stress_surface_pairs(re_ratio)["factor"][dim])


@dataclass(frozen=True)
class LatticeConstants:
    dim: int
    l0: float
    re: float
    n0: float
    lambda0: float
    C: float
    mass: float   # rho l0^d (per unit depth in 2D)
    stress_a: float = 0.0   # the surface-stress model's normaliser a (C2)
    stress_K: float = 0.0   # the colour gradient's normalisation K (C1) [1/m^2]
    stress_Kd: float = 0.0  # the divergence's normalisation K_d (C3) [1/m^2]

    @classmethod
    def compute(cls, dim: int, l0: float, re_ratio: float, rho: float, sigma: float
                ) -> "LatticeConstants":
        lo, hi = L0_FLOAT_RANGE
        if not lo <= l0 <= hi:      # beyond, l0 ** 3 overflows or the cut sum is 0 (S23)
            raise ParameterError("l0", l0, f"{lo:g} .. {hi:g} m (the lattice sums stay finite "
                                 "floats)", "lattice")
        re = re_ratio * l0
        n0, lam = n0_lambda0(dim, l0, re)
        return cls(dim, l0, re, n0, lam, surface_tension_coefficient(dim, l0, re, sigma),
                   rho * l0 ** dim, stress_normaliser(dim, l0, re),
                   stress_gradient_norm(dim, l0, re),
                   stress_gradient_norm(dim, l0, re, stress_pair_kernel,
                                        stress_pair_support(dim, l0, re_ratio)))


def lattice_cohesion_pressure(dim: int, l0: float, re: float, C: float) -> float:
    """The potential model's stress in a perfect lattice (method.md S22, force per the §4 sign
    note): (1/(2 d l0^d)) sum_j -C (r - l0)(r - re) r over the neighbours within re. Negative
    (a tension) for C < 0; inside a resting liquid the equation-of-state pressure balances it,
    so P_EOS = -this + the Laplace jump. In 2D it is -2.25 sigma/l0 and in 3D -3.04 sigma/l0
    at re = 2.1 l0: the jump (sigma/R) is a small difference of large terms."""
    reach = int(np.ceil(re / l0))
    axis = np.arange(-reach, reach + 1)
    pts = np.stack(np.meshgrid(*[axis] * dim, indexing="ij"), -1).reshape(-1, dim) * l0
    r = np.linalg.norm(pts, axis=1)
    r = r[(r > 0) & (r < re)]
    return float(np.sum(-C * (r - l0) * (r - re) * r) / (2 * dim * l0 ** dim))
