"""Kinematic limit checks of a sampled trajectory against the robot's limits.

Position limits come from the URDF, velocity limits from the URDF (unscaled: the
compiler plans at ``velocity_scale`` of them, the check allows the full limit), and
acceleration limits from :mod:`aou_dsl.core.robot_specs` (planned at ``accel_scale``, checked in
full). Each check reports its worst sample.

:func:`check_rates` checks what a motion generator computes from the positions it is
sent at its rate: velocity, acceleration and jerk by backward differences (the jerk
limits come from :mod:`aou_dsl.core.robot_specs`, or a controller's, see
:mod:`aou_dsl.safety.controllers`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..robot.kinematics import ArmModel

__all__ = ["Check", "check_limits", "check_rates"]

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
                 names, "against the URDF position limits")
    pos = Check(pos.name, pos.ok, pos.time, pos.joint,
                pos.value + mid[names.index(pos.joint)], pos.limit + mid[names.index(pos.joint)],
                pos.detail)
    vel = _worst("joint-velocity", t, qd, arm.vmax, names, "against the URDF velocity limits")
    acc = _worst("joint-acceleration", t, qdd, arm.amax, names,
                 "against the robot table's acceleration limits")
    return [pos, vel, acc]


def check_rates(joints: tuple[str, ...], q: np.ndarray, rate: float, *, t0: float = 0.0,
                vmax: np.ndarray | None = None, amax: np.ndarray | None = None,
                jmax: np.ndarray | None = None, source: str = "the robot table's"
                ) -> list[Check]:
    """Joint velocity, acceleration and jerk of positions commanded at ``rate`` [Hz], by
    backward differences, against the limits given (a limit left None is not checked).

    Args:
        joints: the column names.
        q: positions [rad], shape (N, n), sampled every ``1 / rate`` from ``t0`` [s]; a
            motion generator holds the arm at rest before and after, so ``q`` should
            begin and end with three copies of the rest positions (then a motion that
            starts with a jump of acceleration shows it as a jerk).
        vmax, amax, jmax: limits [rad/s, rad/s^2, rad/s^3], shape (n,).
        source: where the limits come from, for the checks' details.

    Returns:
        ``joint-rate-velocity``, ``joint-rate-acceleration`` and ``joint-jerk`` checks, for
        the limits given; the time of a difference is that of its newest sample.
    """
    checks = []
    dt = 1.0 / rate
    for order, name, limit, what in ((1, "joint-rate-velocity", vmax, "velocity"),
                                     (2, "joint-rate-acceleration", amax, "acceleration"),
                                     (3, "joint-jerk", jmax, "jerk")):
        if limit is None or len(q) <= order:
            continue
        d = np.diff(q, order, axis=0) / dt**order
        t = t0 + (np.arange(len(d)) + order) * dt
        checks.append(_worst(name, t, d, np.asarray(limit, dtype=float), joints,
                             f"{what} from differences at {rate:g} Hz, against {source} "
                             "limits"))
    return checks
