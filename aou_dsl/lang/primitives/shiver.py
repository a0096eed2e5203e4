"""``shiver ANGLE [f=FREQ] [for DURATION] [xN]``: a fast tremor of a redundant joint."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from ...core.codes import V105, V126
from ...core.units import Dim
from ..ir import DEFAULTS, Node
from ..parse import Word
from ..timeline import Episode, Pose
from .kind import LOOK_SLACK, MIN_ANGLE, MIN_PAUSE, Key, Kind, Timing, fmt, repeat

__all__ = ["LOOK_SHIVER_F", "MIN_CYCLES", "MIN_SHIVER_F", "Shiver", "ShiverKind",
           "VISIBLE_SHIVER", "shiver_cycles", "shiver_duration"]


@dataclass(frozen=True, kw_only=True, slots=True)
class Shiver(Node):
    """Oscillation of the shiver joint: ``amplitude`` [rad] peak to peak, at ``f`` [Hz]
    for ``duration`` [s]."""

    kind: Literal["shiver"] = "shiver"
    amplitude: float
    f: float
    duration: float
    count: int = 1
    #: Whether the statement says `for` (else ``duration`` is the default).
    timed: bool = False


#: Slowest shiver [Hz]: a shiver is a fast tremor. Slower, its swings are slow rolls
#: back and forth, a small one is measured with a pause inside it (its speed stays under
#: what tells motion from rest for a while), and its 3 cycles take many seconds.
MIN_SHIVER_F = 1.0
#: Slowest shiver that still looks like one [Hz]: the floor a fit keeps and a
#: measurement reads by (the language accepts down to :data:`MIN_SHIVER_F`, so that files
#: written for it keep compiling). A shiver is a tremor, a rapid alternating roll: one
#: motion made of swings, none of them a move of its own. The language's shortest
#: moment a person tells apart is :data:`~.kind.MIN_PAUSE` (0.2 s, the shortest pause seen
#: as a stop). A swing (half a cycle, one reversal to the next) that lasts longer is long
#: enough to be seen as a roll one way and a roll back: a tilt, exploration of the
#: surroundings rather than a tremor, and the motion drifts from fearful toward curious.
#: So a swing lasts at most ``MIN_PAUSE``: ``f >= 1 / (2 MIN_PAUSE)`` = 2.5 Hz, the
#: language's default frequency.
LOOK_SHIVER_F = 1.0 / (2.0 * MIN_PAUSE)
#: Narrowest shiver a fit may leave [rad]: the language's least visible angle
#: (:data:`~.kind.MIN_ANGLE`, 1 deg, twice the 0.5 deg a shiver's amplitude is measured
#: to, so that a shiver at the floor is read as present beyond its tolerance). Chosen at
#: it, not above: the study found no perceived effect of a shiver's amplitude on how
#: fearful a motion looks, so a narrower shiver keeps the look, a slower one does not.
VISIBLE_SHIVER = MIN_ANGLE
#: Fewest cycles of a shiver: it fades in over the first and out over the last.
MIN_CYCLES = 3
#: The rule of a shiver that lasts longer than its `for` says.
LENGTHENED = V126


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
    timing = Timing.OSCILLATION
    evidence = {"tremor": ("amplitude", "sum")}
    look = (f"rapid: at least {LOOK_SHIVER_F:g} Hz (each swing over within "
            f"{MIN_PAUSE:g} s), and at least {math.degrees(VISIBLE_SHIVER):g} deg wide")

    def keeps_look(self, declared, fitted):
        other = super().keeps_look(declared, fitted)
        if other is not None:
            return other
        floor = min(declared.f, LOOK_SHIVER_F)
        if fitted.f < floor * (1.0 - 1e-9):
            return (f"a {fitted.f:g} Hz shiver swings slower than a tremor (at least "
                    f"{floor:g} Hz): it would read as slow rolls, a tilt")
        least = min(declared.amplitude, VISIBLE_SHIVER)
        if fitted.amplitude < least * (1.0 - 1e-9):
            return (f"a {math.degrees(fitted.amplitude):.3g} deg shiver is under the "
                    f"{math.degrees(least):g} deg a person sees")
        return None

    def reads_as(self, kind_values, duration):
        """A measured shiver slower than :data:`LOOK_SHIVER_F` (beyond the measurement's
        slack) reads as slow rolls back and forth: a tilt."""
        f = kind_values.get("frequency")
        if f is not None and f < LOOK_SHIVER_F * (1.0 - LOOK_SLACK):
            return "tilt"
        return self.name

    def read(self, r):
        q = r.quantity("an amplitude")
        amp = r.positive(q, r.si(q, Dim.ANGLE, "shiver amplitude"), "shiver amplitude")
        r.visible(q, amp, MIN_ANGLE, "a shiver of", "deg")
        f = r.key("f")
        if f is not None and f < MIN_SHIVER_F:
            r.error(V105, f"a shiver is a fast tremor of at least {MIN_SHIVER_F:g} Hz, "
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
                          duration=dur or DEFAULTS["shiver_duration"], count=r.count,
                          timed=dur is not None)
            if dur is not None:
                _lengthened(r, node)
            return node
        return None

    def episode(self, node, pose: Pose, arg: float | None = None) -> Episode:
        return Episode("shiver", node.span, pose, pose, shiver_duration(node.duration, node.f),
                       amplitude=node.amplitude, f=node.f)

    def values(self, node):
        return {"amplitude": math.degrees(node.amplitude)}

    def episode_values(self, ep):
        return {"amplitude": math.degrees(ep.amplitude)}


    def format(self, node):
        return (f"shiver {fmt(math.degrees(node.amplitude))}deg f={fmt(node.f)}Hz "
                f"for {fmt(node.duration)}s{repeat(node.count)}")
