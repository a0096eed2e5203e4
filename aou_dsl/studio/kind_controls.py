"""The studio's controls of each primitive kind: one registry keyed by kind.

For every kind: the colour its episodes are drawn in (the hand's path, the timeline's
bands; those of ``aouc plot``) and, for every descriptor read from its episodes, a slider
(the range by the descriptor's unit, :data:`RANGES`, widened to hold the file's value).

A plugin kind gets a slider for each of its descriptors (its plugin's ``descriptors``
part, through :func:`descriptors`) and the colour of its ``studio`` part
(:class:`StudioKindPart`); without one, or with one that does not have that form, its
episodes are drawn in :data:`DEFAULT_COLOUR`, the grey of anything not a kind. A slider
of a plugin descriptor takes its part's ``ranges``, else the range of its unit, else
:data:`DEFAULT_RANGE`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

from ..core import plugins as _plugins
from ..lang.descriptors import REGISTRY, Descriptor, every_descriptor
from ..lang.primitives import APPROACH, GAZE, KINDS, PAUSE, RETREAT, SHIVER, TILT

__all__ = ["DEFAULT_COLOUR", "DEFAULT_RANGE", "EPISODE_COLOURS", "LAYER", "RANGES",
           "KindControls", "StudioKindPart", "colour_of", "descriptor_of", "descriptors",
           "kind_controls", "range_of"]

#: The plugin part this registry reads.
LAYER = "studio"

RGB = tuple[int, int, int]
Range = tuple[float, float, float]

#: What is drawn for an episode of no kind, or of a plugin kind that gives no colour.
DEFAULT_COLOUR: RGB = (180, 180, 180)
#: The slider of a descriptor whose unit has no range and whose plugin gives none.
DEFAULT_RANGE: Range = (0.0, 1.0, 0.01)

#: Slider ranges by the descriptor's unit (counts: ""): (low, high, step).
RANGES: dict[str, Range] = {
    "": (0, 10, 1),
    "s": (0.2, 5.0, 0.01),
    "m": (0.005, 0.2, 0.005),
    "m/s^2": (0.01, 3.0, 0.01),
    "deg": (1.0, 60.0, 0.5),
    "deg/s": (5.0, 180.0, 1.0),
}


@runtime_checkable
class StudioKindPart(Protocol):
    """What a plugin's ``studio`` part gives (a module, an instance or a class will do).

    Attributes:
        colour: its episodes' colour, RGB 0-255, e.g. ``(120, 80, 40)``.

    Optional attribute (read with a default): ``ranges``, the slider of each of its
    descriptors, by descriptor name, as ``(low, high, step)`` (default: by unit).
    """

    colour: RGB


@dataclass(frozen=True)
class KindControls:
    """One kind's entry (the registry's form of a :class:`StudioKindPart`)."""

    colour: RGB
    ranges: Mapping[str, Range] = field(default_factory=dict)


#: The built-in kinds.
BUILTIN: Mapping[str, KindControls] = {
    APPROACH: KindControls((76, 154, 42)), RETREAT: KindControls((192, 57, 43)),
    PAUSE: KindControls((149, 165, 166)), GAZE: KindControls((46, 134, 193)),
    TILT: KindControls((142, 68, 173)), SHIVER: KindControls((230, 126, 34)),
}


def _byte(x: object) -> bool:
    return isinstance(x, int) and not isinstance(x, bool) and 0 <= x <= 255


def _range(x: object) -> bool:
    return isinstance(x, tuple) and len(x) == 3 and all(
        isinstance(v, int | float) and not isinstance(v, bool) for v in x) and x[0] < x[1]


def from_part(part: object) -> KindControls | None:
    """The registry entry of a plugin's ``studio`` part, or None when it is not one."""
    colour = getattr(part, "colour", None)
    ranges = getattr(part, "ranges", None) or {}
    if not (isinstance(colour, tuple) and len(colour) == 3 and all(map(_byte, colour))):
        return None
    if not isinstance(ranges, Mapping) or not all(
            isinstance(k, str) and _range(v) for k, v in ranges.items()):
        return None
    return KindControls(colour, dict(ranges))  # type: ignore[arg-type]


def _plugin(name: str) -> KindControls:
    part = _plugins.part(name, LAYER)
    found = from_part(part) if part is not None else None
    return found or KindControls(DEFAULT_COLOUR)


def kind_controls() -> dict[str, KindControls]:
    """Every kind's controls: the built-ins, then each other kind of ``KINDS`` (a
    plugin's) from its ``studio`` part, or the default."""
    out = dict(BUILTIN)
    for name in KINDS:
        if name not in out:
            out[name] = _plugin(name)
    return out


#: The built-in kinds' colours, RGB 0-255.
EPISODE_COLOURS: dict[str, RGB] = {k: c.colour for k, c in BUILTIN.items()}


def colour_of(kind: str) -> RGB:
    """The colour of ``kind``'s episodes (:data:`DEFAULT_COLOUR` for no kind)."""
    found = BUILTIN.get(kind)
    if found is not None:
        return found.colour
    return _plugin(kind).colour if kind in KINDS else DEFAULT_COLOUR


def descriptors() -> dict[str, Descriptor]:
    """Every descriptor a slider may set: the registry's, then the loaded plugins'."""
    return {d.name: d for d in every_descriptor().values()}


def descriptor_of(name: str) -> Descriptor:
    """The descriptor ``name`` (a registry's or a plugin's); KeyError when none."""
    found = REGISTRY.get(name)
    return found if found is not None else descriptors()[name]


def range_of(name: str) -> Range:
    """The slider of descriptor ``name``: its plugin's, else by its unit, else the
    default."""
    d = descriptor_of(name)
    own = _plugin(d.kind).ranges.get(name) if d.kind not in BUILTIN else None
    return own or RANGES.get(d.unit, DEFAULT_RANGE)
