"""What the compiler refused, typed: the records the fit and the hints read.

The compiler's timing says why it could not time an episode as declared
(:class:`TimingFailure`); the compiler then refuses the file with one record per kind of
refusal (:class:`Unreachable`, :class:`ShiverTooFast`, :class:`TiltTooFast`,
:class:`AccelerationShort`), carried on its diagnostic (``Diagnostic.refusal``, made by
:func:`~aou_dsl.core.diagnostics.refused`). The diagnostic's ``fields``, the JSON a
script reads, are the record's values, in its order. Pure Python.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

from ..core.diagnostics import Diagnostic, Severity

__all__ = ["AccelerationShort", "Answer", "FixedByLanguage", "ShiverTooFast",
           "StartUnreachable", "TiltTooFast", "TimingFailure", "Unreachable", "answered",
           "answer_of", "first_error"]


@dataclass(frozen=True)
class TimingFailure:
    """Why an episode could not be timed as declared: ``reason`` names the binding
    constraint in words, ``joint`` the binding joint when it is one."""

    reason: str
    joint: str | None
    achieved: float | None = None
    wanted: float | None = None
    #: The limit exceeded (``velocity``, ``acceleration``, ``jerk``), when one is.
    limit: str | None = None


@dataclass(frozen=True)
class Unreachable:
    """C301-C303 at an episode: IK cannot follow its pose at ``time`` [s] (``reason``:
    ``unreachable``, ``joint_limit``, ``singularity``), ``joint`` the joint that binds."""

    reason: str
    time: float
    joint: str | None


@dataclass(frozen=True)
class StartUnreachable(Unreachable):
    """C301-C303 at the start pose (``time`` 0), ``start`` [m] from the goal."""

    start: float


@dataclass(frozen=True)
class ShiverTooFast:
    """C308: a shiver the ``joint`` follows only slower; ``max_frequency`` [Hz] the
    highest it follows (None: none that still looks like a shiver), ``duration`` [s] its
    ``for`` as written (None: none written), ``f`` [Hz] its declared frequency."""

    joint: str | None
    limit: str | None
    max_frequency: float | None
    duration: float | None
    f: float


@dataclass(frozen=True)
class TiltTooFast:
    """C309: a tilt the ``joint`` follows only slower; ``max_velocity`` [deg/s] the
    fastest it follows (None: none found), ``declared_velocity`` [deg/s] its own."""

    joint: str | None
    limit: str | None
    max_velocity: float | None
    declared_velocity: float


@dataclass(frozen=True)
class AccelerationShort:
    """C304: a move reaches only ``achieved`` of the ``declared`` peak acceleration
    (m/s^2 or rad/s^2) that sets ``descriptor``; ``joint`` the joint that binds."""

    joint: str | None
    achieved: float | None
    declared: float | None
    descriptor: str


@dataclass(frozen=True)
class FixedByLanguage:
    """C314: the fit's own refusal of a value the arm cannot give but no statement of
    ``kind`` may set: ``key`` is none of the kind's keys (``takes``), the language fixes
    the value (``declared``, in ``unit``), so the fit writes nothing there and the arm
    gives ``achieved``, ``joint`` the joint that binds (a gaze's acceleration)."""

    kind: str
    key: str
    takes: tuple[str, ...]
    declared: float | None
    achieved: float | None
    unit: str
    joint: str | None


def first_error(diagnostics: list[Diagnostic]) -> str:
    """The first error of ``diagnostics`` in words: its code, line and message."""
    d = next(x for x in diagnostics if x.severity is Severity.ERROR)
    return f"{d.code} at line {d.span.line} ({d.message})"


@dataclass(frozen=True)
class Answer:
    """What the fit found for a refusal (``Diagnostic.answer``).

    Attributes:
        offered: the changes that answer it, as records (``line``, ``col``, ``end_col``,
            ``key``, ``declared``, ``fitted``, ``unit``, ``bound``, ``joint``, ``limit``,
            ``descriptor``, ``statement``): field ``reach``.
        not_offered: why no angle or distance is offered (field ``reach_fit``).
        look: why no shiver the arm follows keeps the look (field ``look``).
        edits: the hint's text edits, every change the file needs (field ``edits``);
        edits_complete: whether the file then compiles (field ``edits_complete``).
    """

    offered: tuple[dict[str, Any], ...] = ()
    not_offered: str | None = None
    look: str | None = None
    edits: tuple[dict[str, Any], ...] = ()
    edits_complete: bool = True


#: The field of the diagnostic's JSON that says each part of an :class:`Answer`.
_FIELD = {"offered": "reach", "not_offered": "reach_fit", "look": "look",
          "edits": "edits", "edits_complete": "edits_complete"}


def answer_of(d: Diagnostic) -> Answer:
    """``d``'s answer (an empty one when the fit has said nothing of it)."""
    return d.answer if isinstance(d.answer, Answer) else Answer()


def answered(d: Diagnostic, hint: str | None, **parts: Any) -> Diagnostic:
    """``d`` with ``hint`` and the parts of its :class:`Answer` given (``offered=...``),
    said in its fields too (added after the others, in the order given)."""
    typed: dict[str, Any] = {k: tuple(v) if isinstance(v, list) else v
                             for k, v in parts.items()}
    return replace(d, hint=hint, answer=replace(answer_of(d), **typed),
                   fields={**d.fields, **{_FIELD[k]: v for k, v in parts.items()}})
