"""Robot models for the numerical stages: Pinocchio models of the arm's joints.

Shared by the compiler and by ``aouc measure``; it knows only the robot (its URDF,
:mod:`aou_dsl.robots`, a robot description), never a behaviour. The robot is loaded by
:mod:`aou_dsl.arms.load`, once per process; Pinocchio is imported there, so only the
commands that need kinematics pay for it.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .diagnostics import AouError, Span, diag
from .robots import DEFAULT_JOINT_JERK, RobotSpec

__all__ = ["ArmModel", "arm_model", "frame_id", "load_arm"]


@dataclass(frozen=True)
class ArmModel:
    """A robot reduced to its arm joints, with the limits aou plans with.

    Attributes:
        spec: the robot's spec (a built-in arm of :data:`aou_dsl.robots.ROBOTS`, or one
            read from a robot file).
        model: the reduced ``pinocchio.Model`` (arm joints only; grippers locked;
            continuous joints as revolute joints of one angle).
        frame_id: id of the end-effector frame in ``model``.
        lower, upper: joint position limits [rad], shape (n,).
        vmax: joint velocity limits from the URDF (or the robot file) [rad/s], shape (n,).
        amax: joint acceleration limits from the robot's spec [rad/s^2], shape (n,).
        jmax: joint jerk limits from the robot's spec [rad/s^3], shape (n,).
        effort: joint effort limits from the URDF [N m] (inf where it gives none),
            shape (n,).
    """

    spec: RobotSpec
    model: Any  # pinocchio.Model (pinocchio ships no type hints)
    frame_id: int
    lower: np.ndarray
    upper: np.ndarray
    vmax: np.ndarray
    amax: np.ndarray
    effort: np.ndarray
    jmax: np.ndarray

    @property
    def joint_names(self) -> tuple[str, ...]:
        return self.spec.arm_joints

    @property
    def n(self) -> int:
        return len(self.spec.arm_joints)

    @property
    def plan_vmax(self) -> np.ndarray:
        """Joint velocity limits the compiler plans with [rad/s], shape (n,)."""
        return self.vmax * self.spec.velocity_scale

    @property
    def plan_amax(self) -> np.ndarray:
        """Joint acceleration limits the compiler plans with [rad/s^2], shape (n,)."""
        return self.amax * self.spec.accel_scale

    def data(self):
        return self.model.createData()

    def fk(self, q: np.ndarray, frame: str | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Forward kinematics of every row of ``q``, shape (N, n).

        Returns:
            positions, shape (N, 3) [m], and rotations, shape (N, 3, 3), of the
            end-effector frame (or ``frame``) in the base frame.
        """
        import pinocchio as pin

        fid = self.frame_id if frame is None else frame_id(self.model, frame)
        data = self.model.createData()
        q = np.atleast_2d(np.asarray(q, dtype=float))
        pos = np.empty((len(q), 3))
        rot = np.empty((len(q), 3, 3))
        for i, qi in enumerate(q):
            pin.framesForwardKinematics(self.model, data, qi)
            m = data.oMf[fid]
            pos[i] = m.translation
            rot[i] = m.rotation
        return pos, rot


def frame_id(model: Any, name: str) -> int:
    """The id of frame ``name`` in ``model``: the link's (body) frame when a joint has the
    same name as a link; -1 when there is none."""
    import pinocchio as pin

    ids = [i for i, f in enumerate(model.frames) if f.name == name]
    bodies = [i for i in ids if model.frames[i].type == pin.FrameType.BODY]
    return (bodies or ids or [-1])[0]


def arm_model(spec: RobotSpec, model: Any, *, no_effort: tuple[str, ...] = ()) -> ArmModel:
    """An :class:`ArmModel` of a reduced Pinocchio ``model`` whose joints are
    ``spec.arm_joints``; joints in ``no_effort`` (no effort limit in the URDF) get an
    infinite one."""
    effort = np.array(model.effortLimit, dtype=float)
    for j in no_effort:
        effort[spec.arm_joints.index(j)] = np.inf
    n = len(spec.arm_joints)
    vmax = np.array(spec.joint_velocity or model.velocityLimit, dtype=float)
    return ArmModel(
        spec=spec,
        model=model,
        frame_id=frame_id(model, spec.ee_frame),
        lower=np.array(model.lowerPositionLimit),
        upper=np.array(model.upperPositionLimit),
        vmax=vmax,
        amax=np.array(spec.joint_accel, dtype=float),
        effort=effort,
        jmax=np.array(spec.joint_jerk or (DEFAULT_JOINT_JERK,) * n, dtype=float),
    )


@functools.cache
def load_arm(robot: str, ee_frame: str | None = None) -> ArmModel:
    """The arm of ``robot`` (a built-in name or a robot file's path), its kinematics built
    from the URDF's joints alone (no mesh is read), once per process.

    Raises:
        AouError: V109 for an unknown robot or a robot file aou cannot use (I501 when it
            cannot be read), R402 for a frame the model lacks (listing the valid ones).
    """
    from .arms.load import load_robot

    r = load_robot(robot)
    arm = arm_model(r.spec, r.model, no_effort=r.no_effort)
    if ee_frame is None or ee_frame == r.spec.ee_frame:
        return arm
    fid = frame_id(r.model, ee_frame)
    if fid < 0:
        valid = sorted({f.name for f in r.model.frames})
        raise AouError(diag("R402", f"robot `{robot}` has no frame `{ee_frame}`",
                            Span.whole_file(f"<robot {robot}>"),
                            hint=f"frames: {', '.join(valid)}", valid=valid))
    return replace(arm, frame_id=fid)
