"""``gaze horizontal|vertical ANGLE [v=ANGSPEED] [xN]``: an arc about the goal."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from ...core.units import Dim
from ..ir import DEFAULTS, Node
from ..timeline import Episode, Pose
from .kind import MIN_ANGLE, Key, Kind, Needs, fmt, given, move, repeat
from .pause import PauseKind

__all__ = ["GAZE_ANGULAR_ACCEL", "Gaze", "GazeKind"]

#: Angular acceleration of gaze arcs [rad/s^2] (the language sets only their speed).
GAZE_ANGULAR_ACCEL = math.radians(45.0)
_PLANES = ("horizontal", "vertical")


@dataclass(frozen=True, kw_only=True, slots=True)
class Gaze(Node):
    """An arc about the goal in the horizontal or vertical plane, gaze locked on it.

    ``angle`` [rad] is the angle of the goal vector from the initial line of sight in
    that plane at the end of the episode (signed in a sequence; the amplitude in the
    descriptor form). ``v`` [rad/s] is the angular speed cap.
    """

    kind: Literal["gaze"] = "gaze"
    plane: Literal["horizontal", "vertical"]
    angle: float
    v: float
    count: int = 1


def _angle_in(pose: Pose, plane: str) -> float:
    return pose.h if plane == "horizontal" else pose.v


class GazeKind(Kind):
    name = "gaze"
    node = Gaze
    usage = "gaze horizontal|vertical ANGLE [v=ANGSPEED] [xN]"
    keys = {"v": Key(Dim.ANGULAR_SPEED, "deg/s", "angular speed")}
    evidence = {"exploration": ("angle", "sum")}
    #: Its angle is read at the pause that ends it (a look that comes back is still one).
    needs = Needs(followed_by=PauseKind.name)
    look = ("holds the goal: the hand turns about it in its plane, its line of sight on the "
            "goal throughout, and ends on the side it declares")

    def keeps_look(self, declared, fitted):
        other = super().keeps_look(declared, fitted)
        if other is not None:
            return other
        if fitted.plane != declared.plane:
            return f"the gaze would turn in the {fitted.plane} plane, not the {declared.plane}"
        want = _angle_in(declared.end, declared.plane) - _angle_in(declared.start, declared.plane)
        got = _angle_in(fitted.end, fitted.plane) - _angle_in(fitted.start, fitted.plane)
        if want * got < 0.0 or (want != 0.0 and got == 0.0):
            return "the gaze would turn the other way, or not at all"
        return None

    def read(self, r):
        plane = r.word(_PLANES, "`gaze` needs a plane: `horizontal` or `vertical`")
        q = r.quantity("an angle")
        angle = r.amplitude(q, r.si(q, Dim.ANGLE, "gaze angle"), "a gaze angle")
        if not r.in_sequence:  # in a sequence, 0deg looks straight again
            r.visible(q, angle, MIN_ANGLE, "a gaze of", "deg")
        v = r.key("v")
        if r.done() and plane is not None and angle is not None:
            return Gaze(span=r.st.span, plane=plane, angle=angle, v=v or DEFAULTS["gaze_v"],
                        count=r.count)
        return None

    def episode(self, node, pose: Pose, arg: float | None = None) -> Episode:
        """An arc from ``pose`` to the plane angle ``arg`` [rad] in the node's plane."""
        angle = given(arg, "a gaze's plane angle")
        if node.plane == "horizontal":
            end = Pose(pose.d, angle, pose.v, pose.roll)
        else:
            end = Pose(pose.d, pose.h, angle, pose.roll)
        return move("gaze", node.span, pose, end, GAZE_ANGULAR_ACCEL, node.v,
                    plane=node.plane)

    def values(self, node):
        deg = abs(math.degrees(node.angle))
        return {node.plane: deg, "angle": deg}

    def episode_values(self, ep):
        out = {}
        for plane in _PLANES:
            if _angle_in(ep.start, plane) != _angle_in(ep.end, plane):
                out[plane] = abs(math.degrees(_angle_in(ep.end, plane)))
        out["angle"] = max(out.values(), default=0.0)
        return out


    def format(self, node):
        return (f"gaze {node.plane} {fmt(math.degrees(node.angle))}deg "
                f"v={fmt(math.degrees(node.v))}deg/s{repeat(node.count)}")
