"""How each kind's episodes look in plots: their colour and label, keyed by kind.

The built-in kinds have the colours below. A plugin kind (an ``aou.kinds`` entry point,
:mod:`aou_dsl.core.plugins`) gives its own with its ``media`` part, a
:class:`MediaPart`; a plugin that gives none, or a colour that is not ``#rrggbb``, is
drawn in :data:`DEFAULT_COLOUR` and labelled by its keyword. Pure Python: no plotting
imports.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Protocol

from ..core import plugins as _plugins
from ..lang.primitives import APPROACH, GAZE, PAUSE, RETREAT, SHIVER, TILT

__all__ = ["BUILTIN", "DEFAULT_COLOUR", "LAYER", "Label", "MediaPart", "label_of", "labels"]

#: The layer name under which a plugin gives its part.
LAYER = "media"
#: The colour of a kind that gives none (a light grey: shaded episodes stay readable).
DEFAULT_COLOUR = "#dddddd"
_HEX = re.compile(r"#[0-9a-fA-F]{6}")


class MediaPart(Protocol):
    """What a plugin's ``media`` part may give: ``colour``, the ``#rrggbb`` its episodes
    are shaded in, and ``label``, the word shown on them (its keyword when it gives
    none). Either may be missing; a module with these two names will do."""

    colour: str
    label: str


@dataclass(frozen=True, slots=True)
class Label:
    """How one kind's episodes are drawn: ``colour`` (``#rrggbb``) and ``label``."""

    kind: str
    colour: str
    label: str


#: The built-in kinds' colours and labels.
BUILTIN: dict[str, Label] = {k: Label(k, c, k) for k, c in (
    (APPROACH, "#4c9a2a"), (RETREAT, "#c0392b"), (PAUSE, "#95a5a6"),
    (GAZE, "#2e86c1"), (TILT, "#8e44ad"), (SHIVER, "#e67e22"),
)}


def _plugin_label(kind: str, part: object) -> Label:
    colour = getattr(part, "colour", None)
    label = getattr(part, "label", None)
    return Label(kind,
                 colour if isinstance(colour, str) and _HEX.fullmatch(colour) else
                 DEFAULT_COLOUR,
                 label if isinstance(label, str) and label.strip() else kind)


def labels() -> dict[str, Label]:
    """Every kind's colour and label: the built-ins, then each loaded plugin kind's (a
    built-in's keyword is never taken over)."""
    out = dict(BUILTIN)
    for p in _plugins.plugins():
        if p.name not in out:
            out[p.name] = _plugin_label(p.name, p.part(LAYER))
    return out


def label_of(kind: str) -> Label:
    """How episodes of ``kind`` are drawn; a kind nothing knows gets the default colour
    and its own name."""
    return labels().get(kind) or Label(kind, DEFAULT_COLOUR, kind)
