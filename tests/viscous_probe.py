"""Shared by the viscosity tests (test_viscosity, test_viscous_flow, test_mode_power_tool): the
lattice's fourth moments, which the central viscosity's sums on the lattice are exact in, the
drop cases' disordered ball, and a Simulator of fluid particles without surface tension or
gravity, whose forces a test probes one call at a time."""
import numpy as np

from crowndemo.core import Numerics, Physics, Simulator
from crowndemo.core.lattice import lattice_offsets, weight
from crowndemo.core.params import with_values
from crowndemo.scenes.drop import ball

L0 = 2.0 ** -9          # a power of two: lattice positions are exact in float
RE_RATIO = 2.1
RHO = 1000.0
NU = 1.0e-3


def fourth_moments(dim: int, re_ratio: float = RE_RATIO) -> tuple:
    """m4 = sum_j w x^4 / r^2 and m22 = sum_j w x^2 z^2 / r^2 over the lattice (in l0^2)."""
    q = lattice_offsets(dim, 1.0, re_ratio)
    r2 = (q * q).sum(axis=1)
    w = weight(np.sqrt(r2), re_ratio)
    return (float((w * q[:, 0] ** 4 / r2).sum()),
            float((w * q[:, 0] ** 2 * q[:, -1] ** 2 / r2).sum()))


def disordered_ball(dim: int, radius_l0: float, jitter: float) -> np.ndarray:
    """The drop cases' start (scenes/drop.oscillating_drop's): the lattice points within
    radius_l0 L0 of the centre, each moved by up to jitter L0 along each axis (scenes'
    seeded disorder)."""
    return ball(dim, radius_l0 * L0, L0, jitter)


def probe_simulator(dim: int, count: int, viscosity: str) -> Simulator:
    """A Simulator for ``count`` particles at spacing L0 in [-1, 1]^dim: viscosity NU by the
    named member, the sum form of the pressure gradient (M2), no surface tension, gravity or
    collision model."""
    physics = Physics(dim=dim, l0=L0, v_max=1.0, re_ratio=RE_RATIO, rho=RHO, nu=NU, sigma=0.0,
                      gravity=0.0, sound_speed=5.0)
    numerics = with_values(Numerics(), viscosity=viscosity, pressure_gradient="sum",
                           collision=0.0)
    sim = Simulator(physics, numerics, count)
    sim.configure(physics, numerics, (tuple([-1.0] * dim), tuple([1.0] * dim)))
    return sim
