"""The camera's world: a table, a target cube with a fiducial tag on one face, box
occluders, a pinhole camera and the light; and its geometry (where the tag's corners are,
what the camera sees of them, how fast they move in the image).

Both perceptions that ship read a :class:`Scene`: the rendered camera (:mod:`.camera`)
draws it, the geometric model (:mod:`.geometric`) reasons about it. Positions are in the
world frame [m] (the table's top at z = 0); angles in radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..core.memo import cached

__all__ = ["CUBE", "HEIGHT", "TAG_CELLS", "WIDTH", "Box", "Scene", "focal_px", "shake_px",
           "tag_points", "visible_fraction"]

#: The image [px].
WIDTH, HEIGHT = 320, 240
#: The target cube's side [m]; the tag image covers its face.
CUBE = 0.08
#: The tag image is a grid of this many cells a side (a white border, a black border,
#: 6 x 6 data cells); the black square is 8 of them.
TAG_CELLS = 10


@dataclass(frozen=True)
class Box:
    """An axis-aligned box: its centre and half its size along x, y, z [m]."""

    center: tuple[float, float, float]
    half: tuple[float, float, float]
    name: str = ""


@dataclass(frozen=True)
class Scene:
    """What the camera looks at, at one instant.

    Attributes:
        target: the target cube's centre [m].
        target_yaw: the tagged face looks along (cos, sin, 0) of this angle [rad].
        camera: the camera's position [m]; look_at: where it points (default: the target).
        light: the scene's brightness, 1 a well-lit lab, 0 dark.
        occluders: boxes between the camera and the target, or not.
        target_velocity, camera_velocity: [m/s], for motion blur.
        exposure: the camera's exposure [s]; fov: its vertical field of view [deg].
    """

    target: tuple[float, float, float] = (0.6, 0.0, CUBE / 2)
    target_yaw: float = math.pi
    camera: tuple[float, float, float] = (0.2, 0.0, 0.15)
    look_at: tuple[float, float, float] | None = None
    light: float = 1.0
    occluders: tuple[Box, ...] = ()
    target_velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    camera_velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    exposure: float = 0.02
    fov: float = 60.0
    noise: float = field(default=3.0)  # sensor noise [grey levels], at any light

    @property
    def aim(self) -> tuple[float, float, float]:
        return self.look_at if self.look_at is not None else self.target


def focal_px(scene: Scene) -> float:
    """The pinhole camera's focal length [px]."""
    return (HEIGHT / 2.0) / math.tan(math.radians(scene.fov) / 2.0)


def camera_axes(scene: Scene) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The camera's forward, right and up unit vectors (up as close to +z as it can be)."""
    fwd = np.subtract(scene.aim, scene.camera).astype(float)
    fwd /= max(np.linalg.norm(fwd), 1e-12)
    right = np.cross(fwd, (0.0, 0.0, 1.0))
    if np.linalg.norm(right) < 1e-9:
        right = np.array([0.0, -1.0, 0.0])
    right /= np.linalg.norm(right)
    return fwd, right, np.cross(right, fwd)


def face_frame(scene: Scene) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The tagged face: its centre, outward normal, and its in-plane right and up axes
    (as seen from in front of it) [m]."""
    c, s = math.cos(scene.target_yaw), math.sin(scene.target_yaw)
    normal = np.array([c, s, 0.0])
    centre = np.asarray(scene.target, float) + normal * (CUBE / 2.0)
    right = np.array([s, -c, 0.0])
    return centre, normal, right, np.array([0.0, 0.0, 1.0])


def tag_points(scene: Scene, cells: int = 0) -> np.ndarray:
    """Points of the tag image on the face (its white quiet border included: a detector
    needs it) [m]: its four corners, then (``cells`` > 0) the centres of a ``cells`` x
    ``cells`` grid over it."""
    centre, _, right, up = face_frame(scene)
    uv = _grid(cells) * (CUBE / 2.0)
    return centre + uv[:, :1] * right + uv[:, 1:] * up


@cached(maxsize=4)
def _grid(cells: int) -> np.ndarray:
    """The tag's corners and grid centres in face coordinates, in [-1, 1]."""
    uv = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
    g = (np.arange(cells) + 0.5) / max(cells, 1) * 2.0 - 1.0
    uv += [(float(a), float(b)) for b in g for a in g]
    return np.array(uv)


def segments_hit_box(p0: np.ndarray, p1: np.ndarray, box: Box) -> np.ndarray:
    """Which of the segments from ``p0`` (3,) to each row of ``p1`` (K, 3) cross ``box``
    (slab tests, all segments at once)."""
    d = p1 - p0
    lo_b = np.asarray(box.center) - np.asarray(box.half)
    hi_b = np.asarray(box.center) + np.asarray(box.half)
    flat = np.abs(d) < 1e-15
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (lo_b - p0) / d, (hi_b - p0) / d
    near = np.where(flat, -np.inf, np.minimum(t1, t2))
    far = np.where(flat, np.inf, np.maximum(t1, t2))
    outside = flat & ((p0 < lo_b) | (p0 > hi_b))
    lo = np.maximum(near.max(axis=1), 0.0)
    hi = np.minimum(far.min(axis=1), 1.0)
    return (lo <= hi) & ~outside.any(axis=1)


def visible_fraction(scene: Scene, points: np.ndarray) -> float:
    """The fraction of ``points`` the camera sees: in its field of view, on the side of
    the face the camera is on, and not behind an occluder."""
    cam = np.asarray(scene.camera, float)
    _, normal, _, _ = face_frame(scene)
    if float(np.dot(cam - points[0], normal)) <= 0.0:
        return 0.0
    px = project(scene, points)
    with np.errstate(invalid="ignore"):
        seen = ((px[:, 0] >= 0) & (px[:, 0] < WIDTH) & (px[:, 1] >= 0)
                & (px[:, 1] < HEIGHT))
    for b in scene.occluders:
        seen &= ~segments_hit_box(cam, points, b)
    return float(seen.mean())


def project(scene: Scene, points: np.ndarray) -> np.ndarray:
    """Pixel coordinates (column, row) of world points; nan behind the camera."""
    fwd, right, up = camera_axes(scene)
    rel = np.atleast_2d(points) - np.asarray(scene.camera, float)
    z = rel @ fwd
    f = focal_px(scene)
    with np.errstate(divide="ignore", invalid="ignore"):
        u = WIDTH / 2.0 + f * (rel @ right) / z
        v = HEIGHT / 2.0 - f * (rel @ up) / z
    bad = z <= 1e-6
    u[bad] = v[bad] = np.nan
    return np.stack([u, v], axis=1)


def viewing(scene: Scene) -> tuple[float, float]:
    """The camera's distance to the tag [m] and the viewing angle off the tag's normal
    [rad]."""
    centre, normal, _, _ = face_frame(scene)
    rel = np.asarray(scene.camera, float) - centre
    d = float(np.linalg.norm(rel))
    return d, math.acos(max(-1.0, min(1.0, float(rel @ normal) / max(d, 1e-12))))


def tag_size_px(scene: Scene) -> float:
    """The tag's expected size in the image [px]: its narrower side (pinhole camera:
    side x focal / distance, foreshortened by the viewing angle's cosine), which is what
    a detector must resolve its cells across."""
    d, angle = viewing(scene)
    side = CUBE * (TAG_CELLS - 2) / TAG_CELLS
    return side * focal_px(scene) / max(d, 1e-9) * max(0.0, math.cos(angle))


def blur_px(scene: Scene) -> float:
    """How far the tag moves in the image during one exposure [px]: its speed relative
    to the camera, across the line of sight, times the exposure, over the distance."""
    centre, _, _, _ = face_frame(scene)
    rel = centre - np.asarray(scene.camera, float)
    d = float(np.linalg.norm(rel))
    v = np.subtract(scene.target_velocity, scene.camera_velocity)
    along = rel / max(d, 1e-12)
    across = v - (v @ along) * along
    return float(np.linalg.norm(across)) * scene.exposure * focal_px(scene) / max(d, 1e-9)


def shake_px(scene: Scene) -> float:
    """How far the whole image moves during one exposure [px]: the camera's speed across
    its line of sight times the exposure, over the distance to what it looks at."""
    rel = np.subtract(scene.aim, scene.camera)
    d = float(np.linalg.norm(rel))
    v = np.asarray(scene.camera_velocity, float)
    along = rel / max(d, 1e-12)
    across = v - (v @ along) * along
    return float(np.linalg.norm(across)) * scene.exposure * focal_px(scene) / max(d, 1e-9)


def blur_direction(scene: Scene) -> float:
    """The direction of the tag's motion in the image [rad from the image's x axis]."""
    _, right, up = camera_axes(scene)
    v = np.subtract(scene.target_velocity, scene.camera_velocity)
    return math.atan2(-float(v @ up), float(v @ right))


def shake_direction(scene: Scene) -> float:
    """The direction the whole image moves with the camera [rad from the image's x axis]."""
    _, right, up = camera_axes(scene)
    v = -np.asarray(scene.camera_velocity, float)
    return math.atan2(-float(v @ up), float(v @ right))
