"""The descriptors a behaviour declares.

Descriptor form: the values written in the file (the layout must show them; validation
refuses a file whose layout cannot). Sequence form: the descriptors of the laid-out
timeline, derived exactly as ``aouc measure`` derives them from motion.
"""

from __future__ import annotations

from typing import Any

from .descriptors import Descriptors, derive, every_descriptor
from .ir import Behaviour
from .layout import episode_values
from .primitives import GAZE, KINDS
from .timeline import Timeline

__all__ = ["declared", "source_of", "written"]


def source_of(b: Behaviour, name: str) -> Any:
    """The descriptor-form statement that sets descriptor ``name`` (None when absent): a
    gaze's descriptors are one per plane, every other kind's one per kind."""
    d = every_descriptor()[name]
    return b.first(d.kind, d.key if d.kind == GAZE else None)


def written(b: Behaviour) -> Descriptors:
    """The descriptor form's values as written; counts of absent kinds are zero. Every
    descriptor (a plugin kind's too) is read from its kind's node by the kind itself."""
    out: dict[str, float | int | None] = {}
    for name, d in every_descriptor().items():
        node = source_of(b, name)
        if node is None or node.count == 0:
            out[name] = 0 if d.is_count else None
        elif d.is_count:
            out[name] = node.count
        else:
            out[name] = KINDS[d.kind].values(node)[d.key]
    return Descriptors(out)


def declared(b: Behaviour, timeline: Timeline) -> Descriptors:
    """What the behaviour declares (see the module's docstring)."""
    if b.form == "descriptor":
        return written(b)
    return derive(episode_values(timeline.episodes))
