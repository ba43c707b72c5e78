"""Analytic plane floor (method.md §5 walls, as distance tables): the wall and dummy layers
under a flat floor replaced by their contributions, tabulated on the host against the height s
of a fluid particle above the floor surface (the plane z = 0 of the last axis, where every
scene builder puts its floor).

The layers it stands for are the ones the scene builders lay (scenes/base.py): the fluid
lattice continued below the surface, wall particles at s = -l0/2 and ``layers - 1`` dummy
layers under them. The tables are summed for a particle right above a column of that lattice,
so a fluid lattice at rest sees exactly the number density it would see with the particles;
a particle between columns sees the same values (the particle floor's lateral ripple is left
out). Per height s, six sums over the layers' points j within re (within H = 3 l0 for d_floor,
the divergence's pair support):

- n_floor(s) = sum over every layer of w(r)                 -> number density (S9)
- g_floor(s) = sum over the wall layer of (z_j - z_i) w / r^2 -> pressure gradient (S11), the
  floor's wall particles at the pressure of a hydrostatic mirror, P_i + rho g (s + l0/2)
  (P_i without gravity): with P_j = P_i the floor pushed too little and the 2D tank's floor
  pressure read 6.6 % low
- v_floor(s) = sum over the wall layer of w(r)              -> viscosity (S12), u_j = 0
- vn_floor(s) = sum over the wall layer of w (z_j - z_i)^2 / r^2 -> the central viscosity's
  normal part (V1, core/viscosity.py), u_j = 0
- c_floor(s) = sum over every layer of (z_j - z_i) f(r)     -> the surface-stress model's
  colour gradient (method.md C1): the floor is no free surface
- d_floor(s) = sum over every layer of (z_j - z_i) f_d(r)   -> its divergence (C3), T_j = 0

and a particle closer than the collision distance to the wall layer's plane loses its
approach speed as against a wall particle (the collision model, terms.py).
"""
from __future__ import annotations

import math
from typing import Optional, Tuple

import numpy as np
import taichi as ti

from .lattice import stress_kernel, stress_pair_kernel, stress_pair_support, weight

SAMPLES = 1024
FLOOR_N, FLOOR_G, FLOOR_V, FLOOR_C, FLOOR_D, FLOOR_VN = 0, 1, 2, 3, 4, 5
FLOOR_SUMS = 6


def floor_tables(dim: int, l0: float, re: float, layers: int, samples: int = SAMPLES,
                 reach: Optional[float] = None) -> Tuple[float, float, np.ndarray]:
    """(s0, ds, table[samples, FLOOR_SUMS]): n_floor, g_floor (the component along the last
    axis), v_floor, c_floor, d_floor (along the last axis) and vn_floor at s = s0 + k ds,
    from s0 = -l0/4 (closer, the collision model has acted; the table holds its last value)
    to reach - l0/2 (beyond, no floor point is within reach). ``reach``: the widest walk, re
    (the default) or, for the surface stress, its pair support H (Model.wide_walk): d_floor
    is summed within H but tabulated only as far as the walks reach."""
    h = stress_pair_support(dim, l0, re / l0)
    reach = re if reach is None else reach
    s0, s1 = -0.25 * l0, reach - 0.5 * l0
    ds = (s1 - s0) / (samples - 1)
    m = int(math.ceil(max(reach, re, h) / l0))
    lateral = np.array(np.meshgrid(*[np.arange(-m, m + 1)] * (dim - 1), indexing="ij"))
    lateral = lateral.reshape(dim - 1, -1).T * l0                  # points of one layer
    lat2 = (lateral ** 2).sum(axis=1)
    table = np.zeros((samples, FLOOR_SUMS))
    for k in range(samples):
        s = s0 + k * ds
        for layer in range(layers):
            dz = -(layer + 0.5) * l0 - s                           # z_j - z_i
            r = np.sqrt(lat2 + dz * dz)
            w = weight(r, re)
            table[k, FLOOR_N] += w.sum()
            table[k, FLOOR_C] += (dz * stress_kernel(r, re)).sum()
            table[k, FLOOR_D] += (dz * stress_pair_kernel(r, h)).sum()
            if layer == 0:
                table[k, FLOOR_G] += (dz / (r * r) * w).sum()
                table[k, FLOOR_V] += w.sum()
                table[k, FLOOR_VN] += (w * dz * dz / (r * r)).sum()
    return s0, ds, table


@ti.data_oriented
class PlaneFloor:
    def __init__(self):
        self.table = ti.Vector.field(FLOOR_SUMS, float, SAMPLES)
        self.s0 = ti.field(float, shape=())
        self.inv_ds = ti.field(float, shape=())
        self.wall_depth = ti.field(float, shape=())    # the wall layer's plane: s = -l0/2

    def set(self, dim: int, l0: float, re: float, layers: int,
            reach: Optional[float] = None) -> None:
        """The tables for this spacing, to ``reach`` (floor_tables; re by default)."""
        s0, ds, table = floor_tables(dim, l0, re, layers, reach=reach)
        self.s0[None] = s0
        self.inv_ds[None] = 1.0 / ds
        self.wall_depth[None] = 0.5 * l0
        fdt = np.float64 if ti.lang.impl.current_cfg().default_fp == ti.f64 else np.float32
        self.table.from_numpy(table.astype(fdt))

    def nbytes(self) -> int:
        from .state import field_nbytes
        return field_nbytes(self.table)

    @ti.func
    def at(self, s):
        """(n_floor, g_floor, v_floor, c_floor, d_floor, vn_floor) at height s, linear between
        samples; zero past the top."""
        # clamped before the cast: a height far up (or inf, NaN) would cast to INT_MIN
        x = ti.min((ti.max(s, self.s0[None]) - self.s0[None]) * self.inv_ds[None],
                   float(SAMPLES - 1))
        row = ti.max(ti.min(ti.cast(ti.floor(x), ti.i32), SAMPLES - 1), 0)
        frac = ti.min(x - row, 1.0)
        upper = ti.min(row + 1, SAMPLES - 1)      # the last sample is zero: zero past it
        return (1.0 - frac) * self.table[row] + frac * self.table[upper]

    @ti.func
    def colour_at(self, s):
        """c_floor at height s (the module docstring's fourth sum)."""
        return self.at(s)[FLOOR_C]

    @ti.func
    def divergence_at(self, s):
        """d_floor at height s (the module docstring's fifth sum)."""
        return self.at(s)[FLOOR_D]


__all__ = ["PlaneFloor", "floor_tables", "FLOOR_N", "FLOOR_G", "FLOOR_V", "FLOOR_C",
           "FLOOR_D", "FLOOR_VN", "FLOOR_SUMS"]
