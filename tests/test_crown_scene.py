"""The seed's drop-on-film scene: geometry, what it leaves out, and a few steps of its run."""
import math

import numpy as np
import pytest

from crowndemo.core import FLUID, WALL, simulator_for
from crowndemo.scenes.crown import crown, crown_base_radius

U, D, H, GAP = 8.0, 1.0e-2, 1.0e-3, 1.0e-3


def test_crown_base_radius_is_yarin_weiss():
    # R_c/D = (2/(3 delta))^(1/4) sqrt(tau): at tau = 1, delta = 0.1 -> (20/3)^(1/4)
    assert crown_base_radius(D / U, U, D, H) == pytest.approx(D * (20 / 3) ** 0.25)


@pytest.mark.parametrize("dim", [2, 3])
def test_crown_geometry(dim):
    l0 = 2.5e-4 if dim == 2 else 5.0e-4      # 40 and 20 spacings across the drop
    sc = crown(dim=dim, l0=l0, film=H, drop=D, speed=U, gap=GAP, t_end=1.0e-3)
    fluid = sc.kind == FLUID
    n_drop, n_film = sc.info["n_drop"], sc.info["n_film"]
    drop_volume = math.pi * (D / 2) ** 2 if dim == 2 else math.pi / 6 * D ** 3
    assert n_drop * l0 ** dim == pytest.approx(drop_volume, rel=0.03)
    drop_pos = sc.pos[fluid][n_film:]
    film_pos = sc.pos[fluid][:n_film]
    assert np.all(sc.vel[fluid][n_film:, -1] == -U) and np.all(sc.vel[fluid][:n_film] == 0)
    # the drop's lowest particle centre sits the gap + one spacing above the film's highest
    assert drop_pos[:, -1].min() - film_pos[:, -1].max() == pytest.approx(GAP + l0, abs=l0)
    assert film_pos[:, -1].max() == pytest.approx(H - l0 / 2)
    # 1 ms of impact cannot reach the 45 mm container edge: film trimmed, no side walls
    assert sc.info["trimmed"] and any("film beyond" in s for s in sc.info["left_out"])
    extent = sc.info["extent_m"]
    walls = sc.pos[sc.kind != FLUID]
    assert np.all(walls[:, -1] < 0)                       # floor layers only
    radial = np.abs(walls[:, 0]) if dim == 2 else np.linalg.norm(walls[:, :2], axis=1)
    assert radial.max() <= extent + 3 * l0 + 1e-12
    assert (sc.kind == WALL).sum() > 0


def test_crown_untrimmed_at_the_seed_end_time_has_side_walls():
    sc = crown(dim=2, l0=5.0e-4, t_end=4.0e-3)
    assert not sc.info["trimmed"] and set(sc.info["walls"]) == {"x-", "x+", "y-"}


def test_crown_2d_runs_and_the_drop_falls():
    l0 = 2.5e-4
    sc = crown(dim=2, l0=l0, t_end=1.0e-4)
    sim = simulator_for(sc)
    sim.run(1.0e-4)
    snap = sim.snapshot()
    n_film = sc.info["n_film"]
    drop = snap["pos"][snap["kind"] == FLUID][n_film:]
    z0 = sc.pos[sc.kind == FLUID][n_film:, -1]
    # before contact (the gap takes 125 us at 8 m/s) the drop moves at U: dz = -U t (gravity's
    # g t^2/2 = 5e-8 m is far below this check's 2 %, 16 um = 0.06 l0)
    dz = drop[:, -1] - z0
    assert np.median(dz) == pytest.approx(-U * 1.0e-4 - 9.81 * 1.0e-8 / 2, rel=0.02)
    assert sim.stats.health.left_total == 0
