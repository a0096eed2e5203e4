"""What the compiler refused, typed: the records the fit and the hints read.

The compiler's timing says why it could not time an episode as declared
(:class:`TimingFailure`); the compiler then refuses the file with one record per kind of
refusal (:class:`Unreachable`, :class:`ShiverTooFast`, :class:`TiltTooFast`,
:class:`AccelerationShort`), carried on its diagnostic (``Diagnostic.refusal``, made by
:func:`~aou_dsl.core.diagnostics.refused`). The diagnostic's ``fields``, the JSON a
script reads, are the record's values, in its order. Pure Python.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..core.diagnostics import Diagnostic, Severity

__all__ = ["AccelerationShort", "ShiverTooFast", "StartUnreachable", "TiltTooFast",
           "TimingFailure", "Unreachable", "first_error"]


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


def first_error(diagnostics: list[Diagnostic]) -> str:
    """The first error of ``diagnostics`` in words: its code, line and message."""
    d = next(x for x in diagnostics if x.severity is Severity.ERROR)
    return f"{d.code} at line {d.span.line} ({d.message})"
