"""Joint torques a trajectory needs, by inverse dynamics, against the URDF effort limits.

A motor capped at its effort limit can never read back more than that limit, so a
check of the torques a simulator reports under position control cannot fail: a motor
that saturates shows up only as tracking error. The torque check here asks the other
question, the one a controller designer asks: what torque does *following this
trajectory* take? Pinocchio's recursive Newton-Euler algorithm gives it from the joint
positions, velocities and accelerations of every sample, gravity included (the base
stands upright, gravity 9.81 m/s^2 along -z), with the URDF's masses and inertias.

The dynamic replay's tracking error (:mod:`.replay`) is judged separately, against
:data:`TRACKING_LIMIT`: a saturated or too-soft motor lags the plan.
"""

from __future__ import annotations

import numpy as np

from ..robot.kinematics import ArmModel
from .limits import Check, filtered

__all__ = ["TRACKING_LIMIT", "check_torque", "check_tracking", "inverse_dynamics"]

#: Largest joint tracking error [rad] of the dynamic replay that passes: 1 degree. The
#: shipped behaviours track within a hundredth of that on every built-in arm; an error
#: of a degree or more is a motor that cannot follow (saturated, or asked to jump).
TRACKING_LIMIT = float(np.radians(1.0))


def inverse_dynamics(arm: ArmModel, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray
                     ) -> np.ndarray:
    """Joint torques [N m] that give ``qdd`` at ``q``, ``qd`` under gravity (RNEA).

    Shapes: ``q``, ``qd``, ``qdd`` (N, n) in the arm's joint order; returns (N, n).
    """
    import pinocchio as pin

    model = arm.model
    data = model.createData()
    tau = np.empty((len(q), arm.n))
    for i in range(len(q)):
        tau[i] = pin.rnea(model, data, q[i], qd[i], qdd[i])
    return tau


def check_torque(arm: ArmModel, t: np.ndarray, q: np.ndarray, qd: np.ndarray,
                 qdd: np.ndarray) -> tuple[Check, float]:
    """The ``joint-torque`` check: the sample and joint whose torque comes nearest (or
    furthest past) its effort limit, and that ratio. A noisy recording's torques come
    from its filtered signal (:func:`~.limits.filtered`, as its limits are judged): a
    second derivative of raw noise asks for torques no motion does.

    Returns:
        the check (value: the torque [N m], limit: the effort limit) and the worst
        ratio of torque to effort limit (0 when no joint has a limit).
    """
    note = ""
    judged = filtered(np.asarray(t, float), np.asarray(q, float), arm.amax)
    if judged is not None:  # a noisy recording: judged on its filtered signal, as limits are
        t, q, qd, qdd, note = judged.t, judged.q, judged.qd, judged.qdd, " " + judged.note
    tau = inverse_dynamics(arm, q, qd, qdd)
    effort = np.where(np.isfinite(arm.effort) & (arm.effort > 0), arm.effort, np.inf)
    ratio = np.abs(tau) / effort
    # The first sample within a part per million of the peak: a held pose's gravity
    # torque is a plateau, and rounding must not move its reported time.
    near = ratio >= ratio.max() * (1.0 - 1e-6)
    i = int(np.argmax(near.any(axis=1)))
    j = int(np.argmax(np.where(near[i], ratio[i], -1.0)))
    worst = float(ratio[i, j])
    check = Check("joint-torque", worst <= 1.0, float(t[i]), arm.joint_names[j],
                  float(tau[i, j]), float(arm.effort[j]),
                  f"inverse dynamics (gravity included) against the URDF effort limits: "
                  f"{worst:.0%} of {arm.joint_names[j]}'s" + note)
    return check, worst


def check_tracking(joints: tuple[str, ...], t: np.ndarray, err: np.ndarray,
                   limit: float = TRACKING_LIMIT) -> Check:
    """The ``tracking-error`` check of a replay: ``err`` (N, n) [rad], the achieved minus
    the planned joint position at times ``t`` (N,), against ``limit`` [rad]."""
    a = np.abs(err)
    i, j = np.unravel_index(int(np.argmax(a)), a.shape)
    worst = float(a[i, j])
    return Check("tracking-error", worst <= limit, float(t[i]), joints[j], float(err[i, j]),
                 limit, f"the dynamic replay's joint lags the plan by {np.degrees(worst):.3g} "
                 f"deg (limit {np.degrees(limit):.3g} deg): a motor that cannot follow")
