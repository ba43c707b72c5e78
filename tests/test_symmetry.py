"""Mirror symmetry planes (core/symmetry.py, scenes/symmetric.py): a half or quarter of a
symmetric scene gives what the whole gives, and nothing crosses a plane."""
import math

import numpy as np
import pytest

from crowndemo import config
from crowndemo.config.errors import PresetError
from crowndemo.core import FLUID, Numerics, simulator_for
from crowndemo.core.symmetry import cut, image_room, images_of, mirror_whole, planes_of
from crowndemo.scenes import dam_break, hydrostatic_tank, square_patch
from crowndemo.scenes.base import lattice_block
from crowndemo.scenes.symmetric import halve
from crowndemo.validate.cases import dam_break_fronts

RHO, G = 998.0, 9.81


def test_cut_and_mirror_give_back_the_whole_lattice():
    l0 = 1.0
    whole = lattice_block([-4, -3, 0], [4, 3, 2], l0)        # points at (k + 1/2) l0 from 0
    keep = cut(whole, (0, 1), tol=1e-6)
    assert keep.sum() * 4 == len(whole)
    again = mirror_whole({"pos": whole[keep]}, (0, 1))["pos"]
    as_set = lambda p: {tuple(np.round(x, 6)) for x in p}
    assert as_set(again) == as_set(whole)
    with pytest.raises(ValueError, match="not mirror symmetric"):
        cut(whole + [0.25, 0, 0], (0,), tol=1e-6)
    with pytest.raises(ValueError, match="on a symmetry plane"):
        cut(lattice_block([-4.5, 0], [4.5, 1], l0), (0,), tol=1e-6)


def test_planes_and_image_counts():
    assert planes_of("full", 3) == () and planes_of("half", 2) == (0,)
    assert planes_of("quarter", 3) == (0, 1)
    with pytest.raises(ValueError):
        planes_of("quarter", 2)
    # a 10 x 10 column of a lattice at (k + 1/2) l0: within 2.1 l0 of x = 0 lie the columns
    # at 0.5 and 1.5 l0 (20 points), the same for y = 0, and 4 points near both
    pts = lattice_block([0, 0, 0], [10, 10, 1], 1.0)
    assert images_of(pts, (0,), 2.1) == 20
    assert images_of(pts, (0, 1), 2.1) == 20 + 20 + 4
    assert image_room(pts, (), 2.1) == 0
    assert image_room(pts, (0, 1), 2.1) == 1024       # at least IMAGE_ROOM_MIN


@pytest.mark.parametrize("dim,planes", [(2, (0,)), (3, (0, 1))])
def test_images_complete_every_neighbour_sum(dim, planes):
    # A block at rest, symmetric about the planes: with the images, every particle of the part
    # has the number density it has in the whole block (S9 sums the same neighbours)
    l0 = 1.0e-3
    whole = square_patch(dim=dim, side=(12 if dim == 2 else 8) * l0, l0=l0)
    part = halve(whole, planes, [0.0] * dim)
    densities = []
    for scene in (whole, part):
        sim = simulator_for(scene)
        sim.refresh_pressure()
        snap = sim.snapshot()
        densities.append((snap["pos"], snap["number_density"]))
    (pw, nw), (pp, npart) = densities
    index = {tuple(np.round(p / l0, 3)): n for p, n in zip(pw, nw)}
    expected = np.array([index[tuple(np.round(p / l0, 3))] for p in pp])
    assert np.allclose(npart, expected, rtol=1e-5)


def _floor_pressure(sim, x_shift: float, width: float, depth: float, l0: float) -> float:
    """P at z = 0 from a least-squares line through the fluid away from the walls."""
    sim.refresh_pressure()
    s = sim.snapshot()
    p = s["pos"] + np.array([x_shift, 0.0])
    inner = (s["kind"] == FLUID) & (p[:, 0] > 3 * l0) & (p[:, 0] < width - 3 * l0)
    inner &= (p[:, 1] > 3 * l0) & (p[:, 1] < depth - 4 * l0)
    return float(np.polyfit(p[inner, 1], s["pressure"][inner], 1)[1])


def test_half_tank_has_the_whole_tanks_floor_pressure():
    # the tank of test_physics (rho g H within 5 %); cut at its middle x = W/2, the half must
    # give the whole tank's floor pressure within 1 % (issue 21), and keep x > 0 throughout
    width, depth, l0 = 0.04, 0.04, 1.0e-3
    whole = hydrostatic_tank(dim=2, l0=l0, width=width, depth=depth, nu=1.0e-3)
    part = halve(whole, (0,), (width / 2, 0.0))
    floor = {}
    for name, scene, shift in (("whole", whole, 0.0), ("half", part, width / 2)):
        sim = simulator_for(scene)
        fits, lowest = [], []

        def frame(s, i):
            fits.append(_floor_pressure(s, shift, width, depth, l0))
            snap = s.snapshot()
            lowest.append(snap["pos"][snap["kind"] == FLUID, 0].min())
        sim.run(0.3, frame_times=np.linspace(0.15, 0.3, 7), on_frame=frame)
        floor[name] = np.mean(fits)
        if name == "half":
            assert min(lowest) > 0.0
    assert floor["whole"] == pytest.approx(RHO * G * depth, rel=0.05)
    assert floor["half"] == pytest.approx(floor["whole"], rel=0.01)


def test_half_dam_break_has_the_whole_surge_front_3d():
    # a 3D column a x a/2 x 2a, cut at the channel's middle y = a/4: the surge front of the
    # half (Martin & Moyce's Z = z/a) within 2 % of the whole's (issue 21)
    a, l0, channel = 0.03, 2.5e-3, 0.5
    whole = dam_break(dim=3, a=a, l0=l0, channel=channel)
    part = halve(whole, (1,), (0.0, 0.5 * channel * a, 0.0))
    fronts = [dam_break_fronts(simulator_for(s), a, 2.0, every=0.5)[1] for s in (whole, part)]
    assert fronts[0][-1] > 2.0                      # the surge has run out 2 a by T = 2
    assert np.allclose(fronts[1], fronts[0], rtol=0.02)


def test_nothing_crosses_a_plane():
    # a 2D disc thrown at the plane x = 0: in the whole scene it meets its mirror twin head-on.
    # No particle is ever on the far side, and the approach is stopped (the twins merge).
    l0, R, U = 1.0e-4, 1.0e-3, 2.0
    pts = lattice_block([-R, -R], [R, R], l0)
    pts = pts[np.linalg.norm(pts, axis=1) <= R] + np.array([R + 2 * l0, 0.0])
    from crowndemo.core.params import Physics
    from crowndemo.scenes.base import assemble
    vel = np.tile([-U, 0.0], (len(pts), 1))
    physics = Physics(dim=2, l0=l0, v_max=U, gravity=0.0, sound_speed=10 * U)
    scene = assemble("twins", physics, Numerics(mirror_planes=(0,)), pts, vel, None,
                     ((-20 * R, -100 * R), (20 * R, 100 * R)), 2.0 * R / U, {})
    sim = simulator_for(scene)
    lowest = []
    sim.run(scene.t_end, on_step=lambda s: lowest.append(
        s.state.pos.to_numpy()[: s.state.count, 0].min()))
    assert min(lowest) >= 0.0
    u = sim.snapshot()["vel"]
    assert abs(u[:, 0].mean()) < 0.2 * U            # the approach at -U has stopped
    assert sim.stats.health.left_total == 0 and math.isfinite(sim.stats.health.energy)


def test_preset_symmetry_key():
    r = config.load("3m-drop", "draft", ["scene.symmetry=quarter"])
    assert r.numerics.mirror_planes == (0, 1) and r.model.mirror_planes == (0, 1)
    assert config.load("3m-drop", "draft", []).numerics.mirror_planes == ()
    with pytest.raises(PresetError) as e:
        config.load("3m-drop", "draft", ["dim=2", "scene.symmetry=quarter"])
    assert "scene.symmetry" in str(e.value) and "full or half" in str(e.value)
    with pytest.raises(PresetError, match="scene.symmetry"):
        config.load("3m-drop", "draft", ["scene.symmetry=eighth"])


@pytest.mark.parametrize("dim,symmetry,wall_model,trim",
                         [(3, "quarter", "plane", True), (3, "quarter", "particles", True),
                          (3, "quarter", "particles", False), (2, "half", "particles", True)])
def test_whole_crown_scene_is_its_mirrored_part(dim, symmetry, wall_model, trim):
    # the whole scene's lattice lies at +-(k + 1/2) l0 from the axis, so the whole scene and
    # its part mirrored are the same particles (fluid and floor): a whole run then starts as
    # symmetric as the part's mirror images make the part's run
    from crowndemo.scenes import crown
    args = dict(dim=dim, l0=4.7e-4, numerics=Numerics(wall_model=wall_model), trim=trim,
                floor=0.09 if trim else 0.03)      # untrimmed: side walls on every face
    whole, part = crown(**args), crown(symmetry=symmetry, **args)
    planes = planes_of(symmetry, dim)
    as_set = lambda pos, kind: {tuple(np.round(x / 4.7e-4, 6)) + (k,)
                                for x, k in zip(pos, kind)}
    mirrored = mirror_whole({"pos": part.pos, "kind": part.kind}, planes)
    assert len(whole.pos) == len(mirrored["pos"]) == 2 ** len(planes) * len(part.pos)
    assert as_set(whole.pos, whole.kind) == as_set(mirrored["pos"], mirrored["kind"])
    assert whole.info["n_drop"] == 2 ** len(planes) * part.info["n_drop"]


def test_snapshots_and_vtk_say_the_run_is_a_part(tmp_path):
    from crowndemo.record import snapshots, vtk
    n = 5
    snap = {"pos": np.random.default_rng(1).random((n, 3)), "vel": np.zeros((n, 3)),
            "pressure": np.zeros(n), "number_density": np.zeros(n),
            "kind": np.zeros(n, np.int32), "id": np.arange(n, dtype=np.int32)}
    snapshots.write(tmp_path / "q.npz", snap, 0, 1e-3, symmetry_planes=(0, 1))
    snapshots.write(tmp_path / "w.npz", snap, 0, 1e-3)
    quarter, whole = snapshots.read(tmp_path / "q.npz"), snapshots.read(tmp_path / "w.npz")
    assert quarter["symmetry_planes"] == (0, 1) and whole["symmetry_planes"] == ()
    vtk.write(tmp_path / "q.vtp", quarter, quarter["time"])
    vtk.write(tmp_path / "w.vtp", whole, whole["time"])
    assert vtk.read(tmp_path / "q.vtp")["symmetry_planes"] == (0, 1)
    assert "symmetry_planes" not in vtk.read(tmp_path / "w.vtp")


def _quadrants(pos: np.ndarray):
    """The four quadrants of a whole 3D run, each turned into x > 0, y > 0."""
    for sx in (1, -1):
        for sy in (1, -1):
            q = pos[(sx * pos[:, 0] > 0) & (sy * pos[:, 1] > 0)]
            yield q * np.array([sx, sy, 1.0])


def _crown_run(symmetry: str, stops: tuple, at: float):
    """3m-drop at draft to 2 ms, whole or quarter, its step sequence cut by frame ``stops``:
    the metrics (base radius, rim height, particles) of each quadrant mirrored into a whole
    crown, and the fluid's positions at time ``at`` keyed by their start on the lattice."""
    from crowndemo.validate.crown_metrics import measure
    r = config.load("3m-drop", "draft", [f"scene.symmetry={symmetry}"])
    sim = simulator_for(r.build_scene())
    key = lambda p: map(tuple, np.rint(p / r.l0 * 2).astype(int))
    start = sim.snapshot()
    starts = dict(zip(start["id"].tolist(), key(start["pos"])))
    early = {}

    def keep(sim, index):
        s = sim.snapshot()
        if abs(sim.stats.time - at) < 1e-12:
            f = s["kind"] == FLUID
            early.update(zip((starts[i] for i in s["id"][f].tolist()), s["pos"][f]))
    sim.run(r.t_end, sorted({at, *stops}), keep)
    # nothing thrown out across the planes; a few film particles creep through the particle
    # floor's wall layer at this resolution (the whole run, 2026-12-07: 3 of its 162,620 by
    # 2 ms, parked at the layer's plane, scenes/base.py floor_cut)
    left = sim.stats.health.left
    assert set(left) <= {"left through z-"} and sum(left.values()) <= 1e-4 * sim.n_fluid, left
    snap = sim.snapshot()
    pos = snap["pos"][snap["kind"] == FLUID]
    parts = [pos] if symmetry == "quarter" else list(_quadrants(pos))
    metrics = [measure(mirror_whole({"pos": q}, (0, 1))["pos"], r.t_end, r.scene["film"],
                       r.scene["drop"], r.l0) for q in parts]
    return [(m.base_radius, m.rim_height, len(q)) for m, q in zip(metrics, parts)], early, r.l0


@pytest.mark.slow
def test_quarter_crown_within_the_whole_runs_quadrant_spread():
    # 3m-drop at draft (D/l0 = 30, to 2 ms), whole and quarter (issue 21; docs/symmetry.md,
    # "The quarter against the whole"). The splash is chaotic: the whole run's own mirror
    # twins, equal at the start, drift apart from round-off (1e-7 l0 at 0.05 ms) to l0 by 1 ms,
    # and the quarter drifts from the whole's quadrant no faster. So:
    # 1. before the drift grows (0.2 ms) the quarter is the whole's quadrant particle for
    #    particle, within 0.01 l0 (a missing or wrong mirror image moves a particle near a
    #    plane by a fair part of l0 in a few steps);
    # 2. at 2 ms a run is one sample of the chaos, and the crown metrics are not smooth in the
    #    positions (a sector's highest particle is in the rim or not by a link of 1.6 l0): two
    #    whole runs, their steps cut apart by a frame stop at 0.35 ms, give 8 quadrants, two
    #    quarter runs cut the same ways 2 samples; per metric, the two means differ by no more
    #    than 4 standard errors (a two-sample t, the quadrants' standard deviation s for both,
    #    |t| <= 4: at equal means a chance failure one time in 200 a metric, 1.5 % over three,
    #    sampled from normal deviates). Until 2026-12-07 the bound was the farthest quadrant's
    #    deviation, failed by chance 7.5 % a metric, one run in five (it failed once on main,
    #    rim heights 5.83 / 6.12 mm against the quadrants' 5.39 +- 0.47 at most, and passed on
    #    the same runs scripted again). About 7 minutes on 2 cores: `make test-slow` runs it,
    #    `make test` leaves it out.
    at, members = 2.0e-4, ((), (3.5e-4,))
    quadrants, quarters = [], []
    for stops in members:
        q, q_early, l0 = _crown_run("quarter", stops, at)
        w, w_early, _ = _crown_run("full", stops, at)
        quarters += q
        quadrants += w
        if not stops:
            moved = [np.linalg.norm(p - w_early[k]) for k, p in q_early.items()]
            assert len(moved) == len(q_early) and max(moved) < 0.01 * l0, max(moved) / l0
    quadrants, quarters = np.array(quadrants, dtype=float), np.array(quarters, dtype=float)
    s = quadrants.std(axis=0, ddof=1)
    error = s * np.sqrt(1.0 / len(quarters) + 1.0 / len(quadrants))
    t = (quarters.mean(axis=0) - quadrants.mean(axis=0)) / error
    assert np.all(np.abs(t) <= 4.0), (t, quarters, quadrants)


def test_particle_frames_draw_the_whole_of_a_quarter():
    # the sphere style's buffers hold every fluid particle of a quarter run and its images
    from crowndemo.render.buffers import ParticleBuffers
    from crowndemo.render.colours import ColourScale
    r = config.load("quick", "draft", ["scene.symmetry=quarter"])
    sim = simulator_for(r.build_scene())
    buf = ParticleBuffers(sim.state.capacity, sim.model.mirror_planes)
    drawn = buf.fill(sim.state, ColourScale("height", 0.0, 1.0e-2))
    whole = sim.whole_snapshot()
    expected = whole["pos"][whole["kind"] == FLUID]
    assert drawn == len(expected) == 4 * sim.counts()["fluid"]
    got = buf.pos.to_numpy()[:drawn]
    as_set = lambda p: {tuple(np.round(x / r.l0, 2)) for x in p}
    assert as_set(got) == as_set(expected)
