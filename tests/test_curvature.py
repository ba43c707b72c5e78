"""Curvature of the curvature-based surface-tension member (core/surface_tension/curvature.py)
and the family's selection key.

The particles lie on concentric circles (2D), spheres or coaxial cylinders (3D) spaced l0
apart, about l0 apart along each, the outermost at R - l0/2: the liquid they stand for ends at
R (each particle a cell of side l0), so the exact curvature of its surface is 1/R (circle,
cylinder) and 2/R (sphere, the sum of the principal curvatures). A flat free surface has 0.
Expected values come from this geometry alone.
"""
import math

import numpy as np
import pytest

from crowndemo.core import FLUID, Model, Numerics, ParameterError, Physics, Simulator
from crowndemo.core.params import SURFACE_TENSION_MODELS
from crowndemo.core.surface_tension import MODELS, CurvatureTension, PotentialTension

L0 = 1.0e-4
SIGMA = 0.0728
CAPACITY = {2: 2000, 3: 20000}
CYLINDER_LENGTH = 16          # in l0; the interior of its surface: |z| < 4 l0 (re = 2.1 l0)


def physics(dim: int) -> Physics:
    return Physics(dim=dim, l0=L0, v_max=1.0, nu=0.0, sigma=SIGMA, gravity=0.0)


@pytest.fixture(scope="module", params=[2, 3], ids=["2d", "3d"])
def sim(request):
    dim = request.param
    s = Simulator(physics(dim), Numerics(surface_tension="curvature", collision=0.0),
                  CAPACITY[dim])
    assert isinstance(s.surface_tension, CurvatureTension)
    return s


def fibonacci_sphere(count: int, radius: float) -> np.ndarray:
    k = np.arange(count) + 0.5
    polar = np.arccos(1.0 - 2.0 * k / count)
    azimuth = math.pi * (1.0 + 5.0 ** 0.5) * k
    return radius * np.stack([np.cos(azimuth) * np.sin(polar), np.sin(azimuth) * np.sin(polar),
                              np.cos(polar)], axis=1)


def ring(radius: float, shift: float) -> np.ndarray:
    count = max(int(round(2.0 * math.pi * radius)), 1)
    a = 2.0 * math.pi * (np.arange(count) + shift) / count
    return np.stack([radius * np.cos(a), radius * np.sin(a)], axis=1)


def shells(shape: str, R: int) -> np.ndarray:
    """Layers at R - 1/2 - k (units of l0) down to the centre (axis); positions in metres."""
    pts = [np.zeros((1, 2 if shape == "circle" else 3))] if shape != "cylinder" else []
    for k in range(R):
        r = R - 0.5 - k
        if shape == "circle":
            pts.append(ring(r, 0.5 * (k % 2)))
        elif shape == "sphere":
            pts.append(fibonacci_sphere(max(int(round(4.0 * math.pi * r * r)), 1), r))
        else:
            for z in np.arange(CYLINDER_LENGTH) - CYLINDER_LENGTH / 2 + 0.5:
                xy = ring(r, 0.5 * ((k + int(z)) % 2))
                pts.append(np.column_stack([xy, np.full(len(xy), z)]))
    return np.concatenate(pts) * L0


def curvature(sim: Simulator, pos: np.ndarray):
    """kappa of every particle after the number density (S17) at ``pos``, the positions as the
    device holds them, and the pressures."""
    sim.load(pos, np.zeros_like(pos), np.full(len(pos), FLUID, dtype=np.int32))
    sim.grid.build(sim.lattice.re)
    sim.pressure.density_and_pressure()
    n = sim.state.count
    return (sim.surface_tension.kappa.to_numpy()[:n].astype(float),
            sim.state.pos.to_numpy()[:n].astype(float),
            sim.state.pressure.to_numpy()[:n].astype(float))


@pytest.mark.parametrize("R", [8, 12, 16])
def test_circle_and_sphere(sim, R):
    """Every particle of the outer layer within 5 % of 1/R (circle) or 2/R (sphere)."""
    dim = sim.physics.dim
    kappa, pos, pressure = curvature(sim, shells("circle" if dim == 2 else "sphere", R))
    outer = np.linalg.norm(pos, axis=1) > (R - 1) * L0
    exact = (dim - 1) / (R * L0)
    assert np.all(np.abs(kappa[outer] / exact - 1.0) < 0.05)
    # below the outer layer nothing: the pressure there is the equation of state's (S17/M3)
    assert np.all(kappa[~outer] == 0.0)
    # the boundary condition P = sigma kappa on the outer layer
    np.testing.assert_allclose(pressure[outer], SIGMA * kappa[outer], rtol=1e-5)


@pytest.mark.parametrize("R", [8, 12, 16])
def test_cylinder(sim, R):
    """A cylinder's surface, away from its ends: within 5 % of 1/R."""
    if sim.physics.dim == 2:
        pytest.skip("a cylinder is 3D")
    kappa, pos, _ = curvature(sim, shells("cylinder", R))
    interior = (np.linalg.norm(pos[:, :2], axis=1) > (R - 1) * L0) & (
        np.abs(pos[:, 2]) < 4 * L0)
    assert interior.sum() > 8 * 2 * math.pi * (R - 1)
    assert np.all(np.abs(kappa[interior] * R * L0 - 1.0) < 0.05)


@pytest.mark.parametrize("R", [8, 16])
def test_flat_surface(sim, R):
    """The top of a lattice slab, turned 0.3 rad (the fit's frame follows the normal):
    |kappa| < 0.05/R on the surface away from its edges."""
    dim = sim.physics.dim
    side = 12 if dim == 3 else 40
    axes = [np.arange(side) + 0.5] * (dim - 1) + [np.arange(6) + 0.5]
    pts = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, dim)
    c, s = math.cos(0.3), math.sin(0.3)
    turn = np.eye(dim)
    turn[0, 0], turn[0, -1], turn[-1, 0], turn[-1, -1] = c, -s, s, c
    kappa, pos, _ = curvature(sim, pts @ turn.T * L0)
    pos = pos @ turn / L0                  # back in the slab's frame, in l0
    top = pos[:, -1] > 5.0
    inside = np.all((pos[:, :-1] > 4) & (pos[:, :-1] < side - 4), axis=1)
    sel = top & inside
    assert sel.sum() >= (side - 8) ** (dim - 1)
    assert np.all(np.abs(kappa[sel]) < 0.05 / (R * L0))


def test_family_names_and_default():
    """The registry and the validated names agree; the seed's potential is the default, and
    at sigma = 0 no member is compiled in."""
    assert tuple(MODELS) == SURFACE_TENSION_MODELS == ("potential", "stress", "curvature")
    assert MODELS["potential"] is PotentialTension
    assert Numerics().surface_tension == "potential"
    assert Model.of(physics(2), Numerics()).surface_tension_model == "potential"
    dry = Physics(dim=2, l0=L0, v_max=1.0, sigma=0.0)
    assert Simulator(dry, Numerics(surface_tension="curvature"), 16).surface_tension is None


def test_unknown_model_refused():
    with pytest.raises(ParameterError) as err:
        Numerics(surface_tension="bogus").validate()
    msg = str(err.value)
    assert "surface_tension" in msg and "'bogus'" in msg and "potential | stress | curvature" in msg
