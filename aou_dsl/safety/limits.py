"""Kinematic limit checks of a sampled trajectory against the robot's limits.

Position limits come from the URDF, velocity limits from the URDF (unscaled: the
compiler plans at ``velocity_scale`` of them, the check allows the full limit), and
acceleration limits from :mod:`aou_dsl.robots` (planned at ``accel_scale``, checked in
full). Each check reports its worst sample.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..kinematics import ArmModel

__all__ = ["Check", "check_limits"]

#: Relative slack on velocity and acceleration limits (numerical differentiation).
SLACK = 1e-3


@dataclass(frozen=True)
class Check:
    """One check's verdict and its worst sample (time [s], joint, value, limit)."""

    name: str
    ok: bool
    time: float | None = None
    joint: str | None = None
    value: float | None = None
    limit: float | None = None
    detail: str = ""

    def to_json(self) -> dict:
        return {"name": self.name, "ok": self.ok, "time": self.time, "joint": self.joint,
                "value": self.value, "limit": self.limit, "detail": self.detail}


def _worst(name: str, t: np.ndarray, value: np.ndarray, limit: np.ndarray,
           joints: tuple[str, ...], detail: str) -> Check:
    """The sample where ``|value|`` comes nearest (or furthest past) ``|limit|``;
    ``value`` (N, n), ``limit`` broadcastable to it."""
    limit = np.broadcast_to(limit, value.shape)
    ratio = np.abs(value) / np.abs(limit)
    i, j = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
    return Check(name, bool(ratio[i, j] <= 1.0 + SLACK), float(t[i]), joints[j],
                 float(value[i, j]), float(limit[i, j]), detail)


def check_limits(arm: ArmModel, t: np.ndarray, q: np.ndarray, qd: np.ndarray,
                 qdd: np.ndarray) -> list[Check]:
    """Joint position, velocity and acceleration limits at every sample.

    Shapes: ``t`` (N,), ``q``, ``qd``, ``qdd`` (N, n) in the arm's joint order. Position
    is checked as the distance from the middle of the range against the half range.
    """
    names = arm.joint_names
    mid = (arm.upper + arm.lower) / 2.0
    pos = _worst("joint-position", t, q - mid, np.where(q >= mid, arm.upper, arm.lower) - mid,
                 names, "within the URDF position limits")
    pos = Check(pos.name, pos.ok, pos.time, pos.joint,
                pos.value + mid[names.index(pos.joint)], pos.limit + mid[names.index(pos.joint)],
                pos.detail)
    vel = _worst("joint-velocity", t, qd, arm.vmax, names, "within the URDF velocity limits")
    acc = _worst("joint-acceleration", t, qdd, arm.amax, names,
                 "within the robot table's acceleration limits")
    return [pos, vel, acc]
