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

from ..core.diagnostics import AouError, Span, diag

__all__ = ["FORMAT", "Goal", "Header", "read_header"]

FORMAT = "aou-trajectory/1"
Finite = Annotated[float, Field(allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0.0, allow_inf_nan=False)]


class Goal(BaseModel):
    """``{"position": [x, y, z]}`` in the robot's base frame [m]."""

    model_config = ConfigDict(extra="allow")

    position: tuple[Finite, Finite, Finite]


class Header(BaseModel):
    """The keys of a trajectory document that measuring uses."""

    model_config = ConfigDict(extra="allow")

    format: Literal["aou-trajectory/1"]
    robot: str = Field(min_length=1)
    joint_names: list[str] = Field(min_length=1)
    behaviour: str | None = None
    state: str | None = None
    ee_frame: str | None = None
    goal: Goal | None = None
    generator: str = ""
    rate: Positive | None = None  # Hz, of a compiled file
    duration: Positive | None = None  # s

    @field_validator("goal", mode="before")
    @classmethod
    def _bare_position(cls, value: Any) -> Any:
        """A goal written as the position alone (``[x, y, z]``) is read as one."""
        return {"position": value} if isinstance(value, list | tuple) else value

    @property
    def goal_position(self) -> tuple[float, float, float] | None:
        return None if self.goal is None else self.goal.position


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
                        f"in metres; found {found[:60]}{'...' if len(found) > 60 else ''}")
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
        raise AouError(diag("R401", "a trajectory document is a JSON object",
                            Span.whole_file(path)))
    skip = ("t", "q", "qd", "qdd") if own_goal else ("t", "q", "qd", "qdd", "goal")
    fields = {k: v for k, v in doc.items() if k not in skip}
    try:
        header = Header.model_validate(fields)
    except ValidationError as exc:
        errors = exc.errors(include_url=False)
        raise AouError(diag("R401", _message(errors, doc), _span(path, text, _first(errors)),
                            fields=[".".join(str(x) for x in e["loc"]) for e in errors])
                       ) from None
    return header
