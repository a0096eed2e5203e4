"""The primitive kinds of the language, one module each, and their registry.

A new kind is one new module (a :class:`~.base.Kind` subclass and its IR node) and one
line in :data:`KINDS`.
"""

from __future__ import annotations

from .approach import Approach, ApproachKind
from .gaze import GAZE_ANGULAR_ACCEL, Gaze, GazeKind
from .kind import LOOK_SLACK, MIN_ANGLE, MIN_PAUSE, MIN_RETREAT, Kind, Timing
from .pause import Pause, PauseKind
from .retreat import Retreat, RetreatKind
from .shiver import LOOK_SHIVER_F, MIN_SHIVER_F, VISIBLE_SHIVER, Shiver, ShiverKind, shiver_duration
from .tilt import Tilt, TiltKind

__all__ = [
    "APPROACH",
    "GAZE",
    "GAZE_ANGULAR_ACCEL",
    "KINDS",
    "LOOK_SHIVER_F",
    "LOOK_SLACK",
    "MIN_ANGLE",
    "MIN_PAUSE",
    "MIN_RETREAT",
    "MIN_SHIVER_F",
    "PAUSE",
    "RETREAT",
    "SHIVER",
    "TILT",
    "Approach",
    "Gaze",
    "Kind",
    "Timing",
    "Pause",
    "Retreat",
    "Shiver",
    "Tilt",
    "VISIBLE_SHIVER",
    "kind_of",
    "look_changed",
    "shiver_duration",
]

#: The built-in kinds' keywords as the kinds themselves spell them. Every other module
#: names a kind through these (or a kind object's ``name``), never by a string literal:
#: ``tests/test_kind_names.py`` fails on one.
APPROACH, PAUSE, RETREAT, GAZE, TILT, SHIVER = (
    ApproachKind.name, PauseKind.name, RetreatKind.name, GazeKind.name, TiltKind.name,
    ShiverKind.name)

#: Every primitive kind, by statement keyword.
KINDS: dict[str, Kind] = {k.name: k for k in (
    ApproachKind(), PauseKind(), RetreatKind(), GazeKind(), TiltKind(), ShiverKind(),
)}


def look_changed(declared, fitted) -> str | None:
    """Why the episodes ``fitted`` (a fitted file's timeline) do not look like
    ``declared`` (the file's as written), episode by episode by each kind's own
    invariant (:meth:`Kind.keeps_look`), or None when every one keeps its look."""
    if len(declared) != len(fitted):
        return f"it would have {len(fitted)} episodes, not {len(declared)}"
    for d, f in zip(declared, fitted, strict=True):
        why = KINDS[d.kind].keeps_look(d, f)
        if why is not None:
            return why
    return None


def kind_of(node) -> Kind:
    """The kind object of an IR node (or of an episode's ``kind``)."""
    return KINDS[node if isinstance(node, str) else node.kind]
