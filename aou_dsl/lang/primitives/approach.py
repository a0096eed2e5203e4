"""``approach [LENGTH] [a=ACC] [v=SPEED]``: translation toward the goal."""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Literal

from ...core.codes import V105, V113
from ...core.units import Dim
from ..ir import DEFAULTS, Node
from ..parse import Word
from ..timeline import Episode, Pose
from .kind import MIN_RETREAT, Key, Kind, fmt, given, move

__all__ = ["Approach", "ApproachKind", "translation"]

_REPEAT = re.compile(r"^x\d+$")


@dataclass(frozen=True, kw_only=True, slots=True)
class Approach(Node):
    """Translation toward the goal along the line of sight.

    ``length`` [m] is None for "the rest of the way to the standoff"; it may be negative in
    a sequence (then it moves away, a retreat). ``a`` [m/s^2] is the peak acceleration,
    ``v`` [m/s] the speed cap.
    """

    kind: Literal["approach"] = "approach"
    length: float | None = None
    a: float
    v: float
    count: int = 1


def translation(node, span, pose: Pose, d: float) -> Episode:
    """A move along the line of sight from ``pose`` to distance ``d``: an approach when it
    gets closer to the goal, a retreat when it moves away (what it does, not the word)."""
    kind = "approach" if d <= pose.d else "retreat"
    return move(kind, span, pose, Pose(d, pose.h, pose.v, pose.roll), node.a, node.v)


def _check_repeat(r, length: float | None) -> None:
    """An approach repeats only in a sequence, and only with a length (V113): in the
    descriptor form it runs once, from start to standoff; without a length it already
    runs the rest of the way, so a repeat would have nowhere left to go."""
    if r.args.count is None or (r.in_sequence and (length is not None or r.count <= 1)):
        return
    word = next((a for a in r.st.args if isinstance(a, Word) and _REPEAT.match(a.text)),
                None)
    span = word.span if word is not None else r.st.keyword_span
    text = word.text if word is not None else f"x{r.count}"
    if not r.in_sequence:
        r.error(V113, f"an approach takes no `{text}` in the descriptor form: it runs "
                "once, from start to standoff", span,
                hint="for an approach in steps, write them in a `sequence { }` block, "
                "e.g. `approach 0.05m x3`")
    else:
        r.error(V113, f"an approach without a length runs the rest of the way to the "
                f"standoff: `{text}` would repeat it with nothing left to approach", span,
                hint="give it a length to approach in steps, e.g. `approach 0.05m x3`")


class ApproachKind(Kind):
    name = "approach"
    node = Approach
    translation = True
    usage = "approach [LENGTH] [a=ACC] [v=SPEED]"
    keys = {"a": Key(Dim.ACCEL, "m/s^2", "acceleration"),
            "v": Key(Dim.SPEED, "m/s", "speed")}
    evidence = {"drive": ("peak_acceleration", "max")}
    look = "moves toward the goal along the line of sight"

    def read(self, r):
        length = None
        q = r.optional_quantity()
        if q is not None:
            length = r.si(q, Dim.LENGTH, "approach length")
            if length is not None and not r.in_sequence:
                r.error(V113, "an approach length is only allowed in a `sequence { }`; "
                        "in the descriptor form the approach runs from start to standoff",
                        q.span)
            elif length == 0:
                r.error(V105, "an approach length must not be zero", q.span)
            else:  # a move along the line of sight, either way: by its magnitude
                r.visible(q, length, MIN_RETREAT, "an approach of", "m")
        _check_repeat(r, length)
        a, v = r.key("a"), r.key("v")
        if r.done():
            return Approach(span=r.st.span, length=length, a=a or DEFAULTS["approach_a"],
                            v=v or DEFAULTS["speed_cap"], count=r.count)
        return None

    def episode(self, node, pose: Pose, arg: float | None = None) -> Episode:
        """A move along the line of sight to ``arg`` [m] from the goal."""
        return translation(node, node.span, pose, given(arg, "an approach's end"))

    def values(self, node):
        return {"peak_acceleration": node.a}

    def episode_values(self, ep):
        return {"peak_acceleration": ep.a}


    def format(self, node):
        return f"approach a={fmt(node.a)} v={fmt(node.v)}"
