"""Live mode's window: the run drawn as it is computed, a panel with the sliders (fall height,
film thickness, drop size) and a Drop button, the camera orbiting when the left mouse button
drags outside the panel (Up/Down keys zoom). The logic lives in ``live_control``.

Live draws the particles as spheres, and its panel says so: the liquid surface costs about
1.6 s a frame for ``quick`` on two CPU cores (splashsurf), against a frame budget of 1/15 s."""
from __future__ import annotations

import time
from typing import Optional

from . import camera
from .captions import caption_lines, key_text, text_in
from .live_control import LiveController
from .renderer import Renderer
from .view import PresetView, RenderSettings

LIVE_STYLE = "drawn as particles: the liquid surface is too slow for live on a CPU"
PANEL = (0.01, 0.01, 0.34, 0.36)          # x, y, width, height as fractions of the window
STEP_BUDGET = 1.0 / 15                    # wall seconds of stepping per displayed frame
LABELS = {"en": {"drop": "Drop", "title": "Milk crown, live"},
          "ja": {"drop": "落とす", "title": "ミルククラウン（ライブ）"}}


def _in_panel(x: float, y: float) -> bool:
    """Whether a cursor position (0..1, y up) lies over the panel (y measured from the top)."""
    px, py, pw, ph = PANEL
    return px <= x <= px + pw and py <= 1.0 - y <= py + ph


def run_live(controller: LiveController, settings: RenderSettings = RenderSettings(),
             max_frames: Optional[int] = None) -> int:
    """The interactive loop until the window closes (or ``max_frames``); returns the frames
    shown. GGUI's own text widgets show the Latin captions (its font has no Japanese)."""
    import taichi as ti
    lang = "en"                      # GGUI's panel font covers Latin only
    renderer = Renderer(settings.resolution, show=True, title=LABELS[lang]["title"])
    window, gui = renderer.window, renderer.window.get_gui()
    view: Optional[PresetView] = None
    orbit: Optional[camera.Orbit] = None
    last_cursor, shown, view_run = None, 0, -1
    controller.drop(raise_errors=True)
    try:
        while window.running and (max_frames is None or shown < max_frames):
            if window.get_event(ti.ui.PRESS) and window.event.key == ti.ui.ESCAPE:
                break
            if view_run != controller.runs:       # a new run: a new view
                view = PresetView.from_resolved(controller.resolved, settings)
                orbit = orbit or camera.Orbit.of(view.start)
                orbit.target = view.start.target
                view_run = controller.runs
            # the panel
            with gui.sub_window(LABELS[lang]["title"], *PANEL) as g:
                for s in controller.sliders:
                    shown_value = g.slider_float(f"{text_in(s.label, lang)} [{s.unit}]",
                                                 controller.values[s.name] * s.scale,
                                                 s.lo * s.scale, s.hi * s.scale)
                    controller.set(s.name, shown_value / s.scale)
                if g.button(LABELS[lang]["drop"]):
                    controller.drop()
                for line in caption_lines(view.caption, controller.time, lang)[1:]:
                    g.text(line)
                key = key_text(view.scale, lang)
                if key:
                    g.text(key)
                g.text(LIVE_STYLE)
                g.text(controller.status)
                if controller.error:
                    g.text(controller.error[:300])
            # the camera: drag with the left button outside the panel, Up/Down zoom
            x, y = window.get_cursor_pos()
            if window.is_pressed(ti.ui.LMB) and not _in_panel(x, y):
                if last_cursor is not None:
                    orbit.drag(x - last_cursor[0], y - last_cursor[1])
                last_cursor = (x, y)
            else:
                last_cursor = None
            if window.is_pressed(ti.ui.UP):
                orbit.zoom(0.97)
            if window.is_pressed(ti.ui.DOWN):
                orbit.zoom(1.03)
            start = time.perf_counter()
            controller.advance(STEP_BUDGET)
            renderer.draw(controller.sim.state, orbit.pose(), view.scale, view.radius,
                          view.floor)
            window.show()
            shown += 1
            time.sleep(max(0.0, 0.01 - (time.perf_counter() - start)))
    finally:
        renderer.close()
    return shown


__all__ = ["run_live"]
