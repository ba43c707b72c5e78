"""The GGUI renderer: one window (offscreen unless shown), particles as lit spheres with
per-vertex colours or the liquid surface as a two-sided mesh (the milk look: a dark ground, a
key light from behind and to the side, low ambient), an optional floor mesh, and a capture of
each frame as an RGB image."""
from __future__ import annotations

import math
from typing import TYPE_CHECKING, Optional, Sequence, Tuple

import numpy as np

from ..core.state import ParticleState
from .buffers import ParticleBuffers
from .camera import Pose, project
from .colours import ColourScale
from .floor import FloorMesh
from .meshbuffers import MeshBuffers
from .window import close_window, open_window

if TYPE_CHECKING:
    from .surface import SurfaceMesh

BACKGROUND = (0.07, 0.08, 0.10)
AMBIENT = (0.35, 0.35, 0.35)
LIGHT = (0.75, 0.75, 0.75)
DEFAULT_RESOLUTION = (1280, 720)
BOOTH_RESOLUTION = (1920, 1080)
# the surface's look (GGUI shades ambient + diffuse, no specular): dark ground, low ambient so
# the sheet has shape, a key light behind the crown and to the side (the rim and jets catch
# it), a weak fill from the camera's side
SURFACE_BACKGROUND = (0.015, 0.017, 0.022)
SURFACE_AMBIENT = (0.16, 0.16, 0.16)
KEY_LIGHT = (0.95, 0.93, 0.88)
FILL_LIGHT = (0.30, 0.31, 0.34)
KEY_TURN, KEY_RISE = 125.0, 40.0      # key light: degrees from the eye about the axis, above
BLANK_RETRIES = 5     # a surface frame GGUI drew blank is drawn again (render_surface)


class Renderer:
    """Draws a ParticleState. Call ``render`` once per frame: each capture re-submits the
    scene (GGUI keeps one frame per submission)."""

    def __init__(self, resolution: Tuple[int, int] = DEFAULT_RESOLUTION, show: bool = False,
                 title: str = "crowndemo", background=BACKGROUND):
        import taichi as ti
        self.resolution = (int(resolution[0]), int(resolution[1]))
        self.window = open_window(title, self.resolution, show=show)
        self.canvas = self.window.get_canvas()
        self.scene = self.window.get_scene()
        self.camera = ti.ui.Camera()
        self.background = tuple(background)
        self.buffers: Optional[ParticleBuffers] = None
        self.mesh_buffers: Optional[MeshBuffers] = None
        self.drawn = 0                       # particles (triangles) drawn in the last frame
        self.blank_retries = 0               # surface frames GGUI drew blank, drawn again
        self.blank_frames = 0                # ... and still blank after BLANK_RETRIES
        self._empty = None                   # (pose, floor, its frame without the mesh)

    def _buffers_for(self, capacity: int, planes: Sequence[int] = ()) -> ParticleBuffers:
        if (self.buffers is None or self.buffers.capacity < capacity
                or self.buffers.planes != tuple(planes)):
            self.buffers = ParticleBuffers(capacity, planes)
        return self.buffers

    def _set_camera(self, pose: Pose) -> float:
        cam, scene = self.camera, self.scene
        cam.position(*pose.eye)
        cam.lookat(*pose.target)
        cam.up(*pose.up)
        cam.fov(pose.fov)
        dist = math.dist(pose.eye, pose.target)
        cam.z_near(dist * 1e-3)
        cam.z_far(dist * 1e2)
        scene.set_camera(cam)
        return dist

    def draw(self, state: ParticleState, pose: Pose, scale: ColourScale, radius: float,
             floor: Optional[FloorMesh] = None, planes: Sequence[int] = ()) -> None:
        """Submit one frame: the fluid of ``state`` as spheres of world ``radius``; with
        symmetry ``planes`` (axes) mirrored into the whole."""
        scene = self.scene
        dist = self._set_camera(pose)
        scene.ambient_light(AMBIENT)
        eye, target = np.array(pose.eye), np.array(pose.target)
        scene.point_light(tuple(eye + np.array([0.0, 0.0, 0.8 * dist])
                                + 0.3 * (eye - target)), LIGHT)
        if floor is not None:
            floor.draw(scene)
        buf = self._buffers_for(state.capacity, planes)
        self.drawn = buf.fill(state, scale)
        if self.drawn:
            w, h = self.resolution
            # GGUI 1.7.4 sizes a particle sprite by the window's width where a projection
            # needs its height: scale the radius by h / w so spheres keep their world size
            scene.particles(buf.pos, radius=radius * h / w, per_vertex_color=buf.colour,
                            index_count=self.drawn)
        self.canvas.set_background_color(self.background)
        self.canvas.scene(scene)

    def draw_surface(self, mesh: SurfaceMesh, colours: np.ndarray, pose: Pose,
                     floor: Optional[FloorMesh] = None) -> None:
        """Submit one frame: ``mesh`` (two-sided, its own normals) with per-vertex
        ``colours`` (V x 3 in 0..1), lit by the key and fill lights."""
        if self.mesh_buffers is None:
            self.mesh_buffers = MeshBuffers()
        self.mesh_buffers.fill(mesh.vertices, mesh.triangles, mesh.normals, colours)
        self.drawn = mesh.n_triangles
        self._submit_surface(pose, floor)

    def render_surface(self, mesh: SurfaceMesh, colours: np.ndarray, pose: Pose,
                       floor: Optional[FloorMesh] = None) -> np.ndarray:
        """``draw_surface`` and ``capture``, checked: GGUI 1.7.4 on lavapipe sometimes draws
        nothing of the mesh (meshbuffers.py). A frame of a mesh in view that comes out the
        same, pixel for pixel, as the frame without it is drawn again, its fields made anew
        through a one-triangle mesh, at most BLANK_RETRIES times; counted in
        ``blank_retries`` and, when every try came out blank, ``blank_frames``."""
        self.draw_surface(mesh, colours, pose, floor)
        img = self.capture()
        if not self.drawn or not in_view(mesh.vertices, pose, self.resolution):
            return img
        empty = self._without_mesh(pose, floor)
        for _ in range(BLANK_RETRIES):
            if not np.array_equal(img, empty):
                return img
            self.blank_retries += 1
            one = np.zeros((3, 3))
            buf = self.mesh_buffers
            buf.fill(one, np.array([[0, 1, 2]]), one, one, remake=True)
            self._submit_surface(pose, floor)
            self.capture()
            buf.fill(mesh.vertices, mesh.triangles, mesh.normals, colours, remake=True)
            self._submit_surface(pose, floor)
            img = self.capture()
        if np.array_equal(img, empty):
            self.blank_frames += 1
        return img

    def _without_mesh(self, pose: Pose, floor: Optional[FloorMesh]) -> np.ndarray:
        """The frame of ``pose`` with the ground and dish only (kept for the last pose)."""
        if self._empty is None or self._empty[0] != pose or self._empty[1] is not floor:
            drawn, self.drawn = self.drawn, 0
            self._submit_surface(pose, floor)
            self._empty = (pose, floor, self.capture())     # the floor by identity
            self.drawn = drawn
        return self._empty[2]

    def _submit_surface(self, pose: Pose, floor: Optional[FloorMesh]) -> None:
        scene = self.scene
        dist = self._set_camera(pose)
        scene.ambient_light(SURFACE_AMBIENT)
        for turn, rise, colour in ((KEY_TURN, KEY_RISE, KEY_LIGHT), (-30.0, 20.0, FILL_LIGHT)):
            scene.point_light(_light_at(pose, dist, turn, rise), colour)
        if floor is not None:
            floor.draw(scene)
        buf = self.mesh_buffers
        if self.drawn:
            for offset, count in buf.pieces():
                scene.mesh(buf.vertices, buf.indices, buf.normals, per_vertex_color=buf.colours,
                           two_sided=True, vertex_count=buf.n_vertices, index_offset=offset,
                           index_count=count)
        self.canvas.set_background_color(SURFACE_BACKGROUND)
        self.canvas.scene(scene)

    def capture(self) -> np.ndarray:
        """The submitted frame as an (height, width, 3) uint8 image, top row first."""
        img = self.window.get_image_buffer_as_numpy()          # (w, h, 4), bottom row first
        rgb = np.transpose(img[:, ::-1, :3], (1, 0, 2))
        return (np.clip(rgb, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)

    def render(self, state: ParticleState, pose: Pose, scale: ColourScale, radius: float,
               floor: Optional[FloorMesh] = None, planes: Sequence[int] = ()) -> np.ndarray:
        self.draw(state, pose, scale, radius, floor, planes)
        return self.capture()

    def close(self) -> None:
        close_window(self.window)

    def __enter__(self) -> "Renderer":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def in_view(points: np.ndarray, pose: Pose, resolution: Tuple[int, int],
            sample: int = 20000) -> bool:
    """Whether any of ``points`` (N x 3; at most ``sample`` of them, evenly taken) lands
    inside the image, in front of the eye."""
    px = project(pose, points[::max(1, len(points) // sample)], resolution)
    w, h = resolution
    return bool(np.any((px[:, 2] > 0) & (px[:, 0] >= 0) & (px[:, 0] < w) & (px[:, 1] >= 0)
                       & (px[:, 1] < h)))


def _light_at(pose: Pose, dist: float, turn: float, rise: float) -> Tuple[float, ...]:
    """A light 2 ``dist`` from the target, ``turn`` degrees about the vertical from the eye's
    side, ``rise`` degrees above the horizontal."""
    d = np.subtract(pose.eye, pose.target)
    az = math.atan2(d[1], d[0]) + math.radians(turn)
    el = math.radians(rise)
    offset = 2 * dist * np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az),
                                  math.sin(el)])
    return tuple(float(v) for v in np.add(pose.target, offset))


__all__ = ["Renderer", "BACKGROUND", "DEFAULT_RESOLUTION", "BOOTH_RESOLUTION",
           "SURFACE_BACKGROUND"]
