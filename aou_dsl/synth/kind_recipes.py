"""What synthesis does with each primitive kind: one registry keyed by kind.

For every kind a synthesized file may hold, :class:`KindRecipe` says its statements in a
descriptor-form file (one per plane: a gaze has a horizontal and a vertical one), how far
intensity 1 moves each of its descriptors for each state (the spans, by episode key,
``""`` for the count: a factor for values, episodes added for counts, the angle reached
for an exploration the stimulus lacks), the fewest episodes a varied count keeps, and
how many pauses its episodes need around them (a retreat starts and ends at a pause, a
gaze ends at one).

A plugin kind takes part through its ``synth`` part (:class:`SynthKindPart`). A plugin
kind without one, or with one that does not have that form, is left out of synthesis:
its statements are not written and its descriptors are not varied (synthesis composes
from the study's stimuli, which hold only the built-in kinds). Pure Python.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

from ..core import plugins as _plugins
from ..lang.descriptors import Descriptor, every_descriptor
from ..lang.ir import State
from ..lang.primitives import APPROACH, GAZE, PAUSE, RETREAT, SHIVER, TILT

__all__ = ["LAYER", "KindRecipe", "SynthKindPart", "descriptors",
           "kind_recipes", "pauses_needed", "slots", "span_of", "spans"]

#: The plugin part this registry reads.
LAYER = "synth"

Slot = tuple[str, str | None]


@runtime_checkable
class SynthKindPart(Protocol):
    """What a plugin's ``synth`` part gives (a module, an instance or a class will do).

    Attributes:
        spans: by state, how far intensity 1 moves each of the kind's descriptors, by
            episode key (``""`` for the count): a factor for a value (``x0 * r ** (d * (2 I
            - 1))``, ``d`` the descriptor's ``stronger`` sign), episodes added for a count.
            A descriptor is varied for a state only when it has a span there and its
            ``stronger`` names the state.

    Optional attributes (read with a default): ``planes``, the planes of its statements
    (default ``(None,)``: one statement); ``min_count``, the fewest episodes a varied
    count keeps (default 0); ``pauses``, a function of its episode count giving the
    pauses its episodes need around them (default: none).
    """

    spans: Mapping[State, Mapping[str, float]]


def _no_pauses(n: int) -> int:
    return 0


@dataclass(frozen=True)
class KindRecipe:
    """One kind's entry (the registry's form of a :class:`SynthKindPart`)."""

    spans: Mapping[State, Mapping[str, float]] = field(default_factory=dict)
    planes: tuple[str | None, ...] = (None,)
    min_count: int = 0
    pauses: Callable[[int], int] = _no_pauses


_C, _Cu, _H, _F = State.CONFIDENT, State.CURIOUS, State.HESITANT, State.FEARFUL
_A = "peak_acceleration"

#: The built-in kinds, in the order a descriptor-form file writes their statements. The
#: spans are chosen so that every intensity still reads as its state (the synthesis
#: tests check it).
BUILTIN: Mapping[str, KindRecipe] = {
    APPROACH: KindRecipe({_C: {_A: 1.5}, _Cu: {_A: 1.3}, _H: {_A: 1.4}, _F: {_A: 1.2}}),
    PAUSE: KindRecipe({_C: {"duration": 1.5}, _H: {"duration": 1.5},
                       _F: {"duration": 1.5, "": 2}}, min_count=1),
    RETREAT: KindRecipe({_H: {"distance": 1.5, "": 2}, _F: {"": 2}}, min_count=1,
                        pauses=lambda n: n + 1 if n else 0),
    GAZE: KindRecipe({_Cu: {"horizontal": 1.5, "vertical": 20.0}},
                     planes=("horizontal", "vertical"), pauses=lambda n: 1 if n else 0),
    TILT: KindRecipe({_Cu: {"angle": 30.0}}),
    SHIVER: KindRecipe(),
}


def from_part(part: object) -> KindRecipe | None:
    """The registry entry of a plugin's ``synth`` part, or None when it is not one."""
    spans = getattr(part, "spans", None)
    if not isinstance(spans, Mapping) or not all(
            isinstance(s, State) and isinstance(m, Mapping)
            and all(isinstance(k, str) and isinstance(v, int | float) for k, v in m.items())
            for s, m in spans.items()):
        return None
    planes = getattr(part, "planes", None) or (None,)
    min_count = getattr(part, "min_count", 0)
    pauses = getattr(part, "pauses", None) or _no_pauses
    if not isinstance(planes, tuple) or not isinstance(min_count, int) or not callable(pauses):
        return None
    return KindRecipe(spans, planes, min_count, pauses)


def kind_recipes() -> dict[str, KindRecipe]:
    """Every kind synthesis writes: the built-ins, then each loaded plugin's kind with a
    well-formed ``synth`` part (others are left out; a clash keeps the built-in)."""
    out = dict(BUILTIN)
    for p in _plugins.plugins():
        part = p.part(LAYER)
        entry = from_part(part) if part is not None and p.name not in out else None
        if entry is not None:
            out[p.name] = entry
    return out


def slots() -> tuple[Slot, ...]:
    """The statements of a descriptor-form file, by (kind, plane), in the order written."""
    return tuple((k, plane) for k, r in kind_recipes().items() for plane in r.planes)


def descriptors() -> tuple[Descriptor, ...]:
    """The descriptors synthesis reads and writes: the registry's, then the plugin
    kinds' that take part (those of a kind left out are not)."""
    kinds = kind_recipes()
    return tuple(d for d in every_descriptor().values() if d.kind in kinds)


def spans() -> dict[State, dict[tuple[str, str], float]]:
    """By state, the span of each descriptor, by its (kind, episode key)."""
    out: dict[State, dict[tuple[str, str], float]] = {}
    for kind, r in kind_recipes().items():
        for state, by_key in r.spans.items():
            row = out.setdefault(state, {})
            row.update({(kind, key): span for key, span in by_key.items()})
    return dict(sorted(out.items(), key=lambda i: list(State).index(i[0])))


def pauses_needed(count: Callable[[str, str | None], int]) -> int:
    """The pauses the episodes of a file need around them, ``count(kind, plane)`` the
    episodes of each statement."""
    return sum(r.pauses(sum(count(kind, plane) for plane in r.planes))
               for kind, r in kind_recipes().items())


def span_of(state: State, kind: str, key: str) -> float | None:
    """The span of the descriptor of ``kind`` read by ``key`` for ``state``, or None."""
    r = kind_recipes().get(kind)
    return r.spans.get(state, {}).get(key) if r is not None else None
