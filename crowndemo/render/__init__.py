"""Rendering: the only code that touches ``ti.ui`` (Taichi's GGUI, offscreen through Vulkan).

One job per module:

- ``window``       the Vulkan check (RenderError with how to install a driver), opening and
                   closing GGUI windows;
- ``camera``       scene geometry -> camera pose (three-quarter view, orbit), projection math;
- ``colours``      colour fields (speed, height, pressure, milk), fixed scales, colour map;
- ``buffers``      Taichi fields sized to capacity, filled by a kernel from the particle state;
- ``floor``        the container floor mesh;
- ``surface``      particles -> the liquid surface (pysplashsurf), mirrored for symmetry planes;
- ``meshmeasure``  a mesh's area, volume, open edges, Euler characteristic, pieces;
- ``meshbuffers``  the surface mesh's GGUI fields, with headroom;
- ``renderer``     Renderer: one GGUI window, the surface or spheres, floor, frame capture;
- ``captions``     Pillow text: frame captions, title cards, fonts (CJK where installed);
- ``view``         a preset's camera, colours, sphere size and caption; RenderSettings;
- ``video``        PNG, MP4 (H.264) and GIF files, written under temporary names;
- ``sink``         FrameSink: the frames, video and preview of a recording, timed;
- ``options``      the command-line rendering options and ``sink_from_args``;
- ``player``       the booth loop over recordings (window or video file);
- ``live_control`` live mode's logic (sliders -> preset -> run), no window;
- ``live``         live mode's window.
"""
from .window import INSTALL_HINT, RenderError, check_available, has_display
from .options import add_render_options, settings_from_args, sink_from_args
from .view import PresetView, RenderSettings

__all__ = ["RenderError", "INSTALL_HINT", "check_available", "has_display",
           "add_render_options", "settings_from_args", "sink_from_args", "PresetView",
           "RenderSettings"]
