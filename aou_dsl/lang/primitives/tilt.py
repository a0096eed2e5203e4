"""``tilt ANGLE [v=ANGSPEED] [xN]``: a roll about the forward axis."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from ...core.units import Dim
from ..ir import DEFAULTS, Node
from ..timeline import Episode, Pose
from .kind import MIN_ANGLE, Key, Kind, fmt, repeat

__all__ = ["Tilt", "TiltKind"]


@dataclass(frozen=True, kw_only=True, slots=True)
class Tilt(Node):
    """A roll of ``angle`` [rad] about the forward axis at angular speed ``v`` [rad/s]:
    the episode lasts exactly ``|angle| / v`` (the tilt velocity descriptor)."""

    kind: Literal["tilt"] = "tilt"
    angle: float
    v: float
    count: int = 1


class TiltKind(Kind):
    name = "tilt"
    node = Tilt
    usage = "tilt ANGLE [v=ANGSPEED] [xN]"
    keys = {"v": Key(Dim.ANGULAR_SPEED, "deg/s", "angular speed")}
    timing = "fixed"
    evidence = {"exploration": ("angle", "sum")}

    def read(self, r):
        q = r.quantity("an angle")
        angle = r.amplitude(q, r.si(q, Dim.ANGLE, "tilt angle"), "a tilt angle")
        if q is not None and angle == 0:
            r.error("V105", "a tilt angle must not be zero", q.span)
        r.visible(q, angle, MIN_ANGLE, "a tilt of", "deg")
        v = r.key("v")
        if r.done() and angle is not None:
            return Tilt(span=r.st.span, angle=angle, v=v or DEFAULTS["tilt_v"], count=r.count)
        return None

    def episode(self, node, pose: Pose, delta: float) -> Episode:
        end = Pose(pose.d, pose.h, pose.v, pose.roll + delta)
        duration = abs(delta) / node.v
        return Episode("tilt", node.span, pose, end, duration,
                       a=4.0 * abs(delta) / duration ** 2, vmax=2.0 * node.v)

    def values(self, node):
        return {"angle": abs(math.degrees(node.angle)), "velocity": math.degrees(node.v)}

    def episode_values(self, ep):
        angle = math.degrees(ep.path_length)
        return {"angle": angle, "velocity": angle / ep.duration}


    def format(self, node):
        return (f"tilt {fmt(math.degrees(node.angle))}deg v={fmt(math.degrees(node.v))}deg/s"
                f"{repeat(node.count)}")
