"""The compiler's registry of kinds: how each kind's episodes are timed and checked.

The compiler never asks which kind an episode is; it asks this registry how the kind is
timed (its :class:`~aou_dsl.lang.primitives.Timing`), whether its path coordinate is a
distance or an angle (the path's sampling step and the unit of its acceleration), and
which descriptor a short peak acceleration falls short of (what a C304 names). A kind
from a plugin gives all of it through its ``kind`` part (a
:class:`~aou_dsl.lang.primitives.Kind`: ``timing`` and ``translation``; its descriptors
through its ``descriptors`` part), so a plugin kind timed ``Timing.OPTIMAL`` or
``Timing.HOLD`` compiles and is checked with no edit here.

The two other time laws are the shiver's oscillation of one joint and the tilt's fixed
duration: what the compiler says when they do not fit writes the shiver's and the tilt's
own keys (``f=``, ``v=``). A plugin kind timed one of those is refused with K802 (the
compiler gives it no time law) rather than offered a fix for keys it may not have.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Protocol

from ..core.plugins import plugins
from ..lang.descriptors import REGISTRY, Descriptor, every_descriptor
from ..lang.primitives import BUILTIN_KINDS, KINDS, Timing

__all__ = ["BUILTIN_TIMINGS", "PEAK_ACCELERATION", "PLUGIN_TIMINGS", "KindTiming",
           "TimedKind", "missing", "timing_of"]

#: The episode value a peak acceleration descriptor aggregates.
PEAK_ACCELERATION = "peak_acceleration"
#: The time laws the compiler gives a plugin kind.
PLUGIN_TIMINGS = (Timing.HOLD, Timing.OPTIMAL)


class TimedKind(Protocol):
    """What the compiler reads of a kind (a plugin's ``kind`` part gives it as a Kind):
    its keyword, how its episodes are timed, and whether its path coordinate is a
    distance along the line of sight [m] (else an angle [rad])."""

    @property
    def name(self) -> str: ...
    @property
    def timing(self) -> Timing: ...
    @property
    def translation(self) -> bool: ...


@dataclass(frozen=True, slots=True)
class KindTiming:
    """How the compiler times and checks one kind's episodes.

    Attributes:
        kind: the kind's keyword.
        timing: its time law.
        translation: its path coordinate is a distance [m] (else an angle [rad]).
        acceleration: the name a C304 gives the peak acceleration it finds short: the
            kind's descriptor of :data:`PEAK_ACCELERATION` when it has one, else the
            kind's keyword and ``acceleration`` (a gaze's peak acceleration is no
            descriptor: nothing compares a measured value with this name).
    """

    kind: str
    timing: Timing
    translation: bool
    acceleration: str

    @property
    def still(self) -> bool:
        """No path to solve: held, or one joint swung about a held configuration."""
        return self.timing in (Timing.HOLD, Timing.OSCILLATION)

    @property
    def unit(self) -> str:
        """The unit of its path's acceleration."""
        return "m/s^2" if self.translation else "rad/s^2"

    def step(self, step_length: float, step_angle: float) -> float:
        """The sampling step of its path: a length or an angle."""
        return step_length if self.translation else step_angle


def _of(kind: TimedKind, descriptors: Iterable[Descriptor]) -> KindTiming:
    accel = next((d.name for d in descriptors
                  if d.kind == kind.name and d.key == PEAK_ACCELERATION), None)
    return KindTiming(kind.name, kind.timing, bool(kind.translation),
                      accel or "_".join((kind.name, "acceleration")))


#: The built-in kinds' timings, by keyword.
BUILTIN_TIMINGS = {name: _of(k, REGISTRY.values()) for name, k in BUILTIN_KINDS.items()}


def timing_of(kind: str) -> KindTiming:
    """How ``kind``'s episodes are timed (a built-in's or a loaded plugin's kind)."""
    got = BUILTIN_TIMINGS.get(kind)
    return got if got is not None else _of(KINDS[kind], every_descriptor().values())


def missing(kinds: set[str]) -> tuple[str, str] | None:
    """The first of ``kinds`` (by name) the compiler cannot time, and why, in words (a
    K802's message), or None when it times them all."""
    for name in sorted(kinds):
        if name in BUILTIN_TIMINGS:
            continue
        if name not in KINDS:
            return name, f"`{name}` is no kind of aou or of a loaded plugin"
        source = next((p.source for p in plugins() if p.name == name), "")
        t = KINDS[name].timing
        if t not in PLUGIN_TIMINGS:
            return name, (f"the compiler cannot time `{name}` (plugin {source}): its time "
                          f"law {t.value!r} is the shiver's or the tilt's own; a plugin kind "
                          f"is timed {' or '.join(repr(x.value) for x in PLUGIN_TIMINGS)}")
    return None
