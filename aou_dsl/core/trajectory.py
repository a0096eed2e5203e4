"""One type for joint motion, compiled or recorded: :class:`Trajectory`.

The compiler makes them, ``aouc measure``, ``check``, ``plot`` and ``render`` read them;
a trajectory read from a file and one just compiled are the same kind of object.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .codes import R402
from .diagnostics import AouError, Span, diag

__all__ = ["FrameDefinition", "Trajectory"]


@dataclass(frozen=True)
class FrameDefinition:
    """Where an end-effector frame is on its robot: welded to the link ``parent`` at
    ``xyz`` [m], turned by ``rpy`` (roll, pitch, yaw [rad], the URDF's convention). A
    frame that is a link of the URDF is its own parent at zero.

    Attributes:
        name: the frame's name (``ee_frame`` of the trajectory).
        parent: the URDF link it is welded to.
        xyz: its origin in the parent link's frame [m], shape (3,).
        rpy: its rotation from the parent link's frame [rad], shape (3,).
    """

    name: str
    parent: str
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)

    @property
    def is_link(self) -> bool:
        """Whether the frame is the parent link itself (nothing to add to a model)."""
        return self.name == self.parent and not any(self.xyz) and not any(self.rpy)

    def to_json(self) -> dict:
        return {"parent": self.parent, "xyz": list(self.xyz), "rpy": list(self.rpy)}


@dataclass(frozen=True, eq=False)
class Trajectory:
    """Joint motion of an arm.

    Attributes:
        t: sample times [s], shape (N,), strictly increasing.
        q: joint positions [rad or m], shape (N, J), one column per ``joint_names``
            (a recording may hold joints the robot model does not move).
        joint_names: the columns' joint names.
        robot: the robot (a name of example-robot-data or a robot file's path).
        ee_frame: the end-effector frame, or None for the robot's default.
        goal: goal position in the base frame [m], or None when unknown.
        qd, qdd: joint velocities and accelerations, shape (N, J), when known
            (compiled trajectories have them; recordings usually not).
        episodes: ``(kind, t_start, t_end)`` from the compiler's timeline, when known.
        path: where it was read from, for diagnostics; title: a name for figures.
        package_dirs: folders that hold the robot's ``package://`` meshes, when its URDF
            needs them (absolute paths).
        ee_definition: where ``ee_frame`` is on the robot, when the file says (a frame
            aou added to an arm it knew, read back on an arm loaded from its URDF).
    """

    t: np.ndarray
    q: np.ndarray
    joint_names: tuple[str, ...]
    robot: str
    ee_frame: str | None = None
    goal: tuple[float, ...] | None = None
    qd: np.ndarray | None = None
    qdd: np.ndarray | None = None
    episodes: tuple[tuple[str, float, float], ...] = ()
    path: str = "<memory>"
    title: str = ""
    package_dirs: tuple[str, ...] = ()
    ee_definition: FrameDefinition | None = None

    @property
    def duration(self) -> float:
        """Time from the first sample to the last [s]."""
        return float(self.t[-1] - self.t[0])

    def with_(self, **changes: Any) -> Trajectory:
        """A copy with some fields replaced."""
        return replace(self, **changes)

    def columns(self, names: tuple[str, ...]) -> np.ndarray:
        """Indices of ``names`` among the columns.

        Raises:
            AouError: R402 naming the joints the trajectory lacks.
        """
        missing = [n for n in names if n not in self.joint_names]
        if missing:
            raise AouError(diag(
                R402, f"the trajectory lacks joint(s) {', '.join(missing)} of robot "
                f"`{self.robot}`; its columns are {', '.join(self.joint_names)}",
                Span.whole_file(self.path), missing=missing,
                hint="name each column after its joint, or map them with --map "
                     "COLUMN=JOINT,... (or a mapping file)"))
        return np.array([self.joint_names.index(n) for n in names], dtype=int)
