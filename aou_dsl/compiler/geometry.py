"""Stage 4, geometry: poses of the reach -> end-effector targets in SE(3), gaze locked.

The start frame ``R0 = [x0, y0, z0]`` (MODEL.md s4):

- ``z0`` points from the start pose to the goal (the gaze axis);
- ``y0`` is the world's up direction made perpendicular to ``z0``, so the plane with
  normal ``y0`` (MODEL.md's horizontal plane) is horizontal in the world and a
  horizontal gaze looks left and right; if ``z0`` is vertical, the world x axis is used;
- ``x0 = y0 x z0``.

A pose ``(d, h, v, roll)`` puts the end-effector at ``goal + d B u`` with ``u = -z0``
and ``B = Rot(x0, v) Rot(y0, h)``, oriented ``B R0 Rz(roll)``: its z axis points at the
goal whatever the pose, so the line of sight is zero by construction.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .layout import Pose

__all__ = ["ReachFrame", "axis_angle", "reach_frame"]


def axis_angle(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation matrix about a unit ``axis`` by ``angle`` [rad] (Rodrigues), shape (3, 3)."""
    x, y, z = axis
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)


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
        x0, y0, z0 = self.R0.T
        b = axis_angle(x0, pose.v) @ axis_angle(y0, pose.h)
        p = self.goal + pose.d * (b @ -z0)
        r = b @ self.R0 @ axis_angle(np.array([0.0, 0.0, 1.0]), pose.roll)
        return p, r


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
