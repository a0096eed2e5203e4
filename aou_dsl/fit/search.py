"""The largest value that fits: what the compiler suggests when a declared value asks
too much.

A suggestion (the highest shiver frequency, or tilt velocity, that the joints can follow)
is rounded *down* to two significant digits (:mod:`~aou_dsl.fit.rounding`), a value a
person writes, and then checked by the same check that refused the declared value: a
hint that fails when applied is worse than none. Pure Python.
"""

from __future__ import annotations

from collections.abc import Callable

from .rounding import significant, step

__all__ = ["DIGITS", "largest_fitting"]

#: Significant digits of a suggested value.
DIGITS = 2


def _next(x: float, digits: int) -> float:
    """The next value of ``digits`` significant digits above ``x`` (one of them)."""
    return significant(x + step(x, digits) * 1.000001, digits)


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
    x = significant(min(estimate, below * (1.0 - 1e-9)), digits)
    factor = 0.97
    for _ in range(tries):
        if x <= 0.0:
            return None
        if fits(x):
            break
        x = significant(min(x - step(x, digits), x * factor), digits)
        factor *= factor
    else:
        return None
    above: list[float] = []
    y = _next(x, digits)
    while y < below * (1.0 - 1e-9) and len(above) < 1000:
        above.append(y)
        y = _next(y, digits)
    lo, hi = -1, len(above)  # above[lo] fits (x when lo = -1), above[hi] fails (below)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if fits(above[mid]):
            lo = mid
        else:
            hi = mid
    return above[lo] if lo >= 0 else x
