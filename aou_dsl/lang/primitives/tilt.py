"""``tilt ANGLE [v=ANGSPEED] [xN]``: a roll about the forward axis."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from ...core.codes import V105
from ...core.units import Dim
from ..ir import DEFAULTS, Node
from ..timeline import Episode, Pose
from .kind import MIN_ANGLE, MIN_PAUSE, Key, Kind, Timing, fmt, given, repeat

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
    timing = Timing.FIXED
    evidence = {"exploration": ("angle", "sum")}
    look = ("slow and single: one roll one way, no faster than declared, lasting at least "
            f"{MIN_PAUSE:g} s (a shorter one is a twitch, a swing of a tremor)")

    def keeps_look(self, declared, fitted):
        other = super().keeps_look(declared, fitted)
        if other is not None:
            return other
        turn = fitted.end.roll - fitted.start.roll
        if turn * (declared.end.roll - declared.start.roll) <= 0.0:
            return "the tilt would roll the other way, or not at all"
        speed = abs(turn) / fitted.duration
        if speed > declared.path_length / declared.duration * (1.0 + 1e-9):
            return f"the tilt would roll faster ({math.degrees(speed):.3g} deg/s) than declared"
        if fitted.duration < min(declared.duration, MIN_PAUSE) * (1.0 - 1e-9):
            return f"a {fitted.duration:.3g} s roll is a twitch, not a slow tilt"
        return None

    def read(self, r):
        q = r.quantity("an angle")
        angle = r.amplitude(q, r.si(q, Dim.ANGLE, "tilt angle"), "a tilt angle")
        if q is not None and angle == 0:
            r.error(V105, "a tilt angle must not be zero", q.span)
        r.visible(q, angle, MIN_ANGLE, "a tilt of", "deg")
        v = r.key("v")
        if r.done() and angle is not None:
            return Tilt(span=r.st.span, angle=angle, v=v or DEFAULTS["tilt_v"], count=r.count)
        return None

    def episode(self, node, pose: Pose, arg: float | None = None) -> Episode:
        delta = given(arg, "a tilt's roll")
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
