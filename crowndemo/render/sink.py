"""The frame sink of a recording: each frame rendered to ``OUT/frames/frame_00000.png``, and
when the recording closes, ``OUT/video.mp4`` and ``OUT/preview.gif``. A recording that did not
complete gets ``video.partial.mp4`` and ``preview.partial.gif`` instead, so a partial video
never stands as complete; so does one whose encoding failed (``close`` then raises). Every
file is written under a temporary name and renamed.

It times itself: ``frame_seconds`` (surface, render, caption and PNG of each frame),
``render_seconds`` (their sum), ``surface_seconds`` (the surface reconstruction's part of it)
and ``encode_seconds``, to set against the simulation's time per frame; and how often GGUI
drew a surface blank and it was drawn again (``blank_redraws``; ``blank_frames``: still blank).
"""
from __future__ import annotations

import os
import time as _time
from typing import TYPE_CHECKING, Dict, List, Optional

from ..record.files import FRAMES, frame_name, remove_rendered, rendered_frames, video_names
from . import video
from .renderer import Renderer
from .view import PresetView

if TYPE_CHECKING:
    from ..core.step import Simulator


class FrameSink:
    def __init__(self, out_dir: str, view: PresetView, renderer: Optional[Renderer] = None,
                 resume: bool = False):
        """Frames go to ``out_dir/frames``; ``renderer`` (same resolution) is shared, not
        closed by ``close``; without one the sink opens and closes its own. ``resume`` keeps
        the frames of the interrupted recording that is being continued (the video is made
        from every frame in the folder)."""
        self.out_dir = out_dir
        self.frames_dir = os.path.join(out_dir, FRAMES)
        self.view = view
        self.settings = view.settings
        os.makedirs(self.frames_dir, exist_ok=True)
        # frames and videos of an earlier recording in the folder would mix with ours (a
        # resumed recording keeps its frames: they are its own)
        remove_rendered(out_dir, keep_frames=resume)
        self._owns_renderer = renderer is None     # a renderer passed in stays open
        self.renderer = renderer or Renderer(self.settings.resolution)
        if self.renderer.resolution != tuple(self.settings.resolution):
            raise ValueError(f"renderer of {self.renderer.resolution} for frames of "
                             f"{self.settings.resolution}")
        # GGUI's blank surface frames drawn again (Renderer.render_surface), from here on
        self._blank_start = (self.renderer.blank_retries, self.renderer.blank_frames)
        self.frame_seconds: List[float] = []
        self.surface_frame_seconds: List[float] = []
        self.encode_seconds = 0.0
        self.paths: List[str] = []
        self.outputs: Dict[str, str] = {}          # what close() wrote: video, preview
        self.status: Optional[str] = None

    @property
    def render_seconds(self) -> float:
        return sum(self.frame_seconds)

    def frame(self, sim: Simulator, index: int, time: float) -> None:
        """Render ``sim``'s particles at simulated ``time`` as frame ``index``."""
        if self.status is not None:
            raise RuntimeError("the frame sink is closed")
        start = _time.perf_counter()
        self.view.surface_seconds = 0.0
        image = self.view.image(self.renderer, sim.state, time, index)
        self.surface_frame_seconds.append(self.view.surface_seconds)
        path = os.path.join(self.frames_dir, frame_name(index, ".png"))
        video.write_png(image, path)
        self.paths.append(path)
        self.frame_seconds.append(_time.perf_counter() - start)

    def release(self) -> None:
        """Give the window back without encoding anything: the recording never started (a
        refused resume, a failed set-up)."""
        if self.status is None:
            self.status = "released"
            if self._owns_renderer:
                self.renderer.close()

    def close(self, status: str) -> None:
        """Release the window; encode the video and preview (named by ``status``)."""
        if self.status is not None:
            return
        self.status = status
        if self._owns_renderer:
            self.renderer.close()
        paths = rendered_frames(self.out_dir)
        if not (self.settings.video and paths):
            return
        start = _time.perf_counter()
        try:
            self._encode(paths, video_names(status))
        except BaseException:
            self._mark_partial()
            raise
        finally:
            self.encode_seconds = _time.perf_counter() - start

    def _encode(self, paths: List[str], names: Dict[str, str]) -> None:
        """The MP4 and the GIF preview of the frames in ``paths``, named by ``names``."""
        mp4 = os.path.join(self.out_dir, names["video"])
        video.encode_mp4((video.read_image(p) for p in paths), mp4, self.settings.fps)
        self.outputs["video"] = mp4
        gif = os.path.join(self.out_dir, names["preview"])
        video.encode_gif(paths, gif, self.settings.fps)
        self.outputs["preview"] = gif

    def _mark_partial(self) -> None:
        """Encoding failed: what it wrote takes the partial names, so that nothing stands
        as complete."""
        partial = video_names("failed")
        for kind, path in list(self.outputs.items()):
            target = os.path.join(self.out_dir, partial[kind])
            if path != target:
                os.replace(path, target)
            self.outputs[kind] = target

    def timing(self) -> Dict[str, float]:
        n = len(self.frame_seconds)
        surface = sum(self.surface_frame_seconds)
        return {"frames": n, "style": self.settings.style,
                "render_seconds": self.render_seconds,
                "render_seconds_per_frame": self.render_seconds / n if n else 0.0,
                "surface_seconds": surface,
                "surface_seconds_per_frame": surface / n if n else 0.0,
                "surface_triangles_last": self.view.triangles,
                "blank_redraws": self.renderer.blank_retries - self._blank_start[0],
                "blank_frames": self.renderer.blank_frames - self._blank_start[1],
                "encode_seconds": self.encode_seconds}


__all__ = ["FrameSink"]
