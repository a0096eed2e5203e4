"""Values that fit: what the compiler suggests when a declared value asks too much.

A suggestion (the highest shiver frequency, or tilt velocity, that the joints can follow)
is rounded *down* to two significant digits, a value a person writes, and then checked
by the same check that refused the declared value: a hint that fails when applied is
worse than none. Pure Python.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

__all__ = ["TimingFailure", "floor_sig", "largest_fitting", "times"]

#: Significant digits of a suggested value.
DIGITS = 2


def _unit(x: float, digits: int) -> float:
    """One unit in the last of ``digits`` significant digits of ``x`` (> 0)."""
    return 10.0 ** (math.floor(math.log10(x)) - digits + 1)


def floor_sig(x: float, digits: int = DIGITS) -> float:
    """``x`` rounded down to ``digits`` significant digits (0 for ``x <= 0``)."""
    if not x > 0 or not math.isfinite(x):
        return 0.0
    unit = _unit(x, digits)
    # The fuzz keeps an exact value (2.2 stored as 2.19999...) from dropping a digit; the
    # result is printed with `:g`, so it is rounded to the unit again.
    return round(math.floor(x / unit + 1e-9) * unit, 12)


def _up(x: float, digits: int) -> float:
    """The next value of ``digits`` significant digits above ``x`` (one of them)."""
    return floor_sig(x + _unit(x, digits) * 1.000001, digits)


def largest_fitting(estimate: float, fits: Callable[[float], bool], *, below: float,
                    digits: int = DIGITS, tries: int = 12) -> float | None:
    """The largest value of ``digits`` significant digits under ``below`` (the value that
    was refused) that ``fits``, or None when none is found.

    The search starts at ``estimate`` rounded down (from how the peaks scale with the
    value: usually the answer) and steps down until a value fits, by 3 %, then by twice
    as much each time (a few steps reach any small value); then, since
    that value may be lower than needed, it bisects the values between it and ``below``.
    ``fits`` is assumed to hold below some value and fail above it; whatever it does,
    the result is a value it accepted."""
    x = floor_sig(min(estimate, below * (1.0 - 1e-9)), digits)
    factor = 0.97
    for _ in range(tries):
        if x <= 0.0:
            return None
        if fits(x):
            break
        x = floor_sig(min(x - _unit(x, digits), x * factor), digits)
        factor *= factor
    else:
        return None
    above: list[float] = []
    y = _up(x, digits)
    while y < below * (1.0 - 1e-9) and len(above) < 1000:
        above.append(y)
        y = _up(y, digits)
    lo, hi = -1, len(above)  # above[lo] fits (x when lo = -1), above[hi] fails (below)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if fits(above[mid]):
            lo = mid
        else:
            hi = mid
    return above[lo] if lo >= 0 else x


def times(ratio: float) -> str:
    """A ratio to a limit as text, rounded up so that it never understates the excess:
    ``1.0004`` -> ``1.01``, ``15.51`` -> ``15.6``."""
    if ratio < 10.0:
        return f"{math.ceil(ratio * 100.0 - 1e-9) / 100.0:.2f}"
    return f"{math.ceil(ratio * 10.0 - 1e-9) / 10.0:.1f}"


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
