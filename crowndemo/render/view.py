"""How a preset is shown: its camera (with the optional orbit), colour scale, sphere size,
floor and caption, from the resolved preset and the render settings. ``image`` renders one
captioned frame of a particle state."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Optional, Tuple

import numpy as np

from . import camera
from .captions import CaptionInfo, draw_caption
from .colours import DEFAULT_MODE, ColourScale
from .renderer import DEFAULT_RESOLUTION

if TYPE_CHECKING:
    from ..config.resolve import Resolved
    from ..core.state import ParticleState
    from .floor import FloorMesh
    from .renderer import Renderer

SPHERE = 0.5        # drawn sphere radius / l0: neighbouring particles touch


@dataclass(frozen=True)
class RenderSettings:
    colour: str = DEFAULT_MODE
    lang: str = "en"
    resolution: Tuple[int, int] = DEFAULT_RESOLUTION
    orbit: float = 0.0           # degrees the camera turns per frame (0: fixed)
    video: bool = True           # encode video.mp4 and preview.gif when a recording closes
    fps: float = 12.0            # frames per second of the video


@dataclass
class PresetView:
    geometry: camera.Geometry
    caption: CaptionInfo
    scale: ColourScale
    settings: RenderSettings = field(default_factory=RenderSettings)
    marker: Optional[str] = None          # a label in the corner of every frame

    def __post_init__(self):
        self.start = camera.frame(self.geometry, self.settings.resolution)
        self._floor = None

    @classmethod
    def from_resolved(cls, resolved: Resolved, settings: RenderSettings = RenderSettings()
                      ) -> "PresetView":
        geometry = camera.Geometry.from_resolved(resolved)
        scale = ColourScale.for_scene(settings.colour, resolved.speed, geometry.film,
                                      geometry.drop, resolved.liquid["rho"])
        return cls(geometry, CaptionInfo.from_resolved(resolved), scale, settings)

    @property
    def radius(self) -> float:
        return SPHERE * self.geometry.l0

    def pose(self, index: int) -> camera.Pose:
        return self.start.orbited(self.settings.orbit * index)

    @property
    def floor(self) -> FloorMesh:
        if self._floor is None:                     # Taichi fields: made on first use
            from .floor import FloorMesh
            self._floor = FloorMesh(self.geometry)
        return self._floor

    def image(self, renderer: Renderer, state: ParticleState, time: float, index: int = 0,
              pose: Optional[camera.Pose] = None) -> np.ndarray:
        """One captioned frame (h, w, 3 uint8) of ``state`` at simulated ``time``."""
        img = renderer.render(state, pose or self.pose(index), self.scale, self.radius,
                              self.floor)
        return draw_caption(img, self.caption, time, self.settings.lang, self.marker,
                            self.scale)


__all__ = ["RenderSettings", "PresetView", "SPHERE"]
