"""A PyBullet world (DIRECT mode, no display) holding the robot.

The robot is loaded from the copy of its URDF that :func:`aou_dsl.robot.load.scene_urdf`
writes once per process (mesh paths absolute; visual meshes only when the scene is
drawn, since the checks need collision shapes only). PyBullet is imported here and
only here; each :class:`Scene` owns its own physics client, so several can coexist and
none leaks into another.
"""

from __future__ import annotations

import contextlib
import os
import sys
from dataclasses import dataclass, field

import numpy as np

from ..core.diagnostics import AouError, Span, diag

__all__ = ["Scene", "SceneOptions", "import_pybullet", "quiet", "urdf_path"]


@contextlib.contextmanager
def quiet():
    """Keep PyBullet's C library from printing its banner ("pybullet build time: ...")
    on standard output or error: it would corrupt ``--format json`` output."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 1)
            os.dup2(null.fileno(), 2)
            yield
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in saved:
            os.close(fd)


_quiet = quiet


def import_pybullet():
    """Import PyBullet quietly (see :func:`quiet`)."""
    if "pybullet" not in sys.modules:
        with _quiet():
            import pybullet  # noqa: F401
    return sys.modules["pybullet"]


def urdf_path(robot: str, *, visuals: bool = False) -> tuple[str, str]:
    """The URDF PyBullet loads for ``robot`` (a name or a robot file's path; every mesh
    path in it absolute, the end-effector frame aou adds included; visual shapes only if
    ``visuals``) and its folder."""
    from .load import scene_urdf

    urdf = scene_urdf(robot, visuals=visuals)
    return urdf, os.path.dirname(urdf)


@dataclass(frozen=True)
class SceneOptions:
    """The scene around the robot.

    Attributes:
        target_size: edge of the cube at the goal, which nothing may touch [m].
        table_height: height of the table plane in the base frame [m]; None for no table.
    """

    target_size: float = 0.05
    table_height: float | None = 0.0


@dataclass
class Scene:
    """The robot (and optionally the target and table) in a private PyBullet client.

    ``visuals`` loads the visual meshes too (for drawing); the checks need only the
    collision shapes, which load many times faster.
    """

    robot: str
    goal: tuple[float, ...] | None = None
    options: SceneOptions = field(default_factory=SceneOptions)
    visuals: bool = True

    def __post_init__(self):
        from .load import load_robot

        spec = load_robot(self.robot).spec
        urdf, _ = urdf_path(self.robot, visuals=self.visuals)
        pb = import_pybullet()
        self.pb = pb
        with _quiet():
            self.client = pb.connect(pb.DIRECT)
        flags = pb.URDF_USE_SELF_COLLISION | pb.URDF_USE_SELF_COLLISION_EXCLUDE_PARENT
        try:
            with _quiet():  # PyBullet prints warnings about the URDF (inertia, materials)
                self.body = pb.loadURDF(urdf, useFixedBase=True, flags=flags,
                                        physicsClientId=self.client)
        except pb.error as exc:
            self.close()
            raise AouError(diag("V109", f"PyBullet cannot load robot `{self.robot}`: {exc}",
                                Span.whole_file(urdf))) from None
        #: The arm's joint names, in the order of :meth:`set_arm`'s ``q``.
        self.arm_joints: tuple[str, ...] = spec.arm_joints
        self.joint_index: dict[str, int] = {}
        self.link_index: dict[str, int] = {}
        for j in range(pb.getNumJoints(self.body, physicsClientId=self.client)):
            info = pb.getJointInfo(self.body, j, physicsClientId=self.client)
            self.joint_index[info[1].decode()] = j
            self.link_index[info[12].decode()] = j
        self.arm = [self.joint_index[n] for n in spec.arm_joints]
        self.ee_link = self.link_index[spec.ee_frame]
        self.target = None
        self.table = None
        if self.goal is not None and self.options.target_size > 0:
            half = self.options.target_size / 2
            shape = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=[half] * 3,
                                            physicsClientId=self.client)
            visual = pb.createVisualShape(pb.GEOM_BOX, halfExtents=[half] * 3,
                                          rgbaColor=[0.2, 0.4, 0.9, 1],
                                          physicsClientId=self.client)
            self.target = pb.createMultiBody(0, shape, visual, basePosition=list(self.goal),
                                             physicsClientId=self.client)
        if self.options.table_height is not None:
            plane = pb.createCollisionShape(pb.GEOM_PLANE, physicsClientId=self.client)
            self.table = pb.createMultiBody(0, plane, -1,
                                            basePosition=[0, 0, self.options.table_height],
                                            physicsClientId=self.client)

    def set_arm(self, q: np.ndarray) -> None:
        """Put the arm joints at ``q`` (kinematically, no physics), at rest."""
        self.pb.resetJointStatesMultiDof(self.body, self.arm, [[float(v)] for v in q],
                                         targetVelocities=[[0.0]] * len(self.arm),
                                         physicsClientId=self.client)

    def ee_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """End-effector position (3,) and rotation (3, 3) as PyBullet computes them."""
        st = self.pb.getLinkState(self.body, self.ee_link, computeForwardKinematics=True,
                                  physicsClientId=self.client)
        pos, quat = np.array(st[4]), st[5]
        rot = np.array(self.pb.getMatrixFromQuaternion(quat)).reshape(3, 3)
        return pos, rot

    def close(self) -> None:
        if self.client is not None:
            self.pb.disconnect(physicsClientId=self.client)
            self.client = None

    def __enter__(self) -> Scene:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
