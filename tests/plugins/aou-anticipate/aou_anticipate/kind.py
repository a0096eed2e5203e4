"""``anticipate DIST [a=ACC] [xN]``: the syntax piece, its validation, its C-V evidence
and its time law, as a :class:`aou_dsl.lang.primitives.kind.Kind`.

An anticipation is a small counter-movement: the end-effector draws back from the goal
by ``DIST`` along the line of sight, rest to rest at peak acceleration ``a`` (timed like
a retreat), and the approach it prepares starts at once, with no pause between them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from aou_dsl.core.codes import V113, V130
from aou_dsl.core.units import Dim
from aou_dsl.lang.ir import DEFAULTS, Node
from aou_dsl.lang.primitives import APPROACH
from aou_dsl.lang.primitives.kind import MIN_RETREAT, Key, Kind, Needs, Timing, fmt, move
from aou_dsl.lang.timeline import Episode, Pose

__all__ = ["NAME", "Anticipate", "AnticipateKind", "DEFAULT_A", "MAX_DISTANCE"]

#: The keyword, as the entry point names it.
NAME = "anticipate"
#: Peak acceleration when the statement gives none [m/s^2].
DEFAULT_A = 0.10
#: The largest counter-movement [m]: past it, a move away reads as a retreat, not as the
#: wind-up of an approach.
MAX_DISTANCE = 0.05


@dataclass(frozen=True, kw_only=True, slots=True)
class Anticipate(Node):
    """A draw-back of ``length`` [m] away from the goal at peak acceleration ``a``
    [m/s^2] (speed capped at the language's approach and retreat cap), directly before
    an approach."""

    kind: Literal["anticipate"] = "anticipate"
    length: float
    a: float
    count: int = 1


class AnticipateKind(Kind):
    name = NAME
    node = Anticipate
    usage = "anticipate DIST [a=ACC] [xN]"
    keys = {"a": Key(Dim.ACCEL, "m/s^2", "acceleration")}
    #: Timed like a retreat: the fastest rest-to-rest run of its line under the arm's
    #: limits and its peak acceleration.
    timing = Timing.OPTIMAL
    translation = True
    #: The wind-up of a committed approach: its peak acceleration adds to the drive, as
    #: an approach's does (the largest of them counts).
    evidence = {"drive": ("peak_acceleration", "max")}
    #: It comes directly before an approach, nothing between (a pause would make it a
    #: retreat of its own): the layout puts it there, and only there does it count.
    needs = Needs(followed_by=APPROACH)
    look = (f"moves away from the goal, by {MIN_RETREAT * 1000:g} to "
            f"{MAX_DISTANCE * 1000:g} mm, and an approach follows at once")

    def read(self, r):
        q = r.quantity("a distance")
        d = r.si(q, Dim.LENGTH, "anticipation distance")
        d = r.positive(q, d, "an anticipation distance")
        r.visible(q, d, MIN_RETREAT, "an anticipation of", "m")
        if q is not None and d is not None and d > MAX_DISTANCE:
            r.ctx.error(V130, f"an anticipation of `{q.text}` is out of range: it is a "
                        f"small counter-movement, up to {MAX_DISTANCE * 100:g} cm",
                        q.span, hint=f"for a larger move away, write a `retreat {q.text}`",
                        found=q.text, least=MIN_RETREAT, greatest=MAX_DISTANCE, unit="m")
            d = None
        if r.in_sequence and r.count > 1:
            r.error(V113, f"`x{r.count}` would draw back {r.count} times in a row: in a "
                    "sequence, an anticipation comes directly before an approach",
                    r.st.keyword_span,
                    hint="write one `anticipate` before each approach it prepares")
        a = r.key("a")
        if r.done() and d is not None:
            return Anticipate(span=r.st.span, length=d, a=a or DEFAULT_A, count=r.count)
        return None

    def episode(self, node, pose: Pose, arg: float | None = None) -> Episode:
        """Away from the goal by ``length``, straight back along the line of sight."""
        end = Pose(pose.d + node.length, pose.h, pose.v, pose.roll)
        return move(self.name, node.span, pose, end, node.a, DEFAULTS["speed_cap"])

    def values(self, node):
        return {"distance": node.length, "peak_acceleration": node.a}

    def episode_values(self, ep):
        return {"distance": ep.path_length, "peak_acceleration": ep.a}

    def format(self, node):
        count = f" x{node.count}" if node.count != 1 else ""
        return f"{self.name} {fmt(node.length)}m a={fmt(node.a)}{count}"

    def keeps_look(self, declared, fitted):
        other = super().keeps_look(declared, fitted)
        if other is not None:
            return other
        moved = fitted.end.d - fitted.start.d
        if not MIN_RETREAT * (1.0 - 1e-9) <= moved <= MAX_DISTANCE * (1.0 + 1e-9):
            return (f"a draw-back of {moved * 1000:.3g} mm is not the small counter-movement "
                    f"of an anticipation ({MIN_RETREAT * 1000:g} to "
                    f"{MAX_DISTANCE * 1000:g} mm)")
        return None
