"""A PyBullet world (DIRECT mode, no display) holding the robot from example-robot-data.

PyBullet is imported here and only here; each :class:`Scene` owns its own physics
client, so several can coexist and none leaks into another.
"""

from __future__ import annotations

import contextlib
import os
import sys
from dataclasses import dataclass, field

import numpy as np

from ..robots import ROBOTS

__all__ = ["Scene", "SceneOptions", "import_pybullet", "urdf_path"]


@contextlib.contextmanager
def _quiet():
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


def import_pybullet():
    """Import PyBullet quietly (see :func:`_quiet`)."""
    if "pybullet" not in sys.modules:
        with _quiet():
            import pybullet  # noqa: F401
    return sys.modules["pybullet"]


#: The URDF of each robot inside example-robot-data's share folder.
_URDF = {
    "panda": "panda_description/urdf/panda.urdf",
    "ur5": "ur_description/urdf/ur5_robot.urdf",
}


def urdf_path(robot: str) -> tuple[str, str]:
    """The robot's URDF path and the folder its ``package://`` meshes resolve from."""
    import example_robot_data as erd

    robots = erd.getModelPath(_URDF[robot])
    urdf = os.path.join(robots, "robots", _URDF[robot])
    if not os.path.exists(urdf):  # layouts differ between releases of the data package
        urdf = os.path.join(robots, _URDF[robot])
    share = os.path.normpath(os.path.join(os.path.dirname(urdf), *[".."] * 3))
    return urdf, os.path.dirname(share)


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
    """The robot (and optionally the target and table) in a private PyBullet client."""

    robot: str
    goal: tuple[float, ...] | None = None
    options: SceneOptions = field(default_factory=SceneOptions)

    def __post_init__(self):
        pb = import_pybullet()
        self.pb = pb
        with _quiet():
            self.client = pb.connect(pb.DIRECT)
        urdf, search = urdf_path(self.robot)
        pb.setAdditionalSearchPath(search, physicsClientId=self.client)
        flags = pb.URDF_USE_SELF_COLLISION | pb.URDF_USE_SELF_COLLISION_EXCLUDE_PARENT
        self.body = pb.loadURDF(urdf, useFixedBase=True, flags=flags,
                                physicsClientId=self.client)
        spec = ROBOTS[self.robot]
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
