"""Values written with so many significant digits: one rule, in three directions.

A fitted or suggested value is rounded *toward what fits*: down for a value under a
limit (a frequency, an acceleration, an amplitude), up for one that must be reached
(the duration of a shiver's 3 cycles), and to the nearest where neither binds (a
synthesized value). Rounding is monotone in each direction, so two values keep their
order (a variant pair its contrast). Pure Python.
"""

from __future__ import annotations

import math
from typing import Literal

__all__ = ["Toward", "significant", "step", "times", "written"]

Toward = Literal["down", "up", "nearest"]

#: A value exact in decimal but stored a little under it (2.2 as 2.19999...) keeps its
#: last digit: the quotient is nudged by this much toward the direction's side.
_FUZZ = 1e-9


def _exponent(x: float, digits: int) -> int:
    """The power of ten of the last of ``digits`` significant digits of ``x`` (> 0)."""
    return math.floor(math.log10(x)) - digits + 1


def step(x: float, digits: int) -> float:
    """One unit in the last of ``digits`` significant digits of ``x`` (> 0)."""
    return 10.0 ** _exponent(x, digits)


def significant(x: float, digits: int, toward: Toward = "down") -> float:
    """``x`` with ``digits`` significant digits, rounded ``toward`` (0.0 for ``x`` not
    positive or not finite, rounded down or up)."""
    if toward == "nearest":
        return float(f"{x:.{digits}g}")
    if not x > 0 or not math.isfinite(x):
        return 0.0
    unit = step(x, digits)
    q = math.floor(x / unit + _FUZZ) if toward == "down" else math.ceil(x / unit - _FUZZ)
    return round(q * unit, 12)


def written(x: float, digits: int, toward: Toward = "down") -> str:
    """:func:`significant` as a person writes it: no exponent, no trailing zeros
    (``x`` not positive: as it is, ``0``)."""
    if not x > 0:
        return f"{x:g}"
    e = _exponent(x, digits)
    text = f"{significant(x, digits, toward):.{max(0, -e)}f}"
    return text.rstrip("0").rstrip(".") if "." in text else text  # 1234000 keeps its zeros


def times(ratio: float) -> str:
    """A ratio to a limit as text, rounded up so that it never understates the excess:
    ``1.0004`` -> ``1.01``, ``15.51`` -> ``15.6``."""
    if ratio < 10.0:
        return f"{math.ceil(ratio * 100.0 - 1e-9) / 100.0:.2f}"
    return f"{math.ceil(ratio * 10.0 - 1e-9) / 10.0:.1f}"
