"""The intermediate representation: a validated behaviour, in SI units, every node spanned.

The primitive nodes live with their kinds in :mod:`aou_dsl.primitives`.

All models are frozen pydantic v2 models that reject unknown fields. Angles are in
radians, angular speeds in rad/s. Values a file leaves out are filled from
:data:`DEFAULTS` by the validator, so later stages never guess.
"""

from __future__ import annotations

import enum
import math
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from .diagnostics import Span

__all__ = ["DEFAULTS", "Behaviour", "Effort", "Node", "Settings", "State"]


class State(enum.StrEnum):
    """The five canonical states (docs/model.md), in their table's order (ties break by it)."""

    CONFIDENT = "confident"
    CURIOUS = "curious"
    HESITANT = "hesitant"
    FEARFUL = "fearful"
    INACTIVE = "inactive"


#: Documented defaults for everything a file may leave out (docs/language.md).
DEFAULTS = {
    "start": 0.30,  # m
    "standoff": 0.10,  # m
    "approach_a": 0.10,  # m/s^2
    "retreat_a": 0.10,  # m/s^2
    "speed_cap": 0.25,  # m/s, approach and retreat (ISO/TS 15066 "reduced speed")
    "gaze_v": math.radians(20.0),  # rad/s
    "tilt_v": math.radians(20.0),  # rad/s
    # 6 deg peak to peak at 2.5 Hz needs ~13 rad/s^2 on the shivering joint: within the
    # Panda's 20 rad/s^2 on joint 7. Faster tremors need smaller amplitudes.
    "shiver_f": 2.5,  # Hz
    "shiver_duration": 1.0,  # s
}


class Node(BaseModel):
    """An IR node: frozen, unknown fields rejected, spanned. Primitive nodes (one per kind,
    in :mod:`aou_dsl.primitives`) add ``kind`` and ``count``."""

    model_config = ConfigDict(frozen=True, extra="forbid", defer_build=True)

    span: Span
    kind: str = ""
    count: int = 1


class Effort(Node):
    """The Laban Effort vector (docs/model.md), each factor in [-1, 1]."""

    W: float = Field(ge=-1.0, le=1.0)
    T: float = Field(ge=-1.0, le=1.0)
    S: float = Field(ge=-1.0, le=1.0)
    F: float = Field(ge=-1.0, le=1.0)


class Settings(BaseModel):
    """The file's settings with defaults filled in; ``spans`` holds the written ones."""

    model_config = ConfigDict(frozen=True, extra="forbid", defer_build=True)

    robot: str = "panda"
    goal: tuple[float, float, float] | None = None  # None: the robot's default
    start_direction: tuple[float, float, float] | None = None  # unit vector or None
    start: float = DEFAULTS["start"]
    standoff: float = DEFAULTS["standoff"]
    effort: Effort | None = None
    spans: dict[str, Span] = Field(default_factory=dict)


class Behaviour(BaseModel):
    """One validated ``.aou`` file."""

    model_config = ConfigDict(frozen=True, extra="forbid", defer_build=True)

    name: str
    state: State | None
    form: Literal["descriptor", "sequence"]
    settings: Settings
    primitives: tuple[Node, ...]
    span: Span
    header_span: Span | None = None

    def first(self, kind: str, plane: str | None = None) -> Any:
        """The descriptor-form node of ``kind`` (and gaze ``plane``), if present. Typed
        ``Any``: the node class is the kind's (:mod:`aou_dsl.primitives`)."""
        for p in self.primitives:
            if p.kind == kind and (plane is None or getattr(p, "plane", None) == plane):
                return p
        return None
