"""A parsed URDF as plain data: its joints (:class:`Joint`) and links (:class:`Urdf`), and
the names aou gives what it adds. Read by :mod:`.urdf`, checked by :mod:`.sanity`."""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["CONTINUOUS_RANGE", "GAZE_FRAME", "MOVING", "Gaze", "Joint", "Urdf"]

#: Position range [rad] a continuous joint is given, either way from zero: one turn.
CONTINUOUS_RANGE = 2.0 * math.pi
#: Name of the frame aou adds when the end-effector link's z axis is not its forward axis.
GAZE_FRAME = "aou_ee"
#: ``(ee_link, forward, offset [m], roll [rad])`` of the frame aou adds.
Gaze = tuple[str, str, float, float]
#: Joint types aou can move.
MOVING = ("revolute", "continuous", "prismatic")


@dataclass(frozen=True)
class Joint:
    """One ``<joint>`` of a URDF. Limits are None where the file gives none."""

    name: str
    type: str
    parent: str
    child: str
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    axis: tuple[float, float, float]
    lower: float | None
    upper: float | None
    velocity: float | None
    effort: float | None

    @property
    def moving(self) -> bool:
        return self.type in MOVING


@dataclass(frozen=True)
class Urdf:
    """A parsed URDF.

    Attributes:
        path: the file, absolute.
        text: its content.
        joints: every joint, in file order.
        links: every link name, in file order.
        collision_links: the links with at least one ``<collision>`` element.
    """

    path: str
    text: str
    joints: tuple[Joint, ...]
    links: tuple[str, ...]
    collision_links: frozenset[str]

    @property
    def root(self) -> str:
        """The link no joint has as its child."""
        children = {j.child for j in self.joints}
        return next(link for link in self.links if link not in children)

    def joint(self, name: str) -> Joint:
        return next(j for j in self.joints if j.name == name)

    def children(self, link: str) -> list[Joint]:
        return [j for j in self.joints if j.parent == link]

    def parent_joint(self, link: str) -> Joint | None:
        return next((j for j in self.joints if j.child == link), None)
