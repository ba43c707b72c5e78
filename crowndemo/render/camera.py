"""Camera poses, derived from the scene's geometry (no Taichi here).

World axes are the simulation's: z up in 3D; a 2D scene (x, y-up) is drawn in the plane y = 0
of a 3D view, its vertical axis becoming z. The pose is an elevated three-quarter view (3D) or
a nearly frontal one (2D) whose distance is chosen so that the box the crown can fill by the
end time stays inside the picture. The matrices follow GGUI's conventions (vertical field of
view in degrees, right-handed look-at), so ``project`` says where a point lands in the image.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Optional, Sequence, Tuple

import numpy as np

from ..scenes.crown import crown_base_radius, film_extent

if TYPE_CHECKING:
    from ..config.resolve import Resolved

Vec3 = Tuple[float, float, float]
MARGIN = 0.85            # the framed box fills at most this fraction of the half-image


FRAME_REACH = 1.3       # the frame's half width / Yarin & Weiss's crown base radius at t_end
FRAME_TOP = 1.0         # its height above the film / that radius


@dataclass(frozen=True)
class Geometry:
    """What the camera and the floor need to know about a drop-on-film scene (metres)."""
    dim: int
    drop: float          # diameter D
    film: float          # thickness h
    floor: float         # side of the square floor (width of the 2D slice)
    gap: float           # film surface to the bottom of the drop at t = 0
    speed: float         # impact speed U
    t_end: float
    l0: float
    film_extent: Optional[float] = None   # radius of the film simulated, when trimmed (3D)

    @classmethod
    def from_resolved(cls, resolved: Resolved) -> "Geometry":
        s = resolved.scene
        extent, trimmed = film_extent(s["floor"], s["trim"], s["t_end"], s["speed"], s["drop"],
                                      s["film"], s["gap"], s["trim_reach"])
        return cls(resolved.dim, s["drop"], s["film"], s["floor"], s["gap"], s["speed"],
                   s["t_end"], resolved.l0, extent if trimmed and resolved.dim == 3 else None)

    def frame_box(self) -> Tuple[np.ndarray, np.ndarray]:
        """The box to keep in view: the drop at t = 0 and the crown by t_end, within the floor:
        out to 1.3 Yarin & Weiss base radii (the runs' crowns stand at 0.75-0.8 of it,
        VALIDATION.md crown-base: their spray has room) and up to that radius. A box half as
        high fits the coarse rungs (their rims stand at 0.25-0.3 of it) but not the seed
        rung's, whose rim rose to 0.64 of it by 4 ms (18.2 mm, VALIDATION.md). (Frames drawn
        without the liquid, once blamed on the lower box, were GGUI's: Renderer.render_surface.)"""
        rc = crown_base_radius(self.t_end - self.gap / self.speed, self.speed, self.drop,
                               self.film)
        half = min(max(FRAME_REACH * rc, 0.75 * self.drop), self.floor / 2)
        top = max(self.film + self.gap + self.drop, self.film + FRAME_TOP * rc)
        depth = half if self.dim == 3 else self.slice_depth / 2
        return np.array([-half, -depth, 0.0]), np.array([half, depth, top])

    @property
    def slice_depth(self) -> float:
        """The depth of the floor strip drawn under a 2D slice."""
        return self.drop / 2


@dataclass(frozen=True)
class Pose:
    eye: Vec3
    target: Vec3
    up: Vec3 = (0.0, 0.0, 1.0)
    fov: float = 40.0    # vertical field of view, degrees

    def orbited(self, degrees: float) -> "Pose":
        """The pose turned about the vertical axis through the target."""
        a = math.radians(degrees)
        ex, ey, ez = (e - t for e, t in zip(self.eye, self.target))
        x = ex * math.cos(a) - ey * math.sin(a)
        y = ex * math.sin(a) + ey * math.cos(a)
        tx, ty, tz = self.target
        return replace(self, eye=(tx + x, ty + y, tz + ez))


def spherical(target: Vec3, distance: float, azimuth: float, elevation: float,
              fov: float) -> Pose:
    """A pose looking at ``target`` from ``distance`` (azimuth from +x, elevation above the
    horizontal, in degrees)."""
    az, el = math.radians(azimuth), math.radians(elevation)
    d = (math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el))
    return Pose(tuple(float(t + distance * c) for t, c in zip(target, d)),
                tuple(float(t) for t in target), fov=fov)


def angles(pose: Pose) -> Tuple[float, float, float]:
    """(distance, azimuth, elevation) of the eye about the target; the inverse of
    ``spherical``."""
    d = np.subtract(pose.eye, pose.target)
    r = float(np.linalg.norm(d))
    return r, math.degrees(math.atan2(d[1], d[0])), math.degrees(math.asin(d[2] / r))


@dataclass
class Orbit:
    """A camera turned by dragging: ``drag`` by a fraction of the window turns it."""
    target: Vec3
    distance: float
    azimuth: float
    elevation: float
    fov: float
    turn: float = 180.0            # degrees for a drag across the whole window
    min_elevation: float = 2.0
    max_elevation: float = 85.0

    @classmethod
    def of(cls, pose: Pose) -> "Orbit":
        r, az, el = angles(pose)
        return cls(pose.target, r, az, el, pose.fov)

    def drag(self, dx: float, dy: float) -> None:
        """dx, dy: the cursor's move as a fraction of the window (y up)."""
        self.azimuth -= dx * self.turn
        self.elevation = min(self.max_elevation,
                             max(self.min_elevation, self.elevation - dy * self.turn))

    def zoom(self, factor: float) -> None:
        self.distance *= factor

    def pose(self) -> Pose:
        return spherical(self.target, self.distance, self.azimuth, self.elevation, self.fov)


def view_matrix(pose: Pose) -> np.ndarray:
    """World -> camera (column vectors), right-handed, looking down -z."""
    eye, target, up = (np.asarray(v, float) for v in (pose.eye, pose.target, pose.up))
    f = target - eye
    f /= np.linalg.norm(f)
    s = np.cross(f, up)
    s /= np.linalg.norm(s)
    u = np.cross(s, f)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def project(pose: Pose, points: np.ndarray, resolution: Tuple[int, int]) -> np.ndarray:
    """Pixel coordinates (column, row from the top) and depth of world points, shape (n, 3)."""
    w, h = resolution
    p = np.atleast_2d(np.asarray(points, float))
    cam = (view_matrix(pose) @ np.c_[p, np.ones(len(p))].T).T
    depth = -cam[:, 2]
    f = 1.0 / math.tan(math.radians(pose.fov) / 2)
    ndc_x = f * (h / w) * cam[:, 0] / depth
    ndc_y = f * cam[:, 1] / depth
    return np.c_[(ndc_x + 1) * w / 2, (1 - ndc_y) * h / 2, depth]


def pixel_radius(pose: Pose, point: Sequence[float], radius: float,
                 resolution: Tuple[int, int]) -> float:
    """The on-screen radius (pixels) of a sphere of ``radius`` at ``point``."""
    depth = project(pose, point, resolution)[0, 2]
    return radius / math.tan(math.radians(pose.fov) / 2) / depth * resolution[1] / 2


def frame(geometry: Geometry, resolution: Tuple[int, int], azimuth: float = None,
          elevation: float = None, fov: float = 35.0) -> Pose:
    """The preset's camera: aimed at the centre of the frame box, at the smallest distance
    that keeps its corners within MARGIN of the image edges."""
    lo, hi = geometry.frame_box()
    if azimuth is None:
        azimuth = -60.0 if geometry.dim == 3 else -90.0
    if elevation is None:
        elevation = 28.0 if geometry.dim == 3 else 8.0
    target = tuple((lo + hi) / 2)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                        for z in (lo[2], hi[2])])
    w, h = resolution

    def fits(d: float) -> bool:
        px = project(spherical(target, d, azimuth, elevation, fov), corners, resolution)
        return (px[:, 2] > 0).all() and (np.abs(px[:, 0] - w / 2) <= MARGIN * w / 2).all() \
            and (np.abs(px[:, 1] - h / 2) <= MARGIN * h / 2).all()

    near, far = 0.0, float(np.linalg.norm(hi - lo)) + 1e-6
    while not fits(far):
        far *= 2
    for _ in range(40):                       # bisection on the distance
        mid = (near + far) / 2
        near, far = (near, mid) if fits(mid) else (mid, far)
    return spherical(target, far, azimuth, elevation, fov)


__all__ = ["Geometry", "Pose", "Orbit", "angles", "spherical", "view_matrix", "project", "pixel_radius", "frame"]
