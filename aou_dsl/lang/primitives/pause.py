"""``pause DURATION [xN]``: a hold, every joint at rest."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from ...core.codes import V105
from ...core.units import Dim
from ..ir import Node
from ..timeline import Episode, Pose
from .kind import MIN_PAUSE, Kind, Needs, Timing, fmt, repeat

__all__ = ["Pause", "PauseKind"]


@dataclass(frozen=True, kw_only=True, slots=True)
class Pause(Node):
    """A hold: every joint velocity zero for ``duration`` [s]."""

    kind: Literal["pause"] = "pause"
    duration: float
    count: int = 1


class PauseKind(Kind):
    name = "pause"
    node = Pause
    usage = "pause DURATION [xN]"
    timing = Timing.HOLD
    evidence = {"stillness": ("duration", "sum")}
    #: Two pauses in a row are one hold: motion goes between them.
    needs = Needs(apart=True)
    look = f"still: every joint at rest, for at least {MIN_PAUSE:g} s"

    def read(self, r):
        q = r.quantity("a duration")
        d = r.positive(q, r.si(q, Dim.TIME, "pause duration"), "pause duration")
        if q is not None and d is not None and d < MIN_PAUSE:
            r.error(V105, f"a pause must last at least {MIN_PAUSE}s to be told apart from "
                    f"the stop between two episodes, found `{q.text}`", q.span)
        if r.done() and d is not None:
            return Pause(span=r.st.span, duration=d, count=r.count)
        return None

    def episode(self, node, pose: Pose, arg: float | None = None) -> Episode:
        return Episode("pause", node.span, pose, pose, node.duration)

    def values(self, node):
        return {"duration": node.duration}

    def episode_values(self, ep):
        return {"duration": ep.duration}


    def format(self, node):
        return f"pause {fmt(node.duration)}s{repeat(node.count)}"
