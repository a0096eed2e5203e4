"""What the compiler refused, typed: the records the fit and the hints read.

The compiler's timing says why it could not time an episode as declared
(:class:`TimingFailure`). Pure Python.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["TimingFailure"]


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
