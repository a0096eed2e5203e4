"""What the editor says about each primitive kind: one registry keyed by kind.

For every kind, :class:`KindTexts` gives what completion and hover need beyond the kind
object itself (whose ``usage`` and ``keys`` they already read): the dimension of the
statement's positional quantity (the units offered after a bare number), the planes
that follow the keyword (a gaze's ``horizontal``/``vertical``), other words the
statement takes with the dimension of the quantity after each (a shiver's ``for``), how
hover shows one planned episode, and hover texts of descriptors the registry does not
define.

A plugin kind takes part through its ``editor`` part (:class:`EditorKindPart`). Without
one, or with one that does not have that form, the editor still completes its keyword
and keys from the kind object (:data:`aou_dsl.lang.primitives.KINDS`): the positional
quantity's dimension is read from the placeholder of its ``usage`` (``LENGTH``,
``DURATION``, ``ANGLE``...), else every unit is offered.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable

from ..core import plugins as _plugins
from ..core.units import Dim
from ..lang.primitives import APPROACH, GAZE, KINDS, PAUSE, RETREAT, SHIVER, TILT

__all__ = ["LAYER", "EditorKindPart", "KindTexts", "definition", "kind_texts", "texts_of"]

#: The plugin part this registry reads.
LAYER = "editor"


@runtime_checkable
class EditorKindPart(Protocol):
    """What a plugin's ``editor`` part gives (a module, an instance or a class will do).

    Attributes:
        positional: the dimension (:class:`aou_dsl.core.units.Dim`) of the statement's
            positional quantity, or None when it takes none.

    Optional attributes (read with a default): ``planes``, words that may follow the
    keyword (default none); ``words``, other words the statement takes, each with its
    completion detail (default none); ``word_dims``, the dimension of the quantity after
    each of those words (default none); ``definitions``, the hover text of each of the
    plugin's descriptors, by descriptor name (default: a generic line).
    """

    positional: Dim | None


def _nothing(ep: Any) -> str:
    return ""


def _oscillation(ep: Any) -> str:
    return f": {math.degrees(ep.amplitude):.3g} deg at {ep.f:g} Hz"


@dataclass(frozen=True)
class KindTexts:
    """One kind's entry (the registry's form of an :class:`EditorKindPart`).

    ``planned`` is the hover's text of a planned episode that is not a plain move (None:
    the move's peak speed and acceleration)."""

    positional: Dim | None
    planes: tuple[str, ...] = ()
    words: Mapping[str, str] = field(default_factory=dict)
    word_dims: Mapping[str, Dim] = field(default_factory=dict)
    definitions: Mapping[str, str] = field(default_factory=dict)
    planned: Callable[[Any], str] | None = None


#: The built-in kinds.
BUILTIN: Mapping[str, KindTexts] = {
    APPROACH: KindTexts(Dim.LENGTH),
    PAUSE: KindTexts(Dim.TIME, planned=_nothing),
    RETREAT: KindTexts(Dim.LENGTH),
    GAZE: KindTexts(Dim.ANGLE, planes=("horizontal", "vertical")),
    TILT: KindTexts(Dim.ANGLE),
    SHIVER: KindTexts(Dim.ANGLE, words={"for": "for DURATION: how long it shivers"},
                      word_dims={"for": Dim.TIME}, planned=_oscillation),
}

#: The placeholders of a kind's ``usage`` that name its positional quantity's dimension.
_PLACEHOLDERS = {"LENGTH": Dim.LENGTH, "DIST": Dim.LENGTH, "DISTANCE": Dim.LENGTH,
                 "DURATION": Dim.TIME, "TIME": Dim.TIME, "ANGLE": Dim.ANGLE}


def _from_usage(usage: str) -> Dim | None:
    for word in usage.split()[1:]:
        found = _PLACEHOLDERS.get(word.strip("[]"))
        if found is not None:
            return found
    return None


def _words(x: object) -> bool:
    return isinstance(x, Mapping) and all(isinstance(k, str) for k in x)


def from_part(part: object) -> KindTexts | None:
    """The registry entry of a plugin's ``editor`` part, or None when it is not one."""
    positional = getattr(part, "positional", None)
    planes = tuple(getattr(part, "planes", None) or ())
    words = getattr(part, "words", None) or {}
    dims = getattr(part, "word_dims", None) or {}
    defs = getattr(part, "definitions", None) or {}
    if positional is not None and not isinstance(positional, Dim):
        return None
    if not all(isinstance(p, str) for p in planes) or not all(map(_words, (words, dims,
                                                                            defs))):
        return None
    if not all(isinstance(d, Dim) for d in dims.values()):
        return None
    return KindTexts(positional, planes, dict(words), dict(dims),
                     {k: str(v) for k, v in defs.items()})


def _plugin_texts(name: str, kind: Any) -> KindTexts:
    part = _plugins.part(name, LAYER)
    found = from_part(part) if part is not None else None
    return found or KindTexts(_from_usage(getattr(kind, "usage", "")))


def kind_texts() -> dict[str, KindTexts]:
    """Every kind's texts: the built-ins, then each other kind of ``KINDS`` (a plugin's)
    from its ``editor`` part, or from the kind object alone."""
    out = dict(BUILTIN)
    for name, kind in KINDS.items():
        if name not in out:
            out[name] = _plugin_texts(name, kind)
    return out


def texts_of(keyword: str) -> KindTexts | None:
    """The texts of the kind ``keyword``; None when it is no kind."""
    found = BUILTIN.get(keyword)
    if found is not None:
        return found
    kind = KINDS.get(keyword)
    return _plugin_texts(keyword, kind) if kind is not None else None


def definition(name: str, kind: str) -> str:
    """The hover text of a descriptor the registry does not define: its plugin's, or a
    line saying whose it is."""
    texts = texts_of(kind)
    found = texts.definitions.get(name) if texts is not None else None
    return found or f"a descriptor of `{kind}` episodes (from its plugin)"
