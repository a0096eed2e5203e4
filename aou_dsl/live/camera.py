"""A rendered camera with a real fiducial detector: PyBullet's CPU renderer draws the
scene (:class:`~.world.Scene`: a table, the target cube with an AprilTag 36h11 on its face,
box occluders; no arm), the image is dimmed, blurred and made noisy as a sensor would, and
``pupil-apriltags`` looks for the tag.

Its confidence fuses (docs/live.md):

- the tag's quality in each frame: 0 when it is not detected, else its decision margin
  (normalised by :data:`MARGIN_REF`) times its size in pixels (by :data:`SIZE_REF`),
  averaged over the frames of a sliding window of the last ``WINDOW_S`` seconds
  (detection over the window);
- the image's quality: sharpness (variance of the Laplacian, by :data:`SHARP_REF`) times
  brightness (mean grey level, by :data:`BRIGHT_REF`), each capped at 1.

``confidence = TAG_WEIGHT * tag + (1 - TAG_WEIGHT) * image``: a lit, sharp view of a
hidden tag is half sure (the target was there a moment ago and the camera sees well), a
dark one is not sure of anything. Needs the ``perception`` extra (pupil-apriltags).
"""

from __future__ import annotations

import math
import os
import struct
import tempfile
import zlib
from collections import deque
from dataclasses import dataclass
from typing import Any

import numpy as np

from .geometric import BRIGHT_REF, SHARP_REF, TAG_WEIGHT, WINDOW_S
from .perception import Estimate, Evidence
from .world import (
    CUBE,
    HEIGHT,
    TAG_CELLS,
    WIDTH,
    Scene,
    blur_direction,
    blur_px,
    face_frame,
    project,
    shake_direction,
    shake_px,
)

__all__ = ["BRIGHT_REF", "CAMERA_RATE", "MARGIN_REF", "SHARP_REF", "SIZE_REF", "TAG_CODE",
           "TAG_WEIGHT", "Camera", "Frame", "fuse", "tag_image"]

#: tag36h11 id 0, its 36 bits most significant first.
TAG_CODE = 0xD7E00984B
#: The first quadrant of the data square, 1-based (x, y); the others turn it a quarter.
_QUADRANT = ((1, 1), (2, 1), (3, 1), (4, 1), (5, 1), (2, 2), (3, 2), (4, 2), (3, 3))
#: A decision margin this high, a tag this many pixels wide, an image this sharp
#: (variance of the Laplacian) and this bright (mean grey level) count as fully sure.
#: (The image's references and the tag's share of the confidence are the geometric
#: model's, so that both fuse alike.)
MARGIN_REF, SIZE_REF = 80.0, 24.0
#: How often a loop asks the rendered camera [Hz] (it renders and detects at 30 Hz or
#: more on one core; the loop keeps its last answer between two).
CAMERA_RATE = 20.0


def tag_image(cell: int = 8) -> np.ndarray:
    """The tag36h11 id 0 image, ``cell`` pixels a cell (uint8, white 255)."""
    g = np.full((TAG_CELLS, TAG_CELLS), 255, np.uint8)
    g[1:-1, 1:-1] = 0
    quads = [list(_QUADRANT)]
    for _ in range(3):
        quads.append([(7 - y, x) for x, y in quads[-1]])
    for i, (x, y) in enumerate(p for q in quads for p in q):
        if TAG_CODE >> (35 - i) & 1:
            g[1 + y, 1 + x] = 255
    return np.kron(g, np.ones((cell, cell), np.uint8))


@dataclass(frozen=True)
class Frame:
    """What one frame gave: the grey image, whether the tag was found, its decision
    margin, its size [px], the image's sharpness and brightness, and the tag's centre in
    the image [px]."""

    image: np.ndarray
    detected: bool
    margin: float
    size_px: float
    sharpness: float
    brightness: float
    centre: tuple[float, float] | None


def fuse(tag: float, sharpness: float, brightness: float) -> float:
    """The confidence from the tag's quality over the window and the image's sharpness
    and brightness (the module's docstring)."""
    image = min(1.0, sharpness / SHARP_REF) * min(1.0, brightness / BRIGHT_REF)
    return min(1.0, max(0.0, TAG_WEIGHT * tag + (1.0 - TAG_WEIGHT) * image))


def tag_quality(frame: Frame) -> float:
    """One frame's tag quality: margin and size, each normalised and capped at 1."""
    if not frame.detected:
        return 0.0
    return min(1.0, frame.margin / MARGIN_REF) * min(1.0, frame.size_px / SIZE_REF)


def _free(det: Any) -> None:
    """Free a detector before its tag families: the detector's own teardown reads
    each family's decode table, so freeing a family first (as pupil-apriltags'
    ``__del__`` does) is a use after free that crashes the process some of the time."""
    ptr, det.tag_detector_ptr = det.tag_detector_ptr, None
    if ptr is None:
        return
    det.libc.apriltag_detector_destroy.restype = None
    det.libc.apriltag_detector_destroy(ptr)
    for family, handle in det.tag_families.items():
        destroy = getattr(det.libc, f"{family}_destroy")
        destroy.restype = None
        destroy(handle)
    det.tag_families = {}


def detector() -> Any:
    """A 36h11 tag detector that frees its memory in the safe order."""
    from pupil_apriltags import Detector

    class _Detector(Detector):
        def __del__(self) -> None:
            _free(self)

    return _Detector(families="tag36h11", nthreads=1, quad_decimate=1.0)


class Camera:
    """A rendered camera on a :class:`Scene` (a callable giving the scene at ``t``, or
    one scene); ``seed`` makes its sensor noise repeatable. :meth:`perceive` is a
    :class:`~.perception.Perception`; :meth:`frame` renders and detects once."""

    def __init__(self, scene: Any, *, seed: int = 0, window: float = WINDOW_S):
        import pybullet as p

        self._scene = scene if callable(scene) else (lambda t: scene)
        self.rng = np.random.default_rng(seed)
        self.detector = detector()
        self.p = p
        self.client = p.connect(p.DIRECT)
        self.window_s = window
        self._seen: deque[tuple[float, float]] = deque()
        self._boxes: dict[tuple, int] = {}
        self._build()

    def close(self) -> None:
        if self.client >= 0:
            self.p.disconnect(physicsClientId=self.client)
            self.client = -1

    def __del__(self) -> None:  # a camera dropped without close() frees its client
        try:
            self.close()
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass

    def _build(self) -> None:
        p, c = self.p, self.client
        table = p.createVisualShape(p.GEOM_BOX, halfExtents=[0.6, 0.6, 0.02],
                                    rgbaColor=[0.55, 0.45, 0.35, 1], physicsClientId=c)
        p.createMultiBody(0, -1, table, basePosition=[0.5, 0, -0.02], physicsClientId=c)
        cube = p.createVisualShape(p.GEOM_BOX, halfExtents=[CUBE / 2] * 3,
                                   rgbaColor=[0.75, 0.75, 0.75, 1], physicsClientId=c)
        self.cube = p.createMultiBody(0, -1, cube, physicsClientId=c)
        h = CUBE / 2
        quad = [[0, -h, -h], [0, h, -h], [0, h, h], [0, -h, h]]
        shape = p.createVisualShape(p.GEOM_MESH, vertices=quad, indices=[0, 1, 2, 0, 2, 3],
                                    uvs=[[1, 1], [0, 1], [0, 0], [1, 0]],
                                    normals=[[1, 0, 0]] * 4, physicsClientId=c)
        self.tag = p.createMultiBody(0, -1, shape, physicsClientId=c)
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "tag.png")
            with open(path, "wb") as f:
                f.write(png_grey(tag_image()))
            tex = p.loadTexture(path, physicsClientId=c)
        p.changeVisualShape(self.tag, -1, textureUniqueId=tex, rgbaColor=[1, 1, 1, 1],
                            physicsClientId=c)

    def _place(self, scene: Scene) -> None:
        p, c = self.p, self.client
        orn = p.getQuaternionFromEuler([0, 0, scene.target_yaw])
        p.resetBasePositionAndOrientation(self.cube, scene.target, orn, physicsClientId=c)
        centre, normal, _, _ = face_frame(scene)
        p.resetBasePositionAndOrientation(self.tag, (centre + normal * 5e-4).tolist(), orn,
                                          physicsClientId=c)
        seen = set()
        for box in scene.occluders:
            key = (box.name, tuple(box.half))
            seen.add(key)
            if key not in self._boxes:
                shape = p.createVisualShape(p.GEOM_BOX, halfExtents=list(box.half),
                                            rgbaColor=[0.2, 0.3, 0.5, 1], physicsClientId=c)
                self._boxes[key] = p.createMultiBody(0, -1, shape, physicsClientId=c)
            p.resetBasePositionAndOrientation(self._boxes[key], box.center, [0, 0, 0, 1],
                                              physicsClientId=c)
        for key, body in self._boxes.items():
            if key not in seen:  # parked far away
                p.resetBasePositionAndOrientation(body, [0, 0, -50], [0, 0, 0, 1],
                                                  physicsClientId=c)

    def render(self, scene: Scene) -> np.ndarray:
        """The grey image (float, 0..255) of the scene as the sensor gives it: rendered,
        scaled by the light, blurred by the motion during the exposure, with noise."""
        p, c = self.p, self.client
        self._place(scene)
        view = p.computeViewMatrix(scene.camera, scene.aim, [0, 0, 1], physicsClientId=c)
        proj = p.computeProjectionMatrixFOV(scene.fov, WIDTH / HEIGHT, 0.02, 10.0,
                                            physicsClientId=c)
        _, _, rgb, _, _ = p.getCameraImage(WIDTH, HEIGHT, view, proj, shadow=0,
                                           renderer=p.ER_TINY_RENDERER, physicsClientId=c)
        img = np.asarray(rgb, np.uint8).reshape(HEIGHT, WIDTH, 4)[:, :, :3]
        grey = img.astype(float) @ np.array([0.299, 0.587, 0.114]) * max(0.0, scene.light)
        # the camera's own motion smears everything; the target's, only the target
        still = motion_blur(grey, shake_px(scene), shake_direction(scene))
        moving = motion_blur(grey, blur_px(scene), blur_direction(scene))
        if moving is not grey:
            box = _cube_box(scene, blur_px(scene))
            if box is not None:
                r0, r1, c0, c1 = box
                still[r0:r1, c0:c1] = moving[r0:r1, c0:c1]
        grey = still + self.rng.normal(0.0, scene.noise, grey.shape)
        return np.clip(grey, 0.0, 255.0)

    def frame(self, scene: Scene) -> Frame:
        """Render ``scene`` and look for the tag."""
        grey = self.render(scene)
        found = [d for d in self.detector.detect(grey.astype(np.uint8)) if d.tag_id == 0]
        sharp, bright = sharpness(grey), float(grey.mean())
        if not found:
            return Frame(grey, False, 0.0, 0.0, sharp, bright, None)
        d = max(found, key=lambda d: d.decision_margin)
        x, y = d.corners[:, 0], d.corners[:, 1]
        area = 0.5 * abs(float(np.dot(x, np.roll(y, 1)) - np.dot(y, np.roll(x, 1))))
        return Frame(grey, True, float(d.decision_margin), math.sqrt(area), sharp, bright,
                     (float(d.center[0]), float(d.center[1])))

    def perceive(self, t: float) -> Estimate:
        """Render the scene at ``t``, detect, and fuse (the module's docstring)."""
        scene = self._scene(t)
        fr = self.frame(scene)
        self.last = fr
        self._seen.append((t, tag_quality(fr)))
        while self._seen and self._seen[0][0] <= t - self.window_s:
            self._seen.popleft()
        tag = sum(q for _, q in self._seen) / len(self._seen)
        conf = fuse(tag, fr.sharpness, fr.brightness)
        ev = Evidence("camera", (("detected", float(fr.detected)), ("margin", fr.margin),
                                 ("size_px", fr.size_px), ("sharpness", fr.sharpness),
                                 ("brightness", fr.brightness),
                                 ("tag", tag)))
        return Estimate(conf, scene.target if fr.detected else None, ev)


def _cube_box(scene: Scene, margin: float) -> tuple[int, int, int, int] | None:
    """Rows and columns of the image the target cube covers, ``margin`` pixels wider."""
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
    px = project(scene, np.asarray(scene.target) + corners * (CUBE / 2.0) * 1.5)
    if not np.all(np.isfinite(px)):
        return None
    m = int(math.ceil(margin)) + 1
    c0, r0 = np.floor(px.min(axis=0)).astype(int) - m
    c1, r1 = np.ceil(px.max(axis=0)).astype(int) + m
    r0, c0 = max(0, int(r0)), max(0, int(c0))
    r1, c1 = min(HEIGHT, int(r1)), min(WIDTH, int(c1))
    return (r0, r1, c0, c1) if r1 > r0 and c1 > c0 else None


def png_grey(img: np.ndarray) -> bytes:
    """The grey image ``img`` (uint8) as an RGB PNG: the renderer loads textures from
    files and draws them with three channels (with a one-channel file, ``aouc live
    --render`` died at exit with a corrupted heap about one run in two)."""
    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    h, w = img.shape
    rgb = np.repeat(np.ascontiguousarray(img, np.uint8)[:, :, None], 3, axis=2)
    raw = b"".join(b"\x00" + rgb[r].tobytes() for r in range(h))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def sharpness(grey: np.ndarray) -> float:
    """The variance of the Laplacian (4-neighbour) of the image averaged over 2 x 2
    pixels (which quarters the sensor noise's share)."""
    h, w = grey.shape[0] // 2 * 2, grey.shape[1] // 2 * 2
    grey = grey[:h:2, :w:2] + grey[1:h:2, :w:2] + grey[:h:2, 1:w:2] + grey[1:h:2, 1:w:2]
    grey = grey / 4.0
    lap = (-4.0 * grey[1:-1, 1:-1] + grey[:-2, 1:-1] + grey[2:, 1:-1] + grey[1:-1, :-2]
           + grey[1:-1, 2:])
    return float(lap.var())


def motion_blur(grey: np.ndarray, length: float, angle: float) -> np.ndarray:
    """``grey`` smeared along a line ``length`` pixels long at ``angle`` [rad]: the mean
    of the image shifted to points along the line (a box kernel)."""
    if length < 0.5:
        return grey
    n = max(2, int(math.ceil(length)) + 1)
    out = np.zeros_like(grey)
    for s in np.linspace(-length / 2, length / 2, n):
        dx, dy = int(round(s * math.cos(angle))), int(round(-s * math.sin(angle)))
        out += np.roll(grey, (dy, dx), axis=(0, 1))
    return out / n
