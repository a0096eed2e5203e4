"""``shiver ANGLE [f=FREQ] [for DURATION] [xN]``: a fast tremor of a redundant joint."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from ...core.units import Dim
from ..ir import DEFAULTS, Node
from ..parse import Word
from ..timeline import Episode, Pose
from .kind import MIN_ANGLE, Key, Kind, fmt, repeat

__all__ = ["MIN_CYCLES", "MIN_SHIVER_F", "Shiver", "ShiverKind", "shiver_cycles",
           "shiver_duration"]


@dataclass(frozen=True, kw_only=True, slots=True)
class Shiver(Node):
    """Oscillation of the shiver joint: ``amplitude`` [rad] peak to peak, at ``f`` [Hz]
    for ``duration`` [s]."""

    kind: Literal["shiver"] = "shiver"
    amplitude: float
    f: float
    duration: float
    count: int = 1


#: Slowest shiver [Hz]: a shiver is a fast tremor. Slower, its swings are slow rolls
#: back and forth, a small one is measured with a pause inside it (its speed stays under
#: what tells motion from rest for a while), and its 3 cycles take many seconds.
MIN_SHIVER_F = 1.0
#: Fewest cycles of a shiver: it fades in over the first and out over the last.
MIN_CYCLES = 3
#: The rule of a shiver that lasts longer than its `for` says.
LENGTHENED = "V126"


def shiver_cycles(requested: float, f: float) -> int:
    """The whole number of cycles a shiver asked to last ``requested`` [s] at ``f`` [Hz]
    runs: the nearest to ``requested * f``, at least :data:`MIN_CYCLES`."""
    return max(MIN_CYCLES, round(requested * f))


def shiver_duration(requested: float, f: float) -> float:
    """A shiver lasts a whole number of cycles, at least 3 (ramp up, full, ramp down)."""
    return shiver_cycles(requested, f) / f


def _lengthened(r, node: Shiver) -> None:
    """A `for` shorter than :data:`MIN_CYCLES` cycles is lengthened: say so (a warning)."""
    if round(node.duration * node.f) >= MIN_CYCLES:
        return
    q = r.args.for_
    word = next((a for a in r.st.args if isinstance(a, Word) and a.text == "for"), None)
    runs = shiver_duration(node.duration, node.f)
    r.ctx.report(LENGTHENED, f"a shiver lasts at least {MIN_CYCLES} cycles (it fades in "
                 f"over the first and out over the last): at {node.f:g} Hz it runs "
                 f"{runs:.2f} s, not `{q.text}`", word.span.to(q.span) if word else q.span,
                 hint=f"write `for {runs:.3g}s` to say so, or a higher `f=` for a shorter "
                 "shiver", requested=node.duration, duration=runs)


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
        if f is not None and f < MIN_SHIVER_F:
            r.error("V105", f"a shiver is a fast tremor of at least {MIN_SHIVER_F:g} Hz, "
                    f"found `{r.args.keys['f'].value.text}`", r.args.keys["f"].value.span,
                    hint="a slower roll back and forth is a tilt: `tilt 5deg x4` rolls "
                    "5 deg one way, back, and again")
            f = None
        dur = None
        if r.args.for_ is not None:
            dur = r.positive(r.args.for_, r.si(r.args.for_, Dim.TIME, "shiver duration"),
                             "shiver duration")
        if r.done() and amp is not None:
            node = Shiver(span=r.st.span, amplitude=amp, f=f or DEFAULTS["shiver_f"],
                          duration=dur or DEFAULTS["shiver_duration"], count=r.count)
            if dur is not None:
                _lengthened(r, node)
            return node
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
