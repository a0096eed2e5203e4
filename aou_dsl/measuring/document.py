"""The header of a trajectory document (a JSON file, or an NPZ's ``header.json``): what
measuring reads besides the samples, validated field by field.

Files come from other tools and other people, so every field is checked and a wrong one
is named by its path (``goal.position.2``). Keys the format does not name are kept (the
format may grow; tools add their own). The samples (``t``, ``q``, ``qd``, ``qdd``) are
checked as arrays by the reader, not here: a minute at 1 kHz is 60 000 rows.
"""

from __future__ import annotations

import json
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from ..core.codes import R401
from ..core.diagnostics import AouError, Span, diag
from ..core.trajectory import FrameDefinition

__all__ = ["FORMAT", "MAX_GOAL", "Document", "FrameDef", "Goal", "Header", "RobotIdentity",
           "read_header"]

FORMAT = "aou-trajectory/1"
#: Furthest a goal coordinate may lie from the robot's base [m]: no arm reaches further,
#: and a goal in millimetres (550, 0, 250) is caught.
MAX_GOAL = 10.0
Finite = Annotated[float, Field(allow_inf_nan=False)]
# Numbers are JSON numbers: not booleans, not texts that look like numbers (strict).
Coordinate = Annotated[float, Field(strict=True, allow_inf_nan=False, ge=-MAX_GOAL,
                                    le=MAX_GOAL)]
Positive = Annotated[float, Field(strict=True, gt=0.0, allow_inf_nan=False)]


class Goal(BaseModel):
    """``{"position": [x, y, z]}`` in the robot's base frame [m]."""

    model_config = ConfigDict(extra="allow")

    position: tuple[Coordinate, Coordinate, Coordinate]


class FrameDef(BaseModel):
    """Where the end-effector frame is: welded to the URDF link ``parent`` at ``xyz``
    [m], turned by ``rpy`` [rad] (the URDF's roll, pitch, yaw). A link of the URDF is its
    own parent at zero."""

    model_config = ConfigDict(extra="allow")

    parent: str = Field(min_length=1)
    xyz: tuple[Finite, Finite, Finite]
    rpy: tuple[Finite, Finite, Finite]


class RobotIdentity(BaseModel):
    """Which robot: its name (as the ``robot`` key), the URDF's path as it was given (a
    built-in arm's: inside example-robot-data's ``robots`` folder) and the SHA-256 of the
    URDF's text (hex; empty when it could not be read)."""

    model_config = ConfigDict(extra="allow")

    name: str = Field(min_length=1)
    urdf: str
    sha256: str = Field(pattern=r"^([0-9a-f]{64})?$")


class Header(BaseModel):
    """The keys of a trajectory document that measuring uses."""

    model_config = ConfigDict(extra="allow")

    format: Literal["aou-trajectory/1"]
    robot: str = Field(min_length=1)
    joint_names: list[str] = Field(min_length=1, max_length=1000)
    behaviour: str | None = None
    state: str | None = None
    ee_frame: str | None = None
    goal: Goal | None = None
    generator: str = ""
    rate: Positive | None = None  # Hz, of a compiled file
    duration: Positive | None = None  # s
    ee_frame_definition: FrameDef | None = None
    robot_identity: RobotIdentity | None = None

    @field_validator("goal", mode="before")
    @classmethod
    def _bare_position(cls, value: Any) -> Any:
        """A goal written as the position alone (``[x, y, z]``) is read as one."""
        return {"position": value} if isinstance(value, list | tuple) else value

    @property
    def goal_position(self) -> tuple[float, float, float] | None:
        return None if self.goal is None else self.goal.position

    @property
    def frame_definition(self) -> FrameDefinition | None:
        """Where ``ee_frame`` is, when the file names the frame and defines it."""
        d = self.ee_frame_definition
        if d is None or not self.ee_frame:
            return None
        return FrameDefinition(self.ee_frame, d.parent, d.xyz, d.rpy)


Row = list[Finite]


class Episode(BaseModel):
    """One episode of the compiler's timeline [s]."""

    model_config = ConfigDict(extra="allow")

    kind: str
    t_start: Finite
    t_end: Finite


class Descriptors(BaseModel):
    """The declared and the measured descriptors, by name (null: absent)."""

    model_config = ConfigDict(extra="allow")

    declared: dict[str, Finite | None]
    measured: dict[str, Finite | None]


class Document(Header):
    """A whole trajectory document as ``aouc compile`` writes it (JSON; the NPZ's
    ``header.json`` is this but the samples). Its JSON Schema ships with the package
    (``aou_dsl/schemas/trajectory.schema.json``)."""

    behaviour: str
    state: str | None
    ee_frame: str
    goal: Goal
    generator: str
    rate: Positive
    duration: Positive
    ee_frame_definition: FrameDef
    robot_identity: RobotIdentity
    descriptors: Descriptors
    cv: dict[str, Any]
    episodes: list[Episode]
    checks: dict[str, Any]
    t: list[Finite] = Field(min_length=1)
    q: list[Row] = Field(min_length=1)
    qd: list[Row]
    qdd: list[Row]


def _message(errors: list[Any], doc: dict) -> str:
    """One sentence for pydantic's errors: missing keys together, then each field by its
    path, the format first (a document of another format has other keys)."""
    if any(e["loc"] == ("format",) for e in errors):
        return f"expected format `{FORMAT}`, found {doc.get('format')!r}"
    missing = [str(e["loc"][0]) for e in errors if e["type"] == "missing" and len(e["loc"]) == 1]
    if missing:
        return f"missing key(s): {', '.join(missing)}"
    parts = [f"`{'.'.join(str(x) for x in e['loc'])}`: {e['msg'].lower()}"
             for e in errors if e["loc"][0] != "goal"]
    if any(e["loc"][0] == "goal" for e in errors):  # one part for the goal, in aou's words
        found = json.dumps(doc.get("goal"))
        parts.insert(0, "`goal` must be {\"position\": [x, y, z]}, three finite numbers "
                        f"in metres within {MAX_GOAL:g} m of the base; found {found[:60]}"
                        f"{'...' if len(found) > 60 else ''}")
    more = f" (and {len(parts) - 3} more)" if len(parts) > 3 else ""
    return "; ".join(parts[:3]) + more


def _first(errors: list[Any]) -> tuple:
    """The path of the field the message leads with (:func:`_message`'s order); ``()``
    for missing keys."""
    if any(e["loc"] == ("format",) for e in errors):
        return ("format",)
    if any(e["type"] == "missing" and len(e["loc"]) == 1 for e in errors):
        return ()
    goal = [e for e in errors if e["loc"][0] == "goal"]
    return tuple((goal or errors)[0]["loc"])


def _span(path: str, text: str | None, loc: tuple) -> Span:
    """Where the field at ``loc`` is in the document ``text`` (its nearest enclosing
    field that is there; a missing key: the document's start)."""
    from .locate import json_span

    if text is not None:
        for n in range(len(loc), 0, -1):
            span = json_span(path, text, loc[:n])
            if span is not None:
                return span
    return Span.whole_file(path)


def read_header(path: str, doc: Any, *, own_goal: bool = True, text: str | None = None
                ) -> Header:
    """The validated header of ``doc``; R401 naming each wrong field (the diagnostic
    points at the first in ``text``, the document's JSON, when given). ``own_goal``
    False: the file's goal is not read (one given on the command line replaces it)."""
    if not isinstance(doc, dict):
        raise AouError(diag(R401, "a trajectory document is a JSON object",
                            Span.whole_file(path)))
    skip = ("t", "q", "qd", "qdd") if own_goal else ("t", "q", "qd", "qdd", "goal")
    fields = {k: v for k, v in doc.items() if k not in skip}
    try:
        header = Header.model_validate(fields)
    except ValidationError as exc:
        errors = exc.errors(include_url=False)
        raise AouError(diag(R401, _message(errors, doc), _span(path, text, _first(errors)),
                            fields=[".".join(str(x) for x in e["loc"]) for e in errors])
                       ) from None
    return header
