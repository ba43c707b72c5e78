"""The GGUI renderer (offscreen, CPU arch, Vulkan through lavapipe), captions and the frame
sink. Expected pixels come from an independent pinhole projection, not from the renderer."""
import glob
import math
import os

import numpy as np
import pytest

from crowndemo import config
from crowndemo.core import simulator_for
from crowndemo.core.state import FLUID, GONE, WALL, ParticleState
from crowndemo.render import camera, window
from crowndemo.render.captions import CaptionInfo, caption_lines
from crowndemo.render.colours import ColourScale
from crowndemo.render.renderer import BACKGROUND, Renderer
from crowndemo.render.sink import FrameSink
from crowndemo.render.view import PresetView, RenderSettings

RES = (320, 180)
POSE = camera.Pose(eye=(0.0, -0.3, 0.1), target=(0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0), fov=40.0)
BG = np.round(np.array(BACKGROUND) * 255)


def pinhole(eye, target, up, fov, point, res):
    """Pixel (column, row from the top) and depth of a point: look-at + vertical fov."""
    eye, target, up, point = (np.asarray(v, float) for v in (eye, target, up, point))
    fwd = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(fwd, up)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, fwd)
    d = point - eye
    x, y, z = d @ right, d @ true_up, d @ fwd
    k = 1 / math.tan(math.radians(fov) / 2)
    w, h = res
    return w / 2 + k * (x / z) * h / 2, h / 2 - k * (y / z) * h / 2, z


def state_of(dim, pos, vel, kind):
    s = ParticleState(dim, max(len(pos), 1))
    s.load(np.asarray(pos, float), np.asarray(vel, float), np.asarray(kind))
    return s


@pytest.fixture(scope="module")
def renderer():
    window.check_available()
    r = Renderer(RES)
    yield r
    r.close()


def lit(img):
    """Pixels that differ from the background."""
    return np.abs(img.astype(float) - BG).max(axis=2) > 12


def test_no_vulkan_driver_is_a_clear_error(monkeypatch):
    monkeypatch.setenv("VK_ICD_FILENAMES", "/nonexistent/icd.json")
    monkeypatch.setattr(window, "_checked", None)
    with pytest.raises(window.RenderError, match="apt-get install mesa-vulkan-drivers"):
        window.check_available()


@pytest.mark.parametrize("dim", [3, 2])
def test_particle_lights_its_projected_disc(renderer, dim):
    radius = 0.01
    p3 = np.array([0.04, 0.0, 0.02])
    p = p3 if dim == 3 else p3[[0, 2]]        # a 2D slice is drawn in the plane y = 0
    wall = np.array([-0.05, 0.0, -0.02]) if dim == 3 else np.array([-0.05, -0.02])
    gone = np.array([-0.05, 0.0, 0.03]) if dim == 3 else np.array([-0.05, 0.03])
    st = state_of(dim, [p, wall, gone], np.zeros((3, dim)), [FLUID, WALL, GONE])
    img = renderer.render(st, POSE, ColourScale("height", 0, 0.05), radius)
    assert renderer.drawn == 1
    col, row, depth = pinhole(POSE.eye, POSE.target, POSE.up, POSE.fov, p3, RES)
    r_px = radius / depth / math.tan(math.radians(POSE.fov) / 2) * RES[1] / 2
    rows, cols = np.nonzero(lit(img))
    assert abs(cols.mean() - col) < 1.0 and abs(rows.mean() - row) < 1.0
    # the sphere's silhouette is a disc of the projected radius (GGUI's sprite size corrected)
    assert abs((cols.max() - cols.min() + 1) / 2 - r_px) < 1.5
    assert abs((rows.max() - rows.min() + 1) / 2 - r_px) < 1.5
    for hidden in (wall, gone):                # walls and departed particles are not drawn
        h3 = hidden if dim == 3 else np.array([hidden[0], 0.0, hidden[1]])
        c, r, _ = pinhole(POSE.eye, POSE.target, POSE.up, POSE.fov, h3, RES)
        assert not lit(img)[int(r) - 3:int(r) + 4, int(c) - 3:int(c) + 4].any()


def test_one_window_at_a_time(renderer):
    with pytest.raises(window.RenderError, match="already open"):
        Renderer(RES)


def test_empty_scene_is_background_only(renderer):
    st = state_of(3, [[0.0, 0.0, 0.0]], [[0.0, 0.0, 0.0]], [WALL])
    img = renderer.render(st, POSE, ColourScale("speed", 0, 1), 0.01)
    assert renderer.drawn == 0
    assert np.abs(img.astype(float) - BG).max() <= 1


def test_colour_by_speed_follows_the_speed(renderer):
    U = 8.0
    means = []
    for speed in (0.0, U):
        st = state_of(3, [[0.0, 0.0, 0.0]], [[0.0, 0.0, -speed]], [FLUID])
        img = renderer.render(st, POSE, ColourScale.for_scene("speed", U, 1e-3, 4e-3, 998.0),
                              0.02)
        means.append(img[lit(img)].astype(float).mean(axis=0))
    slow, fast = means
    assert slow[2] > slow[0]          # the map's low end is blue
    assert fast[0] > fast[2]          # its high end is red
    assert np.abs(slow - fast).max() > 60


def test_camera_frames_the_drop_and_the_crown():
    g = camera.Geometry(dim=3, drop=4e-3, film=1.2e-3, floor=0.09, gap=4e-4, speed=8.0,
                        t_end=1e-3, l0=4e-4)
    w, h = 1280, 720
    pose = camera.frame(g, (w, h))
    lo, hi = g.frame_box()
    # the box holds the drop at t = 0 (top at h + gap + D) and the crown base radius at t_end
    rc = g.drop * (2 / (3 * g.film / g.drop)) ** 0.25 * math.sqrt((g.t_end - g.gap / g.speed)
                                                                  * g.speed / g.drop)
    assert hi[2] >= g.film + g.gap + g.drop and hi[0] >= rc
    for x in (lo[0], hi[0]):
        for y in (lo[1], hi[1]):
            for z in (lo[2], hi[2]):
                c, r, d = pinhole(pose.eye, pose.target, pose.up, pose.fov, (x, y, z), (w, h))
                assert d > 0 and 0 <= c <= w and 0 <= r <= h
    assert pose.eye[2] > pose.target[2]                       # seen from above
    orbit = camera.Orbit.of(pose)
    orbit.drag(0.25, 0.0)
    turned = orbit.pose()
    assert math.dist(turned.eye, turned.target) == pytest.approx(math.dist(pose.eye,
                                                                           pose.target))
    assert turned.eye[2] == pytest.approx(pose.eye[2])


def test_caption_says_time_speed_and_fall_height():
    info = CaptionInfo({"en": "Two metres", "ja": "二メートル"}, speed=math.sqrt(2 * 9.81 * 2.0),
                       gravity=9.81)
    title, line = caption_lines(info, 7.5e-4, "en")
    assert title == "Two metres"
    assert "t = 0.750 ms" in line and "U = 6.26 m/s" in line and "2.00 m" in line
    assert caption_lines(info, 0.0, "ja")[0] == "二メートル"


def test_caption_keys_the_colour_scale():
    """The caption band shows the colour map with its ends: speed over [0, U], height over
    [0, h + D], pressure over [0, rho U^2] (render/colours.py); milk has no key."""
    from crowndemo.render.captions import draw_caption, key_labels
    from crowndemo.render.colours import ColourScale, colour_map
    U, h, D, rho = math.sqrt(2 * 9.81 * 2.0), 1e-3, 1e-2, 998.0
    scale = {m: ColourScale.for_scene(m, U, h, D, rho) for m in ("speed", "height", "pressure",
                                                                  "milk")}
    assert key_labels(scale["speed"], "en") == ("speed", "0", "6.26 m/s")
    assert key_labels(scale["height"], "en") == ("height above the floor", "0", "11 mm")
    assert key_labels(scale["pressure"], "en") == ("pressure", "0", "39.2 kPa")  # rho U^2
    assert key_labels(scale["milk"], "en") is None
    from crowndemo.render.captions import key_text          # live mode's panel line
    assert key_text(scale["speed"], "en") == "colours: speed 0 (blue) to 6.26 m/s (red)"
    assert key_text(scale["milk"], "en") is None
    info = CaptionInfo({"en": "Two metres"}, speed=U, gravity=9.81)
    blank = np.full((360, 640, 3), 30, np.uint8)
    plain = draw_caption(blank, info, 1e-3)
    assert np.array_equal(draw_caption(blank, info, 1e-3, scale=scale["milk"]), plain)
    keyed = draw_caption(blank, info, 1e-3, scale=scale["speed"])
    changed = np.argwhere(np.any(keyed != plain, axis=2))
    assert changed[:, 0].max() < 60 and changed[:, 1].min() > 320     # in the band, at the right
    pixels = {tuple(p) for p in keyed[:60, 320:].reshape(-1, 3)}
    for end in (0.0, 1.0):
        assert tuple((255 * colour_map(end)).astype(np.uint8)) in pixels


def test_sink_writes_frames_video_and_preview(renderer, tmp_path):
    r = config.load("quick-2d", "draft", ["quality.draft.l0=2e-4", "scene.t_end=2e-4",
                                          "scene.frame_interval=5e-5"])
    times = r.frame_times()
    assert len(times) == 4
    sim = simulator_for(r.build_scene())
    out = tmp_path / "quick-2d"
    sink = FrameSink(str(out), PresetView.from_resolved(r, RenderSettings(
        resolution=RES, fps=5, style="particles")), renderer)     # lit(): the spheres' ground
    sink.frame(sim, 0, 0.0)
    sim.run(r.t_end, times, on_frame=lambda s, i: sink.frame(s, i + 1, times[i]))
    sink.close("complete")
    frames = sorted(glob.glob(str(out / "frames" / "frame_*.png")))
    assert [os.path.basename(f) for f in frames] == [f"frame_{i:05d}.png" for i in range(5)]
    from crowndemo.render.video import read_image, read_video
    images = [read_image(f) for f in frames]
    for img in images:
        assert img.shape == (RES[1], RES[0], 3) and lit(img).mean() > 0.01   # not blank
    for a, b in zip(images, images[1:]):
        assert np.abs(a.astype(int) - b.astype(int)).max() > 50            # the drop moves
    assert len(list(read_video(str(out / "video.mp4")))) == 5
    assert (out / "preview.gif").stat().st_size > 0
    assert len(sink.frame_seconds) == 5 and sink.render_seconds > 0
    assert not glob.glob(str(out / ".*")) and not glob.glob(str(out / "frames" / ".*"))
    # a second recording into the same folder that does not complete: nothing stands as
    # complete, the old video is gone, the partial one is named as such
    again = FrameSink(str(out), PresetView.from_resolved(r, RenderSettings(resolution=RES)),
                      renderer)
    again.frame(sim, 0, sim.stats.time)
    again.close("interrupted")
    assert not (out / "video.mp4").exists() and not (out / "preview.gif").exists()
    assert (out / "video.partial.mp4").exists() and (out / "preview.partial.gif").exists()
    assert len(glob.glob(str(out / "frames" / "frame_*.png"))) == 1


def test_video_writer_writes_mp4_only(tmp_path):
    """Another suffix is refused by name before ffmpeg starts (it would fail on the uri)."""
    from crowndemo.render.video import VideoWriter, encode_mp4, read_video
    frame = np.zeros((8, 8, 3), np.uint8)
    for name in ("reel.txt", "reel.gif", "reel"):
        with pytest.raises(ValueError, match=r"must end in \.mp4"):
            VideoWriter(str(tmp_path / name), 10)
    assert not os.listdir(tmp_path)
    assert encode_mp4([frame] * 2, str(tmp_path / "REEL.MP4"), 10) == 2     # any case
    assert len(list(read_video(str(tmp_path / "REEL.MP4")))) == 2


def test_render_options_and_sink_from_args(tmp_path):
    import argparse

    from crowndemo.render import add_render_options, settings_from_args, sink_from_args
    p = argparse.ArgumentParser()
    add_render_options(p)
    s = settings_from_args(p.parse_args(["--booth", "--color", "milk", "--orbit", "--lang",
                                         "ja", "--no-video"]))
    assert (s.resolution, s.colour, s.orbit, s.lang, s.video) == ((1920, 1080), "milk", 1.0,
                                                                  "ja", False)
    assert settings_from_args(p.parse_args(["--resolution", "640x360"])).resolution == (640,
                                                                                        360)
    with pytest.raises(SystemExit):
        p.parse_args(["--resolution", "640by360"])
    r = config.load("quick", "draft")
    assert sink_from_args(p.parse_args(["--no-render"]), r, tmp_path) is None


def test_sink_whose_encoding_fails_leaves_only_partial_names(renderer, tmp_path, monkeypatch):
    """The video is made, the preview fails: close raises, and the video takes the partial
    name, so nothing stands as complete."""
    from crowndemo.render import video
    r = config.load("quick-2d", "draft")
    out = tmp_path / "rec"
    sink = FrameSink(str(out), PresetView.from_resolved(r, RenderSettings(resolution=RES)),
                     renderer)
    for i in range(3):
        video.write_png(np.full((RES[1], RES[0], 3), 40 * i, np.uint8),
                        str(out / "frames" / f"frame_{i:05d}.png"))

    def broken(*args, **kw):
        raise OverflowError("int too big to convert")
    monkeypatch.setattr(video, "encode_gif", broken)
    with pytest.raises(OverflowError):
        sink.close("complete")
    assert sorted(p.name for p in out.iterdir()) == ["frames", "video.partial.mp4"]
    assert sink.outputs == {"video": str(out / "video.partial.mp4")}
    assert len(list(video.read_video(str(out / "video.partial.mp4")))) == 3


def test_gif_delay_fits_its_16_bits(tmp_path):
    """At the slowest --fps, many frames per preview frame (and identical frames, which
    Pillow merges, adding their delays) still make a GIF."""
    from PIL import Image

    from crowndemo.render.video import encode_gif, write_png
    paths = []
    for i in range(2):
        paths.append(str(tmp_path / f"f{i}.png"))
        write_png(np.full((8, 8, 3), 200 * i, np.uint8), paths[-1])
    out = tmp_path / "p.gif"
    assert encode_gif(paths[:1] * 1600 + paths[1:] * 1600, str(out), 0.1) == 24
    with Image.open(out) as im:
        assert im.info["duration"] > 0
    assert sorted(os.listdir(tmp_path)) == ["f0.png", "f1.png", "p.gif"]
