"""What the compiler refused, typed: the records the fit and the hints read.

The compiler's timing says why it could not time an episode as declared
(:class:`TimingFailure`). Pure Python.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..core.diagnostics import Diagnostic, Severity

__all__ = ["TimingFailure", "first_error"]


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


def first_error(diagnostics: list[Diagnostic]) -> str:
    """The first error of ``diagnostics`` in words: its code, line and message."""
    d = next(x for x in diagnostics if x.severity is Severity.ERROR)
    return f"{d.code} at line {d.span.line} ({d.message})"
