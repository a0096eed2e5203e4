"""The studio's 3D scene: the arm with its meshes, the goal, the table, the hand's path
coloured by episode and its line of sight; a second arm, ghosted, to compare.

The arm is drawn from the URDF the safety checks and ``aouc render`` load (meshes found
as the compiler finds them, :meth:`.engine.Engine.urdf_path`), through yourdfpy and
viser's URDF helper. The hand's pose comes from aou's own forward kinematics
(:func:`aou_dsl.robot.batch_fk.batch_fk`), so the path drawn is the path measured.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..core.trajectory import Trajectory
from .kind_controls import EPISODE_COLOURS, colour_of

__all__ = ["EPISODE_COLOURS", "Arm", "Track", "track"]


@dataclass(frozen=True)
class Track:
    """A trajectory ready to draw: times, joint values in the URDF's actuated order, the
    hand's positions and forward axes, and the goal."""

    t: np.ndarray
    cfg: np.ndarray
    hand: np.ndarray
    forward: np.ndarray
    goal: np.ndarray | None
    episodes: tuple[tuple[str, float, float], ...]

    @property
    def duration(self) -> float:
        return float(self.t[-1] - self.t[0])

    def index(self, t: float) -> int:
        """The sample at time ``t`` from the start (clamped to the motion)."""
        k = int(np.searchsorted(self.t, self.t[0] + t, side="right")) - 1
        return min(max(k, 0), len(self.t) - 1)


def track(tr: Trajectory, actuated: tuple[str, ...]) -> Track:
    """``tr`` for drawing; ``actuated`` are the URDF's joints (those ``tr`` lacks, like
    fingers, stay at zero)."""
    from ..robot.batch_fk import batch_fk
    from ..robot.load import load_arm

    arm = load_arm(tr.robot, tr.ee_frame)
    q = np.asarray(tr.q, float)
    pos, rot = batch_fk(arm, q[:, tr.columns(arm.joint_names)])
    cfg = np.zeros((len(tr.t), len(actuated)))
    for j, name in enumerate(actuated):
        if name in tr.joint_names:
            cfg[:, j] = q[:, tr.joint_names.index(name)]
    goal = None if tr.goal is None else np.asarray(tr.goal, float)
    return Track(np.asarray(tr.t, float), cfg, pos, rot[:, :, 2], goal, tuple(tr.episodes))


def _kind_at(episodes, t: float) -> str:
    for kind, a, b in episodes:
        if a <= t <= b:
            return kind
    return ""


class Arm:
    """One arm in the scene under ``root`` (``/arm``, ``/ghost``), with its path, line of
    sight and goal; ``ghost`` draws it see-through."""

    def __init__(self, server: Any, urdf_path: str, root: str, ghost: bool = False) -> None:
        from viser.extras import ViserUrdf

        self.server, self.root, self.ghost = server, root, ghost
        self.frame = server.scene.add_frame(root, show_axes=False)
        self._path: Any = None
        colour = (0.55, 0.75, 1.0, 0.35) if ghost else None
        self.urdf = ViserUrdf(server, Path(urdf_path), root_node_name=root,
                              mesh_color_override=colour)
        self.actuated: tuple[str, ...] = tuple(self.urdf.get_actuated_joint_names())
        self.track: Track | None = None
        self._sight: Any = None
        # The player's thread and the build's (drawing a new motion at t = 0) both pose
        # the arm: two first poses at once would each add the line of sight, the second
        # replacing the first, whose handle one of them would then keep and write to.
        self._posing = threading.Lock()

    def show(self, tr: Trajectory) -> None:
        """Draw ``tr``: its path coloured by episode and the goal (:meth:`pose` poses the
        arm)."""
        self.track = tk = track(tr, self.actuated)
        step = max(1, len(tk.t) // 600)  # the path as at most 600 segments
        pts = tk.hand[::step]
        mids = tk.t[::step]
        seg = np.stack([pts[:-1], pts[1:]], axis=1)
        colours = np.array([colour_of(_kind_at(tk.episodes, m)) for m in mids[:-1]],
                           dtype=np.uint8)
        self._path = self.server.scene.add_line_segments(
            f"{self.root}_path", seg, np.repeat(colours[:, None, :], 2, axis=1),
            thickness=2.0 if self.ghost else 4.0, thickness_units="screen",
            visible=self.frame.visible)
        if tk.goal is not None and not self.ghost:
            self.server.scene.add_box("/goal", color=(230, 180, 40),
                                      dimensions=(0.05, 0.05, 0.05),
                                      position=tuple(tk.goal))

    def set_visible(self, visible: bool) -> None:
        """Show or hide the arm and its path (the compared arm's checkbox)."""
        self.frame.visible = visible
        if self._path is not None:
            self._path.visible = visible

    def pose(self, t: float) -> None:
        """The arm at time ``t`` from the start, with its line of sight."""
        with self._posing:
            self._pose(t)

    def _pose(self, t: float) -> None:
        tk = self.track
        if tk is None:
            return
        k = tk.index(t)
        self.urdf.update_cfg(tk.cfg[k])
        if tk.goal is None or self.ghost:
            return
        reach = float(np.linalg.norm(tk.goal - tk.hand[k]))
        seg = np.array([[tk.hand[k], tk.hand[k] + tk.forward[k] * reach]])
        if self._sight is None:
            self._sight = self.server.scene.add_line_segments(
                f"{self.root}_sight", seg, (40, 40, 40), thickness=1.5, thickness_units="screen")
        else:
            self._sight.points = seg


def add_table(server: Any, height: float = 0.0) -> None:
    """The table the checks use: a plane at ``height`` in the base frame."""
    server.scene.add_box("/table", color=(222, 214, 196), dimensions=(1.6, 1.6, 0.01),
                         position=(0.3, 0.0, height - 0.005))
