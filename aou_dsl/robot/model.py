"""A loaded robot (:class:`Robot`) and the Pinocchio model of its arm (:func:`reduced_model`).

Plain data and one builder, below both the loader (:mod:`.load`) and the derivation of what
a URDF lacks (:mod:`.assemble`), which both make robots.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from ..core.codes import V109
from ..core.diagnostics import AouError, Diagnostic, Span, diag
from ..core.robot_specs import RobotSpec
from .kinematics import frame_id
from .urdf import GAZE_FRAME, Gaze, Urdf, gaze_offset, gaze_rpy, kinematic_xml

__all__ = ["Robot", "gaze_of", "reduced_model"]


@dataclass(frozen=True)
class Robot:
    """A loaded robot.

    Attributes:
        spec: everything aou knows of it, pinned or derived.
        urdf: its URDF, parsed.
        model: the Pinocchio model of its arm joints (the rest locked at zero), with
            ``spec.ee_frame``.
        package_dirs: folders given for its ``package://`` meshes.
        description: the robot description file it was read from ("" for none).
        no_effort: arm joints whose URDF gives no effort limit.
        filled_velocity: velocity limits [rad/s] given to joints whose URDF has none.
        warnings: C313 diagnostics (limits from no source).
        reach_ok: whether the derived default reach passed every probe (None: pinned).
    """

    spec: RobotSpec
    urdf: Urdf
    model: Any
    package_dirs: tuple[str, ...] = ()
    description: str = ""
    no_effort: tuple[str, ...] = ()
    filled_velocity: dict[str, float] = field(default_factory=dict)
    warnings: tuple[Diagnostic, ...] = ()
    reach_ok: bool | None = None

    @property
    def collision(self) -> bool:
        """Whether any link the arm moves has collision geometry."""
        moved: set[str] = set()
        frontier = [self.urdf.joint(self.spec.arm_joints[0]).child]
        while frontier:
            link = frontier.pop()
            moved.add(link)
            frontier += [j.child for j in self.urdf.children(link)]
        return bool(moved & self.urdf.collision_links)

    @property
    def gaze(self) -> Gaze | None:
        """``(ee_link, forward, ee_offset, ee_roll)`` when aou adds the end-effector frame."""
        return gaze_of(self.spec)


def gaze_of(spec: RobotSpec) -> Gaze | None:
    """``(ee_link, forward, ee_offset, ee_roll)`` when aou adds the end-effector frame."""
    return (spec.ee_link, spec.forward, spec.ee_offset, spec.ee_roll) if spec.ee_link else None


def reduced_model(urdf: Urdf, joints: Sequence[str], velocity: dict[str, float],
                  gaze: Gaze | None) -> Any:
    """The Pinocchio model of ``joints`` (every other joint welded at zero), built from
    the URDF's kinematics only; with :data:`GAZE_FRAME` when ``gaze`` is given.

    Raises:
        AouError: V109 when Pinocchio cannot build it, or its joints are not ``joints``.
    """
    import numpy as np
    import pinocchio as pin

    try:
        model = pin.buildModelFromXML(kinematic_xml(urdf, joints, velocity))
    except (RuntimeError, ValueError) as exc:
        raise AouError(diag(V109, f"`{os.path.basename(urdf.path)}`: Pinocchio cannot "
                            f"build its kinematics: {exc}", Span.whole_file(urdf.path))
                       ) from None
    names = tuple(model.names[1:])
    if names != tuple(joints):
        raise AouError(diag(
            V109, f"`{os.path.basename(urdf.path)}`: the arm's joints from the base "
            f"outward are {', '.join(names)}; expected {', '.join(joints)}",
            Span.whole_file(urdf.path), hint="list `arm_joints` from the base outward"))
    if gaze is not None:  # added here, not in the XML: link and joint names may clash
        parent = frame_id(model, gaze[0])
        f = model.frames[parent]
        turn = pin.SE3(pin.rpy.rpyToMatrix(*gaze_rpy(gaze[1], gaze[3])),
                       np.array(gaze_offset(gaze[1], gaze[2])))
        model.addFrame(pin.Frame(GAZE_FRAME, f.parentJoint, parent, f.placement * turn,
                                 pin.FrameType.OP_FRAME))
    return model
