"""One type for joint motion, compiled or recorded: :class:`Trajectory`.

The compiler makes them, ``aouc measure``, ``check``, ``plot`` and ``render`` read them;
a trajectory read from a file and one just compiled are the same kind of object.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .diagnostics import AouError, Span, diag

__all__ = ["Trajectory"]


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
                "R402", f"the trajectory lacks joint(s) {', '.join(missing)} of robot "
                f"`{self.robot}`; its columns are {', '.join(self.joint_names)}",
                Span.whole_file(self.path), missing=missing))
        return np.array([self.joint_names.index(n) for n in names], dtype=int)
