"""``shiver ANGLE [f=FREQ] [for DURATION] [xN]``: a fast tremor of a redundant joint."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from ..ir import DEFAULTS, Node
from ..timeline import Episode, Pose
from ..units import Dim
from .base import MIN_ANGLE, Key, Kind, fmt, repeat

__all__ = ["Shiver", "ShiverKind", "shiver_duration"]


@dataclass(frozen=True, kw_only=True, slots=True)
class Shiver(Node):
    """Oscillation of the shiver joint: ``amplitude`` [rad] peak to peak, at ``f`` [Hz]
    for ``duration`` [s]."""

    kind: Literal["shiver"] = "shiver"
    amplitude: float
    f: float
    duration: float
    count: int = 1


def shiver_duration(requested: float, f: float) -> float:
    """A shiver lasts a whole number of cycles, at least 3 (ramp up, full, ramp down)."""
    return max(3, round(requested * f)) / f


class ShiverKind(Kind):
    name = "shiver"
    node = Shiver
    usage = "shiver ANGLE [f=FREQ] [for DURATION] [xN]"
    keys = {"f": Key(Dim.FREQUENCY, "Hz", "shiver frequency")}
    timing = "oscillation"
    evidence = {"tremor": ("amplitude", "sum")}

    def read(self, r):
        q = r.quantity("an amplitude")
        amp = r.positive(q, r.si(q, Dim.ANGLE, "shiver amplitude"), "shiver amplitude")
        r.visible(q, amp, MIN_ANGLE, "a shiver of", "deg")
        f = r.key("f")
        dur = None
        if r.args.for_ is not None:
            dur = r.positive(r.args.for_, r.si(r.args.for_, Dim.TIME, "shiver duration"),
                             "shiver duration")
        if r.done() and amp is not None:
            return Shiver(span=r.st.span, amplitude=amp, f=f or DEFAULTS["shiver_f"],
                          duration=dur or DEFAULTS["shiver_duration"], count=r.count)
        return None

    def episode(self, node, pose: Pose) -> Episode:
        return Episode("shiver", node.span, pose, pose, shiver_duration(node.duration, node.f),
                       amplitude=node.amplitude, f=node.f)

    def values(self, node):
        return {"amplitude": math.degrees(node.amplitude)}

    def episode_values(self, ep):
        return {"amplitude": math.degrees(ep.amplitude)}


    def format(self, node):
        return (f"shiver {fmt(math.degrees(node.amplitude))}deg f={fmt(node.f)}Hz "
                f"for {fmt(node.duration)}s{repeat(node.count)}")
