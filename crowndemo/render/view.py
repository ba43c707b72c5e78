"""How a preset is shown: its style (the liquid surface or spheres), camera (with the optional
orbit), colour scale, sphere size, floor and caption, from the resolved preset and the render
settings. ``image`` renders one captioned frame of a particle state."""
from __future__ import annotations

import time as _time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Optional, Sequence, Tuple

import numpy as np

from . import camera, still_film
from .captions import CaptionInfo, draw_caption
from .colours import DEFAULT_MODE, ColourScale, fields_read, vertex_colours
from .renderer import DEFAULT_RESOLUTION
from .surface import SurfaceMesh, SurfaceParams, fluid_of, plane_axes, reconstruct

if TYPE_CHECKING:
    from ..config.resolve import Resolved
    from ..core.state import ParticleState
    from .floor import FloorMesh
    from .renderer import Renderer

SPHERE = 0.5        # drawn sphere radius / l0: neighbouring particles touch
STYLES = ("surface", "particles")
DEFAULT_STYLE = "surface"
SURFACE_COLOUR = "milk"          # the surface's default colour field; spheres: DEFAULT_MODE
SURFACE_ELEVATION = 18.0         # degrees above the film: low, as the crown is photographed
SYMMETRY_PLANES = {"full": [], "half": ["x"], "quarter": ["x", "y"]}


def default_colour(style: str) -> str:
    return SURFACE_COLOUR if style == "surface" else DEFAULT_MODE


def planes_of(resolved: Resolved) -> Sequence[str]:
    """The symmetry planes of a preset's run (axis names; none when it has no such key)."""
    return SYMMETRY_PLANES[resolved.scene.get("symmetry", "full") or "full"]


@dataclass(frozen=True)
class RenderSettings:
    colour: Optional[str] = None         # None: the style's (milk on the surface, else speed)
    lang: str = "en"
    resolution: Tuple[int, int] = DEFAULT_RESOLUTION
    orbit: float = 0.0           # degrees the camera turns per frame (0: fixed)
    video: bool = True           # encode video.mp4 and preview.gif when a recording closes
    fps: float = 12.0            # frames per second of the video
    style: str = DEFAULT_STYLE   # surface (the liquid, reconstructed) or particles (spheres)
    still_film: bool = True      # 3D surface: the film at rest drawn flat (still_film.py)

    def __post_init__(self):
        if self.style not in STYLES:
            raise ValueError(f"style {self.style!r} is not one of {', '.join(STYLES)}")
        if self.colour is None:
            object.__setattr__(self, "colour", default_colour(self.style))


@dataclass
class PresetView:
    geometry: camera.Geometry
    caption: CaptionInfo
    scale: ColourScale
    settings: RenderSettings = field(default_factory=RenderSettings)
    marker: Optional[str] = None          # a label in the corner of every frame
    planes: Sequence[str] = ()            # the run's symmetry planes: the surface is mirrored
    surface_params: Optional[SurfaceParams] = None     # None: SurfaceParams()

    def __post_init__(self):
        low = self.settings.style == "surface" and self.geometry.dim == 3
        self.start = camera.frame(self.geometry, self.settings.resolution,
                                  elevation=SURFACE_ELEVATION if low else None)
        self._floor = None
        self.surface_seconds = 0.0            # the last frame's reconstruction, wall seconds
        self.triangles = 0                    # the last frame's surface triangles

    @classmethod
    def from_resolved(cls, resolved: Resolved, settings: RenderSettings = RenderSettings()
                      ) -> "PresetView":
        geometry = camera.Geometry.from_resolved(resolved)
        scale = ColourScale.for_scene(settings.colour, resolved.speed, geometry.film,
                                      geometry.drop, resolved.liquid["rho"])
        return cls(geometry, CaptionInfo.from_resolved(resolved), scale, settings,
                   planes=planes_of(resolved))

    @property
    def radius(self) -> float:
        return SPHERE * self.geometry.l0

    def pose(self, index: int) -> camera.Pose:
        return self.start.orbited(self.settings.orbit * index)

    @property
    def floor(self) -> FloorMesh:
        if self._floor is None:                     # Taichi fields: made on first use
            from .floor import FloorMesh, SURFACE_FLOOR
            surface = self.settings.style == "surface"
            self._floor = (FloorMesh(self.geometry, SURFACE_FLOOR, rim=True) if surface
                           else FloorMesh(self.geometry))
        return self._floor

    def image(self, renderer: Renderer, state: ParticleState, time: float, index: int = 0,
              pose: Optional[camera.Pose] = None) -> np.ndarray:
        """One captioned frame (h, w, 3 uint8) of ``state`` at simulated ``time``."""
        pose = pose or self.pose(index)
        if self.settings.style == "surface":
            pos, fields = fluid_of(state)
            img = self.surface_image(renderer, pos, fields, pose)
        else:
            img = renderer.render(state, pose, self.scale, self.radius, self.floor,
                                  plane_axes(self.planes))
        return draw_caption(img, self.caption, time, self.settings.lang, self.marker,
                            self.scale)

    def surface(self, pos: np.ndarray, fields: dict) -> SurfaceMesh:
        """The liquid surface of fluid particles (timed: ``surface_seconds``)."""
        start = _time.perf_counter()
        g, params = self.geometry, self.surface_params or SurfaceParams()
        if g.dim == 3 and self.settings.still_film and len(pos):
            # the film at rest drawn flat (still_film.py): reconstruct the rest
            cols = still_film.columns(pos, g.l0, g.film, params.band(g.l0), self.planes,
                                      g.floor, g.film_extent)
            mesh = reconstruct(pos[cols.keep], g.l0, {k: v[cols.keep] for k, v in fields.items()},
                               params, planes=self.planes)
            mesh = still_film.join(mesh, cols)
        else:
            mesh = reconstruct(pos, g.l0, fields, params, planes=self.planes)
        self.surface_seconds = _time.perf_counter() - start
        self.triangles = mesh.n_triangles
        return mesh

    def surface_image(self, renderer: Renderer, pos: np.ndarray, fields: dict,
                      pose: camera.Pose) -> np.ndarray:
        """The uncaptioned frame of the surface of fluid particles ``pos`` with ``fields``
        (only the one the colour scale reads goes to the reconstruction)."""
        mesh = self.surface(pos, {k: fields[k] for k in fields_read(self.scale.mode)})
        colours = vertex_colours(self.scale, mesh.vertices[:, 2], mesh.fields)
        return renderer.render_surface(mesh, colours, pose, self.floor)


__all__ = ["RenderSettings", "PresetView", "SPHERE", "STYLES", "DEFAULT_STYLE",
           "default_colour", "planes_of"]
