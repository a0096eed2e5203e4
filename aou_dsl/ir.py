"""The intermediate representation: a validated behaviour, in SI units, every node spanned.

All models are frozen pydantic v2 models that reject unknown fields. Angles are in
radians, angular speeds in rad/s. Values a file leaves out are filled from
:data:`DEFAULTS` by the validator, so later stages never guess.
"""

from __future__ import annotations

import enum
import math
from typing import Annotated, Literal, overload

from pydantic import BaseModel, ConfigDict, Field

from .diagnostics import Span

__all__ = [
    "DEFAULTS",
    "Approach",
    "Behaviour",
    "Effort",
    "Gaze",
    "Pause",
    "Primitive",
    "Retreat",
    "Settings",
    "Shiver",
    "State",
    "Tilt",
]


class State(enum.StrEnum):
    """The five canonical states of MODEL.md s2, in the table's order (ties break by it)."""

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


class _Node(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")

    span: Span


class Approach(_Node):
    """Translation toward the goal along the line of sight.

    ``length`` [m] is None for "the rest of the way to the standoff"; it may be negative in
    a sequence (moving away). ``a`` [m/s^2] is the peak acceleration, ``v`` [m/s] the cap.
    """

    kind: Literal["approach"] = "approach"
    length: float | None = None
    a: float
    v: float
    count: int = 1


class Pause(_Node):
    """A hold: every joint velocity zero for ``duration`` [s]."""

    kind: Literal["pause"] = "pause"
    duration: float
    count: int = 1


class Retreat(_Node):
    """Translation away from the goal by ``length`` [m] with peak acceleration ``a``."""

    kind: Literal["retreat"] = "retreat"
    length: float
    a: float
    v: float
    count: int = 1


class Gaze(_Node):
    """An arc about the goal in the horizontal or vertical plane.

    ``angle`` [rad] is the bearing of the goal vector from its start direction at the end
    of the episode (signed in a sequence; the amplitude in the descriptor form).
    """

    kind: Literal["gaze"] = "gaze"
    plane: Literal["horizontal", "vertical"]
    angle: float
    v: float
    count: int = 1


class Tilt(_Node):
    """A roll of ``angle`` [rad] about the forward axis at angular speed ``v`` [rad/s]."""

    kind: Literal["tilt"] = "tilt"
    angle: float
    v: float
    count: int = 1


class Shiver(_Node):
    """Oscillation of the redundant joint: ``amplitude`` [rad] peak to peak, at ``f`` [Hz]
    for ``duration`` [s]."""

    kind: Literal["shiver"] = "shiver"
    amplitude: float
    f: float
    duration: float
    count: int = 1


Primitive = Annotated[
    Approach | Pause | Retreat | Gaze | Tilt | Shiver, Field(discriminator="kind")
]


class Effort(_Node):
    """The Laban Effort vector of MODEL.md s1, each factor in [-1, 1]."""

    W: float = Field(ge=-1.0, le=1.0)
    T: float = Field(ge=-1.0, le=1.0)
    S: float = Field(ge=-1.0, le=1.0)
    F: float = Field(ge=-1.0, le=1.0)


class Settings(BaseModel):
    """The file's settings with defaults filled in; ``spans`` holds the written ones."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    robot: str = "panda"
    goal: tuple[float, float, float] | None = None  # None: the robot's default
    start_direction: tuple[float, float, float] | None = None  # unit vector or None
    start: float = DEFAULTS["start"]
    standoff: float = DEFAULTS["standoff"]
    effort: Effort | None = None
    spans: dict[str, Span] = Field(default_factory=dict)


class Behaviour(BaseModel):
    """One validated ``.aou`` file."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    name: str
    state: State | None
    form: Literal["descriptor", "sequence"]
    settings: Settings
    primitives: tuple[Primitive, ...]
    span: Span
    header_span: Span | None = None

    @overload
    def first(self, kind: Literal["approach"], plane: None = None) -> Approach | None: ...
    @overload
    def first(self, kind: Literal["pause"], plane: None = None) -> Pause | None: ...
    @overload
    def first(self, kind: Literal["retreat"], plane: None = None) -> Retreat | None: ...
    @overload
    def first(self, kind: Literal["gaze"], plane: str | None = None) -> Gaze | None: ...
    @overload
    def first(self, kind: Literal["tilt"], plane: None = None) -> Tilt | None: ...
    @overload
    def first(self, kind: Literal["shiver"], plane: None = None) -> Shiver | None: ...
    @overload
    def first(self, kind: str, plane: str | None = None) -> Primitive | None: ...

    def first(self, kind: str, plane: str | None = None) -> Primitive | None:
        """The descriptor-form primitive of ``kind`` (and gaze ``plane``), if present."""
        for p in self.primitives:
            if p.kind == kind and (plane is None or getattr(p, "plane", None) == plane):
                return p
        return None
