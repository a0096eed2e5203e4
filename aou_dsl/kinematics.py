"""Robot models for the numerical stages: Pinocchio, loaded from example-robot-data.

Shared by the compiler and by ``aouc measure``; it knows only the robot (URDF and
:mod:`aou_dsl.robots`), never a behaviour. Pinocchio is imported here, so only the
commands that need kinematics pay for it.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

import numpy as np

from .diagnostics import AouError, Span, diag
from .robots import DEFAULT_JOINT_JERK, ROBOTS, RobotSpec

__all__ = ["ArmModel", "load_arm"]


@dataclass(frozen=True)
class ArmModel:
    """A robot reduced to its arm joints, with the limits aou plans with.

    Attributes:
        spec: the robot's entry of :data:`aou_dsl.robots.ROBOTS`.
        model: the reduced ``pinocchio.Model`` (arm joints only; fingers locked).
        frame_id: id of the end-effector frame in ``model``.
        lower, upper: joint position limits [rad], shape (n,).
        vmax: joint velocity limits from the URDF [rad/s], shape (n,).
        amax: joint acceleration limits from the robot table [rad/s^2], shape (n,).
        jmax: joint jerk limits from the robot table [rad/s^3], shape (n,).
        effort: joint effort limits from the URDF [N m], shape (n,).
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

        fid = self.frame_id if frame is None else self.model.getFrameId(frame)
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


@functools.cache
def load_arm(robot: str, ee_frame: str | None = None) -> ArmModel:
    """Load a robot of :data:`ROBOTS` from example-robot-data, reduced to its arm.

    Raises:
        AouError: V109 for a robot aou has no table for, R402 for a frame the model
            lacks (listing the valid ones), I501 when the model's joints are not the
            table's.
    """
    import example_robot_data as erd
    import pinocchio as pin

    spec = ROBOTS.get(robot)
    where = Span.whole_file(f"<robot {robot}>")
    if spec is None:
        raise AouError(diag("V109", f"unknown robot `{robot}`: expected one of "
                            f"{', '.join(ROBOTS)}", where))
    full = erd.load(robot).model
    lock = [full.getJointId(n) for n in full.names[1:] if n not in spec.arm_joints]
    q_ref = pin.neutral(full)
    model = pin.buildReducedModel(full, lock, q_ref) if lock else full
    names = list(model.names[1:])
    if tuple(names) != spec.arm_joints:
        raise AouError(diag("I501", f"robot `{robot}` has joints {names}, expected "
                            f"{list(spec.arm_joints)}", where))
    frame = ee_frame or spec.ee_frame
    if not model.existFrame(frame):
        valid = sorted({f.name for f in model.frames})
        raise AouError(diag("R402", f"robot `{robot}` has no frame `{frame}`", where,
                            hint=f"frames: {', '.join(valid)}", valid=valid))
    return ArmModel(
        spec=spec,
        model=model,
        frame_id=model.getFrameId(frame),
        lower=np.array(model.lowerPositionLimit),
        upper=np.array(model.upperPositionLimit),
        vmax=np.array(model.velocityLimit),
        amax=np.array(spec.joint_accel),
        effort=np.array(model.effortLimit),
        jmax=np.array(spec.joint_jerk or (DEFAULT_JOINT_JERK,) * len(spec.arm_joints)),
    )
