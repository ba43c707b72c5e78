"""Live mode's controller, without a window: slider values -> preset values (through the
config layer) -> a restarted run."""
import math

import pytest

from crowndemo.cli import live as live_cli
from crowndemo.cli import main
from crowndemo.render import window
from crowndemo.render.live_control import LiveController, overrides

SETS = ["quality.draft.l0=2e-4"]          # quick-2d, coarser: a cheap 2D run
G = 9.81                                  # quick's gravity


@pytest.fixture(scope="module")
def controller():
    return LiveController("quick-2d", "draft", sets=SETS)


def test_sliders_map_to_preset_values(controller):
    l0 = 2e-4
    film, drop = [s for s in controller.sliders if s.name in ("film", "drop")]
    assert film.lo == pytest.approx(3 * l0)            # at least 3 particles across
    assert drop.lo >= 3 * l0
    controller.set("height", 1.25)
    controller.set("film", 8e-4)
    controller.set("drop", 3e-3)
    r = controller.resolve()
    assert r.speed == pytest.approx(math.sqrt(2 * G * 1.25))     # U = sqrt(2 g H)
    assert r.scene["film"] == pytest.approx(8e-4)
    assert r.scene["drop"] == pytest.approx(3e-3)
    assert r.l0 == pytest.approx(l0) and r.quality == "draft"
    # clamped to the slider, which reaches up to the preset's own height (U = 8 m/s)
    assert controller.set("height", 50.0) == pytest.approx(8.0 ** 2 / (2 * G))
    assert controller.set("film", 1e-6) == pytest.approx(3 * l0)
    assert "scene.speed=" in overrides(controller.values, controller.sliders)


def test_drop_restarts_the_run(controller):
    controller.set("height", 1.25)
    controller.set("film", 8e-4)
    controller.set("drop", 3e-3)
    assert controller.drop()
    sim = controller.sim
    n_first = sim.n_fluid
    assert controller.time == 0.0
    assert controller.advance(0.0) == 1 and controller.time > 0
    # a smaller drop: the run restarts from t = 0 in the same compiled simulator
    controller.set("drop", 2e-3)
    assert controller.drop()
    assert controller.runs == 2 and controller.time == 0.0
    assert controller.sim is sim and controller.sim.n_fluid < n_first
    assert controller.resolved.scene["drop"] == pytest.approx(2e-3)
    # a value the preset refuses (past the slider's range): reported, the run goes on
    controller.advance(0.0)
    t = controller.time
    controller.values["film"] = 1e-4                  # half a particle across the film
    assert not controller.drop()
    assert "film" in controller.error and controller.runs == 2
    assert controller.sim is sim and controller.time == t


def test_the_first_drop_runs_at_the_presets_speed(controller):
    fresh = LiveController("quick-2d", "draft", sets=SETS, start=lambda r: None)
    assert fresh.resolve().speed == pytest.approx(8.0)      # not the booth range's 3 m


def test_an_unstable_run_says_which_sliders_help():
    """max_mach * c just above U: gravity takes the falling drop past it in the first step."""
    c = LiveController("quick-2d", "draft", sets=SETS + ["numerics.max_mach=0.2000001"])
    assert c.drop()
    c.advance(0.0)
    assert c.unstable and c.status == "unstable" and c.finished
    assert c.error.startswith("unstable at t = ") and "max_mach" in c.error
    assert c.error.endswith("try a thicker film, a smaller drop or a lower fall height")
    assert len(c.error) < 300                  # the panel shows it whole
    assert c.advance(0.0) == 0


@pytest.fixture
def no_backend(monkeypatch):
    """Fails the test if `crowndemo live` gets as far as starting Taichi."""
    monkeypatch.setattr(live_cli, "start_backend", lambda args: pytest.fail("backend started"))


def test_live_without_a_display_gives_its_own_advice(monkeypatch, capsys, no_backend):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert main(["live"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("crowndemo: error: no display (DISPLAY unset); live mode needs a "
                          "window; without one, use 'crowndemo record PRESET', then "
                          "'crowndemo play --headless --out FILE.mp4'")
    assert err.count("\n") == 1


def test_live_with_no_x_server(monkeypatch, tmp_path, capsys, no_backend):
    monkeypatch.setattr(window, "X11_SOCKET_DIR", str(tmp_path))
    monkeypatch.setenv("DISPLAY", ":99")
    assert main(["live"]) == 2
    assert "error: cannot open a window on DISPLAY :99 (no X server answers" in \
        capsys.readouterr().err


def test_live_reports_a_misspelt_preset_before_the_display(monkeypatch, capsys, no_backend):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert main(["live", "qiuck"]) == 2
    err = capsys.readouterr().err
    assert "preset = 'qiuck'" in err and "did you mean 'quick'" in err
    assert "display" not in err
    assert main(["live", "--set", "scene.film=-1"]) == 2     # --set values too
    assert "scene.film" in capsys.readouterr().err
