"""Parameter validation, time-step limits (method.md §1, S5-S8, M1) and container walls (§5).

No Taichi kernels run here.
"""
import math

import numpy as np
import pytest

from crowndemo.core import DUMMY, FLUID, WALL, Model, Numerics, ParameterError, Physics
from crowndemo.core import timestep
from crowndemo.scenes import container_walls, dam_break, hydrostatic_tank, wall_layers
from crowndemo.scenes.base import lattice_block

GOOD = dict(dim=2, l0=1.0e-3, v_max=1.0)


def physics(**changes) -> Physics:
    return Physics(**{**GOOD, **changes})


# ---- validation ------------------------------------------------------------------------------
def test_good_values_pass():
    assert physics().validate() is not None
    assert physics(dim=3, nu=0.0, sigma=0.0, gravity=0.0, sound_speed=20.0).validate()
    assert Numerics().validate() is not None
    for form in ("seed", "pmin", "sum"):
        Numerics(pressure_gradient=form).validate()


@pytest.mark.parametrize("key,value", [
    ("dim", 4), ("dim", 1), ("l0", 0.0), ("l0", -1e-3), ("l0", math.nan), ("l0", math.inf),
    ("v_max", 0.0), ("v_max", -2.0), ("re_ratio", 1.0), ("re_ratio", 5.0), ("rho", 0.0),
    ("nu", -1e-6), ("sigma", -0.07), ("sigma", math.nan), ("gravity", math.inf),
    ("sound_speed", 0.0), ("sound_speed", -3.0), ("l0", True), ("l0", "1e-3"),
])
def test_physics_rejects(key, value):
    with pytest.raises(ParameterError) as err:
        physics(**{key: value}).validate(source="preset.yaml")
    assert err.value.key == key
    assert key in str(err.value) and "preset.yaml" in str(err.value)


@pytest.mark.parametrize("key,value", [
    ("courant", 0.0), ("courant", -0.1), ("courant", 3.0), ("acoustic", 0.0),
    ("acoustic", math.nan), ("viscous", 2.5), ("capillary", -1.0), ("dt_max", 0.0),
    ("fixed_dt", 0.0), ("fixed_dt", -1e-5), ("fixed_dt", math.inf),
    ("pressure_gradient", "foo"), ("pressure_gradient", "PMIN"), ("beta", 1.0), ("beta", 0.2),
    ("max_density_excess", 0.0), ("max_mach", -1.0), ("max_out_fraction", 1.5),
    ("reorder_every", -1), ("reorder_every", 1.5),
])
def test_numerics_rejects(key, value):
    with pytest.raises(ParameterError) as err:
        Numerics(**{key: value}).validate()
    assert err.value.key == key
    assert key in str(err.value)


def test_simulator_refuses_bad_parameters_before_compiling():
    from crowndemo.core import Simulator
    with pytest.raises(ParameterError) as err:
        Simulator(physics(l0=-1.0), Numerics(), 10)
    assert err.value.key == "l0"
    with pytest.raises(ParameterError) as err:
        Simulator(physics(), Numerics(pressure_gradient="foo"), 10)
    assert err.value.key == "pressure_gradient"


# ---- time-step limits ------------------------------------------------------------------------
def limits_of(ph: Physics, nm: Numerics = Numerics(), speed: float = None):
    return timestep.limits(ph, nm, Model.of(ph, nm), ph.v_max if speed is None else speed)


def test_limits_formulas():
    l0, v, c, nu, sigma, rho = 1e-3, 2.0, 30.0, 1e-4, 0.05, 900.0
    ph = physics(l0=l0, v_max=v, sound_speed=c, nu=nu, sigma=sigma, rho=rho)
    nm = Numerics(courant=0.2, acoustic=1.0, viscous=0.15, capillary=0.5)
    lim = limits_of(ph, nm, speed=v)
    assert lim["courant"] == pytest.approx(0.2 * l0 / v, rel=1e-14)             # S5
    assert lim["acoustic"] == pytest.approx(1.0 * l0 / c, rel=1e-14)            # S6
    assert lim["viscous"] == pytest.approx(0.15 * l0 ** 2 / nu, rel=1e-14)      # M1
    assert lim["capillary"] == pytest.approx(
        0.5 * math.sqrt(rho * l0 ** 3 / (2 * math.pi * sigma)), rel=1e-14)     # M1
    assert "dt_max" not in lim
    assert limits_of(ph, Numerics(dt_max=1e-6))["dt_max"] == 1e-6
    assert limits_of(ph, nm, speed=0.0)["courant"] == math.inf


def test_default_sound_speed_equalises_courant_and_acoustic():
    """S8: c = 5 v_max makes C_v = 0.2 and C_c = 1.0 give the same dt."""
    ph = physics(v_max=3.0)
    assert ph.c == pytest.approx(15.0)
    lim = limits_of(ph)
    assert lim["courant"] == pytest.approx(lim["acoustic"], rel=1e-12)


@pytest.mark.parametrize("nu,sigma", [(0.0, 0.0), (1e-6, 0.0), (0.0, 0.07), (1e-6, 0.07)])
def test_limits_only_for_terms_in_force(nu, sigma):
    lim = limits_of(physics(nu=nu, sigma=sigma))
    assert ("viscous" in lim) == (nu > 0)
    assert ("capillary" in lim) == (sigma > 0)
    assert {"courant", "acoustic"} <= set(lim)


def test_choose_names_the_binding_limit():
    # very viscous liquid: the viscous limit binds
    ph = physics(nu=1.0, sigma=0.0)
    nm = Numerics()
    dt, name = timestep.choose(ph, nm, Model.of(ph, nm), 0.1)
    assert name == "viscous" and dt == pytest.approx(0.15 * 1e-6 / 1.0)
    # fixed dt wins and says so
    nm = Numerics(fixed_dt=1e-7)
    assert timestep.choose(ph, nm, Model.of(ph, nm), 0.1) == (1e-7, "fixed")


def test_check_fixed_dt_refuses_above_acoustic_limit():
    # c = 10 v_max: the acoustic limit l0/c is the smallest (courant is 0.2 l0/v = 2 l0/c)
    ph = physics(l0=1e-3, v_max=1.0, sound_speed=10.0, nu=0.0, sigma=0.0)
    acoustic = 1.0 * 1e-3 / 10.0
    nm = Numerics(fixed_dt=1.5 * acoustic)
    with pytest.raises(ParameterError) as err:
        timestep.check_fixed_dt(ph, nm, Model.of(ph, nm))
    assert err.value.key == "fixed_dt"
    assert "acoustic" in str(err.value)
    # at the limit or below: accepted; above but explicitly unsafe: accepted
    for ok in (Numerics(fixed_dt=acoustic), Numerics(fixed_dt=0.5 * acoustic),
               Numerics(fixed_dt=1.5 * acoustic, allow_unsafe_dt=True), Numerics()):
        timestep.check_fixed_dt(ph, ok, Model.of(ph, ok))


def test_check_fixed_dt_names_capillary_when_it_binds():
    # tiny l0 and large sigma: capillary sqrt(rho l0^3 / (2 pi sigma)) below the acoustic limit
    ph = physics(l0=1e-5, v_max=0.1, nu=0.0, sigma=1.0)
    cap = math.sqrt(998.0 * 1e-15 / (2 * math.pi * 1.0))
    assert cap < 1e-5 / ph.c
    nm = Numerics(fixed_dt=2 * cap)
    with pytest.raises(ParameterError, match="capillary"):
        timestep.check_fixed_dt(ph, nm, Model.of(ph, nm))


# ---- walls -----------------------------------------------------------------------------------
@pytest.mark.parametrize("re_ratio,layers", [(1.5, 2), (2.0, 2), (2.1, 3), (3.0, 3), (3.1, 4),
                                             (4.5, 5)])
def test_wall_layers_is_ceil_re_over_l0(re_ratio, layers):
    assert wall_layers(re_ratio) == layers


def _layer_index(pts, inner_lo, inner_hi, l0):
    """How many lattice layers outside the inner box (Chebyshev, in units of l0)."""
    lo, hi = np.asarray(inner_lo), np.asarray(inner_hi)
    out = np.maximum(lo - pts, pts - hi).max(axis=1)      # > 0 outside, half-integer * l0
    return np.rint(out / l0 + 0.5).astype(int)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("re_ratio", [2.1, 3.0])
def test_container_walls_layers(dim, re_ratio):
    l0 = 1.0e-3
    n_in = [6, 5, 8][:dim]                     # inner box in cells
    inner_lo = [0.0] * dim
    inner_hi = [k * l0 for k in n_in]
    faces = ["x-", "x+", "y-"] if dim == 2 else ["x-", "x+", "y-", "y+", "z-"]
    L = wall_layers(re_ratio)
    assert L == math.ceil(re_ratio)
    pts, kind = container_walls(inner_lo, inner_hi, l0, L, faces)
    layer = _layer_index(pts, inner_lo, inner_hi, l0)
    assert layer.min() == 1 and layer.max() == L
    assert np.all(kind[layer == 1] == WALL)
    assert np.all(kind[layer > 1] == DUMMY)
    assert set(np.unique(kind)) == {WALL, DUMMY}
    # nothing inside the box, nothing above the open top
    assert np.all(layer > 0)
    assert pts[:, -1].max() < inner_hi[-1]
    # every lattice site of the walls is there once: count the open-top shell exactly
    ext = [n + 2 * L for n in n_in[:-1]] + [n_in[-1] + L]
    assert len(pts) == np.prod(ext) - np.prod(n_in)
    assert len(np.unique(np.round(pts / l0, 6), axis=0)) == len(pts)
    # the walls continue the fluid lattice (sites at (i + 1/2) l0)
    frac = pts / l0 - 0.5
    np.testing.assert_allclose(frac, np.rint(frac), atol=1e-9)
    # the WALL layer alone is the open-top shell one layer thick
    ext1 = [n + 2 for n in n_in[:-1]] + [n_in[-1] + 1]
    assert (kind == WALL).sum() == np.prod(ext1) - np.prod(n_in)


@pytest.mark.parametrize("dim", [2, 3])
def test_scenes_use_enough_wall_layers(dim):
    l0 = 2e-3
    for scene in (dam_break(dim=dim, a=0.01, l0=l0), hydrostatic_tank(dim=dim, l0=l0,
                                                                      width=0.01, depth=0.01)):
        re = scene.physics.re
        fluid = scene.pos[scene.kind == FLUID]
        walls = scene.pos[scene.kind != FLUID]
        # depth of the wall block below the floor: ceil(re/l0) layers of spacing l0
        floor = fluid[:, -1].min() - 0.5 * l0
        depth_layers = np.rint((floor - walls[:, -1].min()) / l0 + 0.5)
        assert depth_layers == math.ceil(re / l0 - 1e-9)
        # a fluid particle on the floor sees wall/dummy particles down to re below it
        assert floor - walls[:, -1].min() >= re - 0.5 * l0
        # under the liquid's footprint: the first layer is WALL, the deeper ones DUMMY
        kinds = scene.kind[scene.kind != FLUID]
        lat = slice(0, dim - 1)
        below_fluid = np.all((walls[:, lat] >= fluid[:, lat].min(axis=0) - 1e-9)
                             & (walls[:, lat] <= fluid[:, lat].max(axis=0) + 1e-9), axis=1)
        under = below_fluid & (walls[:, -1] < floor)
        first = under & (walls[:, -1] > floor - l0)
        assert first.sum() == len(np.unique(np.floor(fluid[:, lat] / l0).astype(int), axis=0))
        assert np.all(kinds[first] == WALL)
        assert under.sum() == first.sum() * math.ceil(re / l0 - 1e-9)
        assert np.all(kinds[under & ~first] == DUMMY)


def test_lattice_block_counts():
    pts = lattice_block([0.0, 0.0], [0.01, 0.02], 1e-3)
    assert pts.shape == (200, 2)
    assert pts.min() == pytest.approx(0.5e-3) and pts[:, 1].max() == pytest.approx(0.0195)
