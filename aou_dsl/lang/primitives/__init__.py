"""The primitive kinds of the language, one module each, and their registry.

A new kind is one new module (a :class:`~.base.Kind` subclass and its IR node) and one
line in :data:`KINDS`.
"""

from __future__ import annotations

from .approach import Approach, ApproachKind
from .gaze import GAZE_ANGULAR_ACCEL, Gaze, GazeKind
from .kind import MIN_ANGLE, MIN_PAUSE, MIN_RETREAT, Kind
from .pause import Pause, PauseKind
from .retreat import Retreat, RetreatKind
from .shiver import MIN_SHIVER_F, Shiver, ShiverKind, shiver_duration
from .tilt import Tilt, TiltKind

__all__ = [
    "GAZE_ANGULAR_ACCEL",
    "KINDS",
    "MIN_ANGLE",
    "MIN_PAUSE",
    "MIN_RETREAT",
    "MIN_SHIVER_F",
    "Approach",
    "Gaze",
    "Kind",
    "Pause",
    "Retreat",
    "Shiver",
    "Tilt",
    "kind_of",
    "shiver_duration",
]

#: Every primitive kind, by statement keyword.
KINDS: dict[str, Kind] = {k.name: k for k in (
    ApproachKind(), PauseKind(), RetreatKind(), GazeKind(), TiltKind(), ShiverKind(),
)}


def kind_of(node) -> Kind:
    """The kind object of an IR node (or of an episode's ``kind``)."""
    return KINDS[node if isinstance(node, str) else node.kind]
