"""The controllers a trajectory is sent to, and the limits their motion generators enforce.

A controller reads the trajectory as positions commanded at its own rate and computes
velocity, acceleration and jerk from them by differences; a command past its limits
stops the arm. aou checks the same: the motion sampled at the controller's rate (the
compiled law itself, or a trajectory file interpolated as a ``joint_trajectory_controller``
would), the arm at rest before and after, every joint's jerk (and, for a named
controller, velocity and acceleration) against the limits.

- **default** (no controller named): 1 kHz, the robot table's jerk limits
  (:mod:`aou_dsl.core.robot_specs`; the URDF's and the table's velocity and acceleration limits are
  checked on every sample by :mod:`aou_dsl.safety.limits`).
- **franka**, the Franka Control Interface (libfranka), which drives the Panda: 1 kHz;
  its published joint limits ("Robot and interface specifications" of the FCI
  documentation): velocity 2.175 (joints 1-4) and 2.61 rad/s (5-7), acceleration 15,
  7.5, 10, 12.5, 15, 20, 20 rad/s^2, jerk 7500, 3750, 5000, 6250, 7500, 10000,
  10000 rad/s^3. These are *necessary* conditions: the FCI aborts a motion that
  violates one (a jump of acceleration is a jerk past the limit, reported as
  ``joint_motion_generator_acceleration_discontinuity``). It also requires zero velocity
  and acceleration at the start and the end, which the rest before and after checks.
- **ur**, Universal Robots through ``ur_robot_driver``: the e-Series controller runs at
  500 Hz (a CB3 at 125 Hz; checking at 500 Hz is the stricter). The datasheets give a
  joint speed of 180 deg/s for the UR5 (all joints); UR publishes no joint acceleration
  or jerk limit, so the robot table's apply.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from ..core.diagnostics import AouError, Span, diag

if TYPE_CHECKING:
    from ..compiler.pipeline import CompileResult
    from ..core.trajectory import Trajectory
    from ..robot.kinematics import ArmModel
    from .limits import Check

__all__ = ["CONTROLLERS", "DEFAULT_RATE", "Controller", "controller_checks", "describe", "get"]

#: Rate [Hz] of the default jerk check: the fastest common motion-generator rate.
DEFAULT_RATE = 1000.0
#: Rest samples on each side of the motion (a third difference needs three).
PAD = 3


@dataclass(frozen=True)
class Controller:
    """A controller's rate and published limits.

    Attributes:
        name: its name on the command line (``--controller``).
        title: what it is, in words.
        rate: the rate [Hz] at which it reads commanded positions.
        robots: name prefixes of the robots (in :data:`aou_dsl.core.robot_specs.ROBOTS`) it drives;
            empty for any.
        velocity, acceleration, jerk: published joint limits [rad/s, rad/s^2,
            rad/s^3] per robot name (which also covers its variants, ``ur5_limited``),
            one per arm joint; a robot or a kind of limit the vendor does not publish
            takes the robot table's (the URDF's for velocity).
    """

    name: str
    title: str
    rate: float
    robots: tuple[str, ...] = ()
    velocity: dict[str, tuple[float, ...]] = field(default_factory=dict)
    acceleration: dict[str, tuple[float, ...]] = field(default_factory=dict)
    jerk: dict[str, tuple[float, ...]] = field(default_factory=dict)

    def drives(self, robot: str) -> bool:
        return not self.robots or any(robot.startswith(p) for p in self.robots)

    def limits(self, arm: ArmModel) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Joint velocity, acceleration and jerk limits for ``arm``, each shape (n,)."""
        name = arm.spec.name

        def pick(table: dict[str, tuple[float, ...]], default: np.ndarray) -> np.ndarray:
            # A variant (ur5_limited, ur5_gripper) has its arm's joints and speeds.
            keys = [k for k in table if name == k or name.startswith(k + "_")]
            return np.array(table[keys[0]], dtype=float) if keys else default

        return (pick(self.velocity, arm.vmax), pick(self.acceleration, arm.amax),
                pick(self.jerk, arm.jmax))


_PANDA_V = (2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61)
_PANDA_A = (15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0)
_PANDA_J = (7500.0, 3750.0, 5000.0, 6250.0, 7500.0, 10000.0, 10000.0)

CONTROLLERS: dict[str, Controller] = {
    "default": Controller("default", "any motion generator at 1 kHz, the robot table's "
                          "jerk limits", DEFAULT_RATE),
    "franka": Controller("franka", "Franka Control Interface (libfranka), 1 kHz",
                         1000.0, ("panda",), {"panda": _PANDA_V}, {"panda": _PANDA_A},
                         {"panda": _PANDA_J}),
    "ur": Controller("ur", "Universal Robots e-Series (ur_robot_driver), 500 Hz", 500.0,
                     ("ur",), {"ur5": (math.radians(180.0),) * 6}),
}


def get(name: str | None) -> Controller:
    """The controller called ``name`` (None: the default).

    Raises:
        AouError: V109 for a name aou does not know, listing the known ones.
    """
    key = name or "default"
    if key not in CONTROLLERS:
        known = [c for c in CONTROLLERS if c != "default"]
        raise AouError(diag("V109", f"unknown controller `{name}`: expected one of "
                            f"{', '.join(known)}", Span.whole_file("<controller>"),
                            found=name, valid=known))
    return CONTROLLERS[key]


def controller_checks(motion: CompileResult | Trajectory, controller: str | None = None,
                      *, rate: float | None = None) -> list[Check]:
    """The motion as ``controller`` reads it: positions at its rate (``rate`` overrides),
    the arm at rest before and after, checked by differences against its limits.

    Args:
        motion: a compilation (its time law is sampled exactly) or a trajectory (read
            from a file: interpolated between its samples as a ``joint_trajectory_controller``
            does, quintic where it has velocities and accelerations).
        controller: a name of :data:`CONTROLLERS`; None for the default jerk check.

    Returns:
        Checks named ``joint-jerk`` (C311 when it fails) and, for a named controller,
        ``joint-rate-velocity`` and ``joint-rate-acceleration``; a ``controller`` check
        fails when the controller does not drive this robot.

    Raises:
        AouError: V109 for an unknown controller; R402 when a trajectory lacks a joint.
    """
    from ..robot.load import load_arm
    from .limits import Check, check_rates

    ctrl = get(controller)
    hz = float(rate or ctrl.rate)
    tr = _trajectory(motion)
    arm = load_arm(tr.robot, tr.ee_frame)
    if not ctrl.drives(arm.spec.name):
        return [Check("controller", False, detail=f"{ctrl.title} does not drive "
                      f"`{arm.spec.name}`")]
    t0, q = _commanded(motion, arm, hz)
    vmax, amax, jmax = ctrl.limits(arm)
    named = ctrl.name != "default"
    source = f"{ctrl.name}'s" if named else "the robot table's"
    checks = check_rates(arm.joint_names, q, hz, t0=t0, vmax=vmax if named else None,
                         amax=amax if named else None, jmax=jmax, source=source)
    # A difference is timed by its newest tick, which may fall in the rest after the end.
    start, end = float(tr.t[0]), float(tr.t[-1])
    return [replace(c, time=min(max(c.time, start), end)) if c.time is not None else c
            for c in checks]


def _trajectory(motion) -> Trajectory:
    """The trajectory of a compilation (or the trajectory itself)."""
    tr = motion.trajectory if hasattr(motion, "segments") else motion
    if tr is None:
        raise AouError(diag("C305", "the compilation failed: there is nothing to check",
                            motion.behaviour.span))
    return tr


def _commanded(motion, arm: ArmModel, rate: float) -> tuple[float, np.ndarray]:
    """Positions at ``rate`` from ``PAD`` ticks before the start to ``PAD`` after the end:
    the first tick's time and the positions, shape (N, n) in the arm's joint order."""
    if hasattr(motion, "segments"):
        from ..compiler.pipeline import positions

        tr = motion.trajectory
        t = _ticks(float(tr.t[0]), float(tr.t[-1]), rate)
        return float(t[0]), positions(motion, t)
    tr = motion
    cols = tr.columns(arm.joint_names)
    t = _ticks(float(tr.t[0]), float(tr.t[-1]), rate)
    return float(t[0]), _interpolate(tr, cols, t)


def _ticks(start: float, end: float, rate: float) -> np.ndarray:
    """Ticks every ``1 / rate`` from ``PAD`` before ``start`` until ``PAD`` past ``end``."""
    n = int(math.floor((end - start) * rate + 1e-9)) + 1
    return start + (np.arange(-PAD, n + PAD + 1)) / rate


def _interpolate(tr: Trajectory, cols: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Positions of a trajectory file at times ``t``, as a ``joint_trajectory_controller``
    interpolates its points: quintic Hermite between samples with velocities and
    accelerations, cubic Hermite with velocities only, else a cubic spline through the
    positions (a controller would interpolate those linearly). Outside its span the
    motion goes on with its first and last state (a file that starts moving continues a
    motion: a re-plan from the arm's state); at rest that is a hold."""
    from scipy.interpolate import CubicSpline

    ts, q = np.asarray(tr.t, float), np.asarray(tr.q, float)[:, cols]
    if len(ts) < 2:
        return np.repeat(q[:1], len(t), axis=0)
    tc = np.clip(t, ts[0], ts[-1])
    if tr.qd is None:
        return CubicSpline(ts, q, axis=0)(tc)
    i = np.clip(np.searchsorted(ts, tc, side="right") - 1, 0, len(ts) - 2)
    h = (ts[i + 1] - ts[i])[:, None]
    x = (tc - ts[i])[:, None] / h
    x2, x3 = x * x, x * x * x
    x4, x5 = x3 * x, x3 * x2
    qd = np.asarray(tr.qd, float)[:, cols]
    p0, p1, v0, v1 = q[i], q[i + 1], qd[i] * h, qd[i + 1] * h
    if tr.qdd is None:
        return ((2 * x3 - 3 * x2 + 1) * p0 + (x3 - 2 * x2 + x) * v0
                + (3 * x2 - 2 * x3) * p1 + (x3 - x2) * v1)
    qdd = np.asarray(tr.qdd, float)[:, cols]
    a0, a1 = qdd[i] * h * h, qdd[i + 1] * h * h
    inside = ((1 - 10 * x3 + 15 * x4 - 6 * x5) * p0 + (x - 6 * x3 + 8 * x4 - 3 * x5) * v0
              + (x2 - 3 * x3 + 3 * x4 - x5) / 2 * a0 + (x3 - 2 * x4 + x5) / 2 * a1
              + (-4 * x3 + 7 * x4 - 3 * x5) * v1 + (10 * x3 - 15 * x4 + 6 * x5) * p1)
    for k, mask in ((0, t < ts[0]), (-1, t > ts[-1])):
        dt = (t[mask] - ts[k])[:, None]
        inside[mask] = q[k] + qd[k] * dt + 0.5 * qdd[k] * dt * dt
    return inside


_UNITS = {"joint-rate-velocity": "rad/s", "joint-rate-acceleration": "rad/s^2",
          "joint-jerk": "rad/s^3"}


def describe(check: Check) -> str:
    """A failed controller check in words, for a diagnostic (C311 for ``joint-jerk``)."""
    if check.name not in _UNITS or check.value is None or check.limit is None:
        return check.detail
    return (f"{check.joint} reaches {abs(check.value):.4g} {_UNITS[check.name]} at "
            f"t={check.time:.3f}s, limit {check.limit:.4g} ({check.detail})")
