"""Kinematic limit checks of a sampled trajectory against the robot's limits.

Position limits come from the URDF, velocity limits from the URDF (unscaled: the
compiler plans at ``velocity_scale`` of them, the check allows the full limit), and
acceleration limits from :mod:`aou_dsl.core.robot_specs` (planned at ``accel_scale``, checked in
full). Each check reports its worst sample.

A recording carries encoder noise, which differences turn into velocities and
accelerations far beyond any limit (1e-4 rad at 1 kHz is about 100 rad/s^2). Its limits
are judged on the filtered signal (:func:`filtered`): the noise estimated as
``aouc measure`` estimates it, the velocity through the measurement's own filter, the
acceleration through a Savitzky-Golay filter just long enough that its noise stays
under 2 % of the smallest acceleration limit. Noise alone then never reaches a limit,
while a violation that lasts as long as the filter still does.

:func:`check_rates` checks what a motion generator computes from the positions it is
sent at its rate: velocity, acceleration and jerk by backward differences (the jerk
limits come from :mod:`aou_dsl.core.robot_specs`, or a controller's, see
:mod:`aou_dsl.safety.controllers`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..robot.kinematics import ArmModel

__all__ = ["Check", "Filtered", "check_limits", "check_rates", "filtered"]

#: Relative slack on velocity and acceleration limits (numerical differentiation).
SLACK = 1e-3
#: The acceleration filter's noise (NOISE_SIGMAS of its std) stays under this fraction
#: of the smallest acceleration limit.
ACCEL_RESOLUTION = 0.02
#: Longest acceleration filter [s].
MAX_ACCEL_WINDOW = 0.25


@dataclass(frozen=True)
class Filtered:
    """A noisy recording's joint signals on one clock, filtered as its limits are judged.

    Attributes:
        t: times [s], (N,); q, qd, qdd: positions, filtered velocities and
            accelerations, (N, n).
        noise: the largest joint noise [rad].
        velocity_window, accel_window: the filters' spans [s].
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    noise: float
    velocity_window: float
    accel_window: float

    @property
    def note(self) -> str:
        return (f"on the filtered signal (noise {self.noise:.2g} rad; velocity over "
                f"{self.velocity_window * 1e3:.0f} ms, acceleration over "
                f"{self.accel_window * 1e3:.0f} ms)")


def filtered(t: np.ndarray, q: np.ndarray, amax: np.ndarray) -> Filtered | None:
    """The joint signals as a noisy recording's limits are judged; None for a
    trajectory without noise (compiled, or computed by a planner), whose own
    derivatives are judged. ``amax``: the acceleration limits [rad/s^2], (n,)."""
    from ..measuring.episodes import COMPUTED_NOISE
    from ..measuring.signal import (
        NOISE_SIGMAS,
        curvature_gain,
        joint_noise,
        odd,
        short_window,
        smooth,
        to_grid,
    )
    from ..measuring.staircase import dequantised

    if len(t) < 8:
        return None
    jn = joint_noise(t, q)
    noise = jn.effective
    sigma = float(noise.max(initial=0.0))
    if sigma <= COMPUTED_NOISE:
        return None
    q = dequantised(t, q, jn)  # a coarse encoder's staircase, as measure reads it
    h = float(np.median(np.diff(t)))
    wv = short_window(sigma, h)
    grid = to_grid(t, q, wv * h)
    longest = odd(MAX_ACCEL_WINDOW / grid.h, 5)
    resolution = ACCEL_RESOLUTION * float(np.min(amax))
    wa = 5
    while wa < longest and NOISE_SIGMAS * sigma * curvature_gain(wa, grid.h) > resolution:
        wa += 2
    qd = smooth(grid.q, wv, 1, grid.h, order=2)
    qdd = smooth(grid.q, wa, 2, grid.h, order=3)
    return Filtered(grid.t + t[0], grid.q, qd, qdd, sigma, wv * grid.h, wa * grid.h)


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


def _worst(name: str, t: np.ndarray | Callable[[int], float], value: np.ndarray,
           limit: np.ndarray, joints: tuple[str, ...], detail: str) -> Check:
    """The sample where ``|value|`` comes nearest (or furthest past) ``|limit|``;
    ``value`` (N, n), ``limit`` broadcastable to it (one per joint: its absolute value
    is taken once, not at every sample; the quotients are the same). The sample's time is
    ``t[i]``, or ``t(i)`` (a clock of equal steps, whose times need not be made)."""
    ratio = np.abs(value)
    ratio /= np.abs(limit)
    i, j = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
    at = float(t(int(i))) if callable(t) else float(t[i])
    return Check(name, bool(ratio[i, j] <= 1.0 + SLACK), at, joints[j],
                 float(value[i, j]), float(np.broadcast_to(limit, ratio.shape)[i, j]), detail)


def check_limits(arm: ArmModel, t: np.ndarray, q: np.ndarray, qd: np.ndarray,
                 qdd: np.ndarray) -> list[Check]:
    """Joint position, velocity and acceleration limits at every sample.

    Shapes: ``t`` (N,), ``q``, ``qd``, ``qdd`` (N, n) in the arm's joint order. Position
    is checked as the distance from the middle of the range against the half range.
    A trajectory whose positions carry noise (a recording) is judged on its filtered
    signal instead (:func:`filtered`; ``qd`` and ``qdd`` are then not used), and each
    check's detail says so.
    """
    names = arm.joint_names
    judged = filtered(np.asarray(t, float), np.asarray(q, float), arm.amax)
    note = ""
    if judged is not None:
        t, q, qd, qdd = judged.t, judged.q, judged.qd, judged.qdd
        note = " " + judged.note
    mid = (arm.upper + arm.lower) / 2.0
    pos = _worst("joint-position", t, q - mid,
                 np.where(q >= mid, arm.upper - mid, arm.lower - mid),
                 names, "against the URDF position limits" + note)
    pos = Check(pos.name, pos.ok, pos.time, pos.joint,
                pos.value + mid[names.index(pos.joint)], pos.limit + mid[names.index(pos.joint)],
                pos.detail)
    source = "the robot description's" if arm.spec.joint_velocity else "the URDF"
    vel = _worst("joint-velocity", t, qd, arm.vmax, names,
                 f"against {source} velocity limits" + note)
    acc = _worst("joint-acceleration", t, qdd, arm.amax, names,
                 "against the robot table's acceleration limits" + note)
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
    diff = np.asarray(q)
    for order, name, limit, what in ((1, "joint-rate-velocity", vmax, "velocity"),
                                     (2, "joint-rate-acceleration", amax, "acceleration"),
                                     (3, "joint-jerk", jmax, "jerk")):
        if len(diff) < 2:
            break
        diff = np.diff(diff, axis=0)  # np.diff(q, order): the same differences
        if limit is None:
            continue

        def newest(i: int, k: int = order) -> float:  # the time of difference i's newest tick
            return t0 + (i + k) * dt

        checks.append(_worst(name, newest, diff / dt**order, np.asarray(limit, dtype=float),
                             joints, f"{what} from differences at {rate:g} Hz, against "
                             f"{source} limits"))
    return checks
