"""Stage 4, geometry: poses of the reach -> end-effector targets in SE(3), gaze locked.

The start frame ``R0 = [x0, y0, z0]`` (docs/model.md, "Frames"):

- ``z0`` points from the start pose to the goal (the gaze axis);
- ``y0`` is the world's up direction made perpendicular to ``z0``, so the plane with
  normal ``y0`` (the model's horizontal plane) is horizontal in the world and a
  horizontal gaze looks left and right; if ``z0`` is vertical, the world x axis is used;
- ``x0 = y0 x z0``.

A pose ``(d, h, v, roll)`` gives the goal vector ``g`` the plane angles of the model:
projected into the horizontal plane (normal ``y0``) it is ``h`` from the initial line of
sight, projected into the vertical plane (normal ``x0``) it is ``v``, so in the start
frame ``g ~ (tan h, -tan v, 1)``. The end-effector sits at ``goal - d g/|g|``, oriented
``B R0 Rz(roll)`` where ``B = Rot(x0, b) Rot(y0, a)`` turns ``z0`` onto ``g``: its z axis
points at the goal whatever the pose, so the line of sight is zero by construction.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from ..lang.timeline import Pose

__all__ = ["ReachFrame", "axis_angle", "reach_frame", "rotation_angles"]


def axis_angle(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation matrix about a unit ``axis`` by ``angle`` [rad] (Rodrigues), shape (3, 3)."""
    x, y, z = axis
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return _EYE3 + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)


_EYE3 = np.eye(3)
_EYE3.setflags(write=False)
_Z = np.array([0.0, 0.0, 1.0])
_Z.setflags(write=False)


@dataclass(frozen=True)
class ReachFrame:
    """The goal and the start frame of a reach.

    Attributes:
        goal: goal position in the base frame [m], shape (3,).
        R0: end-effector orientation at the start, columns x0, y0, z0; shape (3, 3).
    """

    goal: np.ndarray
    R0: np.ndarray

    def target(self, pose: Pose) -> tuple[np.ndarray, np.ndarray]:
        """Position (3,) and rotation (3, 3) of the end-effector at ``pose``."""
        back, r = self._turn(pose.h, pose.v, pose.roll)
        return self.goal + pose.d * back, r

    def targets(self, start: Pose, end: Pose, fractions: Iterable[float]
                ) -> list[tuple[np.ndarray, np.ndarray]]:
        """``[target(start.lerp(end, f)) for f in fractions]``, the same numbers to the
        bit; the rotation is computed once per distinct angles (bit for bit: a signed
        zero is another angle), so a path that keeps its gaze and roll (an approach, a
        retreat) turns once, and its positions are computed at once. The rotations and
        positions are shared and read-only."""
        f = np.fromiter(fractions, dtype=float)
        # Pose.lerp's arithmetic for every fraction at once (elementwise: the same bits).
        d, h, v, roll = (a + f * (b - a) for a, b in ((start.d, end.d), (start.h, end.h),
                                                       (start.v, end.v),
                                                       (start.roll, end.roll)))
        angles = np.stack([h, v, roll], axis=1)
        if len(f) and (angles.view(np.uint64) == angles[:1].view(np.uint64)).all():
            back, r = self._turn(*angles[0].tolist())
            r.setflags(write=False)
            pos = self.goal + d[:, None] * back
            pos.setflags(write=False)
            return [(p, r) for p in pos]
        out = []
        turns: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}
        for dk, (hk, vk, rk) in zip(d.tolist(), angles.tolist(), strict=True):
            key = struct.pack("3d", hk, vk, rk)
            turn = turns.get(key)
            if turn is None:
                turn = turns[key] = self._turn(hk, vk, rk)
                turn[1].setflags(write=False)
            out.append((self.goal + dk * turn[0], turn[1]))
        return out

    def _turn(self, h: float, v: float, roll: float) -> tuple[np.ndarray, np.ndarray]:
        """The unit vector from the goal back to the end-effector, and the end-effector's
        rotation, at the angles of a pose."""
        x0, y0, z0 = self.R0.T
        a, c = rotation_angles(h, v)
        b = axis_angle(x0, c) @ axis_angle(y0, a)
        return b @ -z0, b @ self.R0 @ axis_angle(_Z, roll)


def rotation_angles(h: float, v: float) -> tuple[float, float]:
    """The rotations ``(a, b)`` about ``y0`` then ``x0`` [rad] whose goal vector has the
    plane angles ``h`` (horizontal) and ``v`` (vertical), each within +-90 deg.

    ``Rot(x0, b) Rot(y0, a)`` takes the line of sight to ``(sin a, -cos a sin b,
    cos a cos b)`` in the start frame; it must be parallel to ``(tan h, -tan v, 1)``.
    """
    gx, gy, gz = math.tan(h), -math.tan(v), 1.0
    n = math.sqrt(gx * gx + gy * gy + gz * gz)
    a = math.asin(gx / n)
    return a, math.atan2(-gy, gz)


def reach_frame(goal: tuple[float, float, float], start_direction: tuple[float, float, float]
                ) -> ReachFrame:
    """The reach frame for a goal and a unit direction from the goal toward the start."""
    u = np.asarray(start_direction, dtype=float)
    u = u / np.linalg.norm(u)
    z0 = -u
    up = np.array([0.0, 0.0, 1.0])
    if abs(up @ z0) > 0.99:
        up = np.array([1.0, 0.0, 0.0])
    y0 = up - (up @ z0) * z0
    y0 /= np.linalg.norm(y0)
    x0 = np.cross(y0, z0)
    return ReachFrame(np.asarray(goal, dtype=float), np.column_stack([x0, y0, z0]))
