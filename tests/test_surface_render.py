"""The liquid surface drawn by GGUI (offscreen, lavapipe): the mesh fields, the milk look, and
a recording of ``quick`` in the surface style."""
import json

import numpy as np
import pytest

pytest.importorskip("pysplashsurf")

from crowndemo import config  # noqa: E402
from crowndemo.cli import main  # noqa: E402
from crowndemo.record import snapshots  # noqa: E402
from crowndemo.render import camera, window  # noqa: E402
from crowndemo.render.colours import COLOUR_MAP, MILK_HIGH, MILK_LOW, fields_read  # noqa: E402
from crowndemo.render.meshbuffers import HEADROOM, MAX_INDICES, MeshBuffers  # noqa: E402
from crowndemo.render.renderer import SURFACE_BACKGROUND, Renderer  # noqa: E402
from crowndemo.render.surface import reconstruct  # noqa: E402
from crowndemo.render.video import read_image, read_video  # noqa: E402
from crowndemo.render.view import PresetView, RenderSettings  # noqa: E402

RES = (320, 180)
L0 = 1.0e-4
MILK = np.array([MILK_LOW, MILK_HIGH]).mean(axis=0)


def chroma(rgb):
    """Colour without brightness: rgb / its sum."""
    rgb = np.asarray(rgb, float)
    return rgb / np.maximum(rgb.sum(axis=-1, keepdims=True), 1e-9)


def milk_share(img, bright):
    """Share of the ``bright`` pixels whose colour is the milk's, shaded by white lights
    (the lights' tints differ from white by at most 0.05 in chroma)."""
    d = np.abs(chroma(img[bright]) - chroma(MILK)).max(axis=1)
    return (d < 0.02).mean()


def ball(radius, centre):
    n = int(radius) + 1
    g = (np.stack(np.meshgrid(*[np.arange(-n, n) + 0.5] * 3, indexing="ij"), -1)
         .reshape(-1, 3))
    return g[np.linalg.norm(g, axis=1) <= radius] * L0 + np.asarray(centre)


@pytest.fixture
def renderer():             # closed after its test: the recording below opens its own window
    window.check_available()
    r = Renderer(RES)
    yield r
    r.close()


def test_ball_drawn_in_milk_where_it_projects(renderer):
    """A ball of R = 10 l0 seen from 6 R: its pixels lie on its projected disc and are milk;
    the ground is the surface background. Drawn as recordings draw it, by ``render_surface``:
    a bare ``draw_surface`` + ``capture`` came out blank once in CI, the first frame of a new
    window (GGUI on lavapipe; meshbuffers.py)."""
    centre = (0.0, 0.0, 12 * L0)
    mesh = reconstruct(ball(10, centre), L0)
    pose = camera.spherical(centre, 60 * L0, -60.0, 18.0, 35.0)
    colours = np.tile(np.float32(MILK), (mesh.n_vertices, 1))
    img = renderer.render_surface(mesh, colours, pose).astype(float) / 255
    assert renderer.blank_frames == 0
    bg = np.abs(img - np.array(SURFACE_BACKGROUND)).max(axis=2) < 2 / 255
    cx, cy, _ = camera.project(pose, [centre], RES)[0]
    r_px = camera.pixel_radius(pose, centre, 10 * L0, RES)
    rows, cols = np.mgrid[:RES[1], :RES[0]]
    dist = np.hypot(cols + 0.5 - cx, rows + 0.5 - cy)
    assert bg[dist > r_px + 2].all()                  # nothing outside the sphere's outline
    inside = dist < r_px - 2
    assert not bg[inside].any()                        # the whole disc is drawn
    assert milk_share(img, inside) > 0.95


@pytest.mark.parametrize("colour", ["speed", "milk"])
def test_surface_coloured_by_the_field_its_scale_reads(renderer, colour):
    """A ball whose particles all move at the scale's top speed U, drawn by the preset view
    (with its dish):
    coloured by speed it is the colour map's top (red); in milk, milk (the view then leaves
    the fields out of the reconstruction, which milk and height do not read)."""
    r = config.load("quick", "draft")
    view = PresetView.from_resolved(r, RenderSettings(resolution=RES, colour=colour))
    centre = (0.0, 0.0, 12 * L0)
    pos = ball(10, centre)
    fields = {"speed": np.full(len(pos), r.speed), "pressure": np.zeros(len(pos))}
    pose = camera.spherical(centre, 60 * L0, -60.0, 18.0, 35.0)
    img = view.surface_image(renderer, pos, fields, pose).astype(float) / 255
    cx, cy, _ = camera.project(pose, [centre], RES)[0]
    rows, cols = np.mgrid[:RES[1], :RES[0]]
    disc = np.hypot(cols + 0.5 - cx, rows + 0.5 - cy) < camera.pixel_radius(
        pose, centre, 10 * L0, RES) - 2
    bright = disc & (img.max(axis=2) > 0.15)        # the ball, not the dark dish behind it
    assert bright.sum() > 0.5 * disc.sum()
    if colour == "milk":
        assert fields_read(colour) == () and milk_share(img, bright) > 0.95
    else:
        assert fields_read(colour) == ("speed",)
        d = np.abs(chroma(img[bright]) - chroma(COLOUR_MAP[-1])).max(axis=1)
        assert (d < 0.05).mean() > 0.95


def test_mesh_fields_have_headroom_and_grow_rarely():
    """Fields made for a mesh hold it with HEADROOM; meshes that grow by 10 % a frame are
    reallocated only when they pass the headroom (a ball of R^2 area: 10 frames, 3 times)."""
    window.check_available()
    buf = MeshBuffers()
    sizes = [int(1000 * 1.1 ** k) for k in range(10)]
    for n in sizes:
        v = np.zeros((n, 3), np.float32)
        buf.fill(v, np.zeros((2 * n, 3), np.int64), v, v)
        assert buf.vertex_capacity >= n and buf.index_capacity >= 6 * n
        assert buf.vertex_capacity <= HEADROOM * max(sizes)
    expected = 1 + int(np.log(sizes[-1] / sizes[0]) / np.log(HEADROOM))
    assert buf.allocations <= expected + 1
    assert buf.allocations < len(sizes) / 2
    buf.n_indices = 2 * MAX_INDICES + 9                # the pieces a huge mesh is drawn in
    pieces = list(buf.pieces())
    assert pieces == [(0, MAX_INDICES), (MAX_INDICES, MAX_INDICES), (2 * MAX_INDICES, 9)]
    assert all(float(np.float32(x)) == x for piece in pieces for x in piece)   # exact in f32


def uv_sphere(rings, radius):
    """A closed UV sphere of ``rings`` rings (2 rings x rings quads): its mesh and its
    outward normals."""
    th, ph = np.meshgrid(np.linspace(0, np.pi, rings + 1),
                         np.linspace(0, 2 * np.pi, 2 * rings + 1)[:-1], indexing="ij")
    n = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1)
    n = n.reshape(-1, 3)
    m = 2 * rings
    i, j = np.meshgrid(np.arange(rings), np.arange(m), indexing="ij")
    a, b = i * m + j, i * m + (j + 1) % m
    c, d = a + m, b + m
    tris = np.concatenate([np.stack([a, c, b], -1), np.stack([b, c, d], -1)]).reshape(-1, 3)
    from crowndemo.render.surface import SurfaceMesh
    return SurfaceMesh(radius * n, tris, n.copy())


def test_meshes_that_outgrow_their_fields_are_still_drawn(renderer):
    """GGUI 1.7.4 on lavapipe drew nothing of a mesh whose buffers grew in 10-25 % of such
    frames (meshbuffers.py). Balls that alternate between small and large (new fields every
    frame, 30 frames), rendered through the renderer's check: every frame shows the ball
    whole, at its size."""
    pose = camera.spherical((0.0, 0.0, 0.0), 5.0, 30.0, 20.0, 40.0)
    shown = []
    for k, rings in enumerate([10, 200, 12, 300, 14, 250] * 5):
        radius = 0.6 + 0.1 * (k % 2)
        mesh = uv_sphere(rings, radius)
        allocations = renderer.mesh_buffers.allocations if renderer.mesh_buffers else 0
        img = renderer.render_surface(mesh, np.tile(np.float32(MILK), (mesh.n_vertices, 1)),
                                      pose)
        assert renderer.mesh_buffers.allocations > allocations        # new fields each time
        lit = np.abs(img.astype(float) / 255 - np.array(SURFACE_BACKGROUND)).max(axis=2) > 2 / 255
        r_px = camera.pixel_radius(pose, (0.0, 0.0, 0.0), radius, RES)
        shown.append(lit.sum() / (np.pi * r_px ** 2))     # the ball's share of its disc
    assert all(0.9 < x < 1.1 for x in shown), (shown, renderer.blank_retries)
    assert renderer.blank_frames == 0


def test_a_frame_drawn_blank_is_drawn_again(renderer, monkeypatch):
    """The check itself: when GGUI leaves the mesh out of the first two draws of a frame
    (forced here), render_surface sees the frame equal to the one without the mesh, draws it
    again in new fields, and returns the ball; two redraws counted, none left blank."""
    from crowndemo.render.renderer import Renderer as R
    pose = camera.spherical((0.0, 0.0, 0.0), 5.0, 30.0, 20.0, 40.0)
    mesh = uv_sphere(40, 0.6)
    submit, dropped = R._submit_surface, []

    def flaky(self, pose_, floor):
        if self.drawn and self.mesh_buffers.n_indices > 3 and len(dropped) < 2:   # its mesh, twice
            dropped.append(1)
            drawn, self.drawn = self.drawn, 0
            submit(self, pose_, floor)
            self.drawn = drawn
        else:
            submit(self, pose_, floor)
    monkeypatch.setattr(R, "_submit_surface", flaky)
    img = renderer.render_surface(mesh, np.tile(np.float32(MILK), (mesh.n_vertices, 1)), pose)
    assert len(dropped) == 2 and renderer.blank_retries == 2 and renderer.blank_frames == 0
    lit = np.abs(img.astype(float) / 255 - np.array(SURFACE_BACKGROUND)).max(axis=2) > 2 / 255
    r_px = camera.pixel_radius(pose, (0.0, 0.0, 0.0), 0.6, RES)
    assert 0.9 < lit.sum() / (np.pi * r_px ** 2) < 1.1


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    """quick (draft) to 0.5 ms in the surface style, its frames and snapshots."""
    root = tmp_path_factory.mktemp("rec")
    sets = ["scene.t_end=5e-4"]
    args = ["record", "quick", "--recordings", str(root), "--resolution", "%dx%d" % RES,
            "--quiet", "--fast-compile"] + sum((["--set", s] for s in sets), [])
    assert main(args) == 0
    return root / "quick", config.load("quick", "draft", sets)


def test_quick_surface_frames(quick):
    folder, r = quick
    meta = json.loads((folder / "metadata.json").read_text())
    frames = sorted((folder / "frames").glob("frame_*.png"))
    assert len(frames) == len(r.frame_times()) + 1 == len(meta["frames"])
    assert len(list(read_video(str(folder / "video.mp4")))) == len(frames)
    images = [read_image(str(f)).astype(float) / 255 for f in frames]
    view = PresetView.from_resolved(r, RenderSettings(resolution=RES))
    caption = 0.2                              # the caption band's share of the height, top
    for img in images:
        body = img[int(caption * RES[1]):]
        bright = body.max(axis=2) > 2 * max(0.125, max(SURFACE_BACKGROUND))  # over the dish
        assert bright.mean() > 0.1                                       # not blank
        assert milk_share(body, bright) > 0.9                           # milk, mostly
    for a, b in zip(images, images[1:]):
        assert np.abs(a - b).max() > 0.2                                 # it moves
    # the crown at the end time: the liquid above the film, projected with the frame's camera,
    # lies inside the picture and spans a good part of the box the camera frames (the crown's
    # reach, 1.3 Yarin-Weiss base radii: the crown itself is at least half of it)
    snap = snapshots.read(folder / meta["frames"][-1]["file"])
    mesh = reconstruct(snap["pos"], r.l0)
    above = mesh.vertices[mesh.vertices[:, 2] > r.scene["film"] + r.l0]
    pose = view.pose(len(frames) - 1)
    px = camera.project(pose, above, RES)
    assert (px[:, 0] > 0).all() and (px[:, 0] < RES[0]).all()
    assert (px[:, 1] > 0).all() and (px[:, 1] < RES[1]).all()
    lo, hi = view.geometry.frame_box()
    box = camera.project(pose, [[lo[0], 0, 0], [hi[0], 0, 0]], RES)
    assert np.ptp(px[:, 0]) > 0.5 * np.ptp(box[:, 0])
    # play shows it: the headless reel holds every frame (no title card)
    reel = folder.parent / "reel.mp4"
    assert main(["play", "quick", "--recordings", str(folder.parent), "--headless", "--out",
                 str(reel), "--card-seconds", "0", "--resolution", "%dx%d" % RES]) == 0
    assert len(list(read_video(str(reel)))) == len(frames)
    # the surface's cost, beside the render's and the simulation's
    t = meta["render"]
    assert t["style"] == "surface" and 0 < t["surface_seconds"] < t["render_seconds"]
    assert t["surface_seconds_per_frame"] == pytest.approx(t["surface_seconds"] / len(frames))


def test_style_options():
    """record: surface by default in milk, --style particles in speed; live (no --style)
    draws spheres; a resumed recording is told its style again."""
    import argparse

    from crowndemo.cli.record import _option_words
    from crowndemo.render.options import add_render_options, settings_from_args
    rec = argparse.ArgumentParser()
    add_render_options(rec)
    s = settings_from_args(rec.parse_args([]))
    assert (s.style, s.colour) == ("surface", "milk")
    s = settings_from_args(rec.parse_args(["--style", "particles"]))
    assert (s.style, s.colour) == ("particles", "speed")
    s = settings_from_args(rec.parse_args(["--colour", "pressure"]))
    assert (s.style, s.colour) == ("surface", "pressure")
    live = argparse.ArgumentParser()
    add_render_options(live, lang=False, recording=False)
    with pytest.raises(SystemExit):
        live.parse_args(["--style", "surface"])
    s = settings_from_args(live.parse_args([]))
    assert (s.style, s.colour) == ("particles", "speed")
    base = {"render": True, "resolution": [1280, 720], "lang": "en", "orbit": 0.0,
            "fps": 12.0, "video": True, "all_particles": False, "checkpoint_every": 1}
    assert _option_words({**base, "style": "surface", "colour": "milk"}) == []
    assert _option_words({**base, "style": "particles", "colour": "speed"}) == [
        "--style", "particles"]
    # a recording made before --style was drawn with spheres
    assert _option_words({**base, "colour": "speed"}) == ["--style", "particles"]


@pytest.mark.parametrize("quality", ["draft", "booth", "seed"])
def test_every_crown_preset_is_seen_from_low_with_its_crown_in_view(quality):
    """The surface's camera for every 3D crown preset: 10 to 25 degrees above the film, and
    the box the crown can fill by the end time (frame_box) inside the picture."""
    from crowndemo.config.loader import preset_names
    seen = 0
    for name in preset_names():
        r = config.load(name, quality)
        if r.dim != 3:
            continue
        view = PresetView.from_resolved(r, RenderSettings())
        _, _, elevation = camera.angles(view.start)
        assert 10.0 <= elevation <= 25.0, name
        lo, hi = view.geometry.frame_box()
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                            for z in (lo[2], hi[2])])
        px = camera.project(view.start, corners, view.settings.resolution)
        w, h = view.settings.resolution
        assert (px[:, 0] >= 0).all() and (px[:, 0] <= w).all(), name
        assert (px[:, 1] >= 0).all() and (px[:, 1] <= h).all(), name
        seen += 1
    assert seen >= 4


def test_the_dish_has_a_low_rim():
    """The surface's floor with its rim: the floor at the wall face (z = -l0/2) over the whole
    square, and four side walls on its edges rising h + D above it, each with its own normal
    (horizontal, across the wall)."""
    window.check_available()
    from crowndemo.render.floor import FloorMesh
    r = config.load("quick", "draft")
    g = PresetView.from_resolved(r, RenderSettings()).geometry
    mesh = FloorMesh(g, rim=True)
    v, n = mesh.vertices.to_numpy(), mesh.normals.to_numpy()
    half, z = g.floor / 2, -0.5 * g.l0
    assert len(v) == 4 * 5 and len(mesh.indices_np) == 6 * 5
    assert np.allclose(v[:4, 2], z) and np.allclose(np.abs(v[:4, :2]), half)
    walls, wn = v[4:], n[4:]
    assert np.allclose(np.abs(walls[:, :2]).max(axis=1), half, rtol=1e-6)
    assert np.isclose(walls[:, 2].max(), z + g.film + g.drop, rtol=1e-6)
    assert np.allclose(wn[:, 2], 0.0, atol=1e-6) and np.allclose(np.linalg.norm(wn, axis=1), 1)
    assert len(FloorMesh(g).corners) == 4                          # spheres: the floor alone
