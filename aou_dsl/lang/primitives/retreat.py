"""``retreat LENGTH [a=ACC] [v=SPEED] [xN]``: translation away from the goal."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from ...core.codes import V105
from ...core.units import Dim
from ..ir import DEFAULTS, Node
from ..timeline import Episode, Pose
from .approach import translation
from .kind import MIN_RETREAT, Key, Kind, Needs, fmt, repeat
from .pause import PauseKind

__all__ = ["Retreat", "RetreatKind"]


@dataclass(frozen=True, kw_only=True, slots=True)
class Retreat(Node):
    """Translation away from the goal by ``length`` [m] with peak acceleration ``a``
    [m/s^2] and speed cap ``v`` [m/s]; negative in a sequence moves toward it."""

    kind: Literal["retreat"] = "retreat"
    length: float
    a: float
    v: float
    count: int = 1


class RetreatKind(Kind):
    name = "retreat"
    node = Retreat
    translation = True
    usage = "retreat LENGTH [a=ACC] [v=SPEED] [xN]"
    keys = {"a": Key(Dim.ACCEL, "m/s^2", "acceleration"),
            "v": Key(Dim.SPEED, "m/s", "speed")}
    evidence = {"extent": ("distance", "sum"), "vigour": ("peak_acceleration", "max")}
    #: A retreat starts and ends at a pause: a withdrawal, not a step of a longer move.
    needs = Needs(preceded_by=PauseKind.name, followed_by=PauseKind.name)
    look = (f"moves away: the goal distance grows, by at least {MIN_RETREAT * 1000:g} mm "
            "(an approach statement of negative length is a retreat, and the reverse)")

    def keeps_look(self, declared, fitted):
        other = super().keeps_look(declared, fitted)
        if other is not None:
            return other
        if fitted.end.d - fitted.start.d < MIN_RETREAT * (1.0 - 1e-9):
            return (f"a retreat of {(fitted.end.d - fitted.start.d) * 1000:.3g} mm is under "
                    f"the {MIN_RETREAT * 1000:g} mm a person sees move away")
        return None

    def read(self, r):
        q = r.quantity("a distance")
        d = r.si(q, Dim.LENGTH, "retreat distance")
        if q is not None and not r.in_sequence:
            d = r.positive(q, d, "retreat distance")
        elif q is not None and d == 0:
            r.error(V105, "a retreat distance must not be zero", q.span)
        r.visible(q, d, MIN_RETREAT, "a retreat of", "m")
        a, v = r.key("a"), r.key("v")
        if r.done() and d is not None:
            return Retreat(span=r.st.span, length=d, a=a or DEFAULTS["retreat_a"],
                           v=v or DEFAULTS["speed_cap"], count=r.count)
        return None

    def episode(self, node, pose: Pose, arg: float | None = None) -> Episode:
        """Away from the goal by ``length`` (toward it when negative: an approach)."""
        return translation(node, node.span, pose, pose.d + node.length)

    def values(self, node):
        return {"distance": abs(node.length), "peak_acceleration": node.a}

    def episode_values(self, ep):
        return {"distance": ep.path_length, "peak_acceleration": ep.a}


    def format(self, node):
        return (f"retreat {fmt(node.length)}m a={fmt(node.a)} v={fmt(node.v)}"
                f"{repeat(node.count)}")
