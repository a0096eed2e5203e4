"""What a trajectory file says of its robot, so that another tool can recompute the hand
pose from the file alone: the end-effector frame's definition and the robot's identity.

- :func:`frame_definition`: where the end-effector frame is, as the parent link it is
  welded to and its placement (``xyz`` [m], ``rpy`` [rad]). aou adds a frame (``aou_ee``)
  to arms whose end-effector link does not look along its z axis; the frame exists only
  inside aou, so the file says where it is.
- :func:`robot_identity`: the robot's name, the URDF's path as it was given (for a
  built-in arm, its path inside example-robot-data's ``robots`` folder) and the SHA-256 of
  the URDF's text, so a reader can tell whether the URDF it holds is the one used.
- :func:`with_frame`: an arm model with a frame a file defines, for a robot loaded from a
  URDF that lacks it.
"""

from __future__ import annotations

import os
from dataclasses import replace
from typing import Any

from ..core.codes import R402
from ..core.diagnostics import AouError, Span, diag
from ..core.memo import file_digest
from ..core.robot_specs import ROBOTS, RobotSpec
from ..core.trajectory import FrameDefinition
from .kinematics import ArmModel
from .model import Robot
from .urdf import gaze_offset, gaze_rpy

__all__ = ["frame_definition", "robot_identity", "urdf_sha256", "with_frame"]


def frame_definition(spec: RobotSpec) -> FrameDefinition:
    """Where ``spec.ee_frame`` is: on ``spec.ee_link`` at the tool's offset, its z axis
    the forward axis turned by ``ee_roll``, when aou adds the frame; else the URDF's own
    link (its own parent at zero)."""
    if not spec.ee_link:
        return FrameDefinition(spec.ee_frame, spec.ee_frame)
    xyz = tuple(float(v) + 0.0 for v in gaze_offset(spec.forward, spec.ee_offset))
    rpy = tuple(float(v) + 0.0 for v in gaze_rpy(spec.forward, spec.ee_roll))
    return FrameDefinition(spec.ee_frame, spec.ee_link, xyz, rpy)  # type: ignore[arg-type]


def urdf_sha256(path: str) -> str:
    """The SHA-256 of the file at ``path``, in hex ("" when it cannot be read): of its
    bytes now, hashed again whenever the file changed."""
    return file_digest(path)


def _given_urdf(robot: str, spec: RobotSpec, description: str) -> str:
    """The URDF's path as the user gave it: the robot's own path for a URDF, the path a
    robot description names (from where the description was named), or a built-in arm's
    path inside example-robot-data."""
    if robot in ROBOTS or not os.path.isabs(spec.urdf):
        return spec.urdf
    if not description:
        return robot
    rel = os.path.relpath(spec.urdf, os.path.dirname(description))
    return os.path.normpath(os.path.join(os.path.dirname(robot), rel))


def robot_identity(robot: str, loaded: Robot) -> dict[str, str]:
    """``{"name", "urdf", "sha256"}`` of the robot named ``robot`` (a built-in name or a
    robot file's path, as the trajectory's ``robot`` key holds it), ``loaded`` by
    :func:`~.load.load_robot`."""
    return {"name": robot, "urdf": _given_urdf(robot, loaded.spec, loaded.description),
            "sha256": urdf_sha256(loaded.urdf.path)}


def with_frame(arm: ArmModel, frame: FrameDefinition, where: str) -> ArmModel:
    """``arm`` whose end-effector is ``frame`` (a frame a trajectory file defines),
    added to a copy of its model when the model has no frame of that name and placement.

    Raises:
        AouError: R402 when the model has no link ``frame.parent``.
    """
    import numpy as np
    import pinocchio as pin

    from .kinematics import frame_id

    placement = pin.SE3(pin.rpy.rpyToMatrix(*frame.rpy), np.array(frame.xyz, float))
    parent = frame_id(arm.model, frame.parent)
    if parent < 0:
        valid = sorted({f.name for f in arm.model.frames})
        raise AouError(diag(R402, f"the file's end-effector frame `{frame.name}` is welded "
                            f"to `{frame.parent}`, a link robot `{arm.spec.name}` lacks",
                            Span.whole_file(where), hint=f"frames: {', '.join(valid)}",
                            valid=valid))
    p = arm.model.frames[parent]
    wanted = p.placement * placement
    own = frame_id(arm.model, frame.name)
    if own >= 0 and _same(arm.model.frames[own], p.parentJoint, wanted):
        return replace(arm, frame_id=own)
    model: Any = arm.model.copy()
    fid = model.addFrame(pin.Frame(f"{frame.name}", p.parentJoint, parent, wanted,
                                   pin.FrameType.OP_FRAME))
    return replace(arm, model=model, frame_id=int(fid))


def _same(f: Any, joint: int, placement: Any) -> bool:
    import numpy as np

    return bool(f.parentJoint == joint and np.allclose(f.placement.homogeneous,
                                                        placement.homogeneous, atol=1e-9))
