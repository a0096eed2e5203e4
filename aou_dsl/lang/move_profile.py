"""Rest-to-rest motion profiles: the time a move takes under a peak acceleration and a
speed cap. Pure maths, shared by validation (resource bounds) and the layout."""

from __future__ import annotations

import math

__all__ = ["bang_time"]


def bang_time(length: float, a: float, vmax: float) -> float:
    """Rest-to-rest time [s] over ``length`` [m or rad] at peak acceleration ``a`` and
    speed cap ``vmax``: a triangular velocity profile, or a trapezoid once the cap is
    reached."""
    length = abs(length)
    if length == 0.0:
        return 0.0
    if length * a <= vmax * vmax:
        return 2.0 * math.sqrt(length / a)
    return length / vmax + vmax / a
