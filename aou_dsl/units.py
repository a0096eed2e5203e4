"""Units of the language: every quantity becomes an SI float with a checked dimension.

Angles are stored in radians, angular speeds in rad/s; output converts to degrees
where the descriptors are in degrees.
"""

from __future__ import annotations

import enum
import math
import re

__all__ = ["Dim", "UNITS", "parse_quantity", "units_for"]


class Dim(enum.StrEnum):
    """A physical dimension and the noun used for it in messages."""

    LENGTH = "length"
    TIME = "duration"
    ANGLE = "angle"
    SPEED = "speed"
    ACCEL = "acceleration"
    ANGULAR_SPEED = "angular speed"
    FREQUENCY = "frequency"


#: unit -> (dimension, factor to SI). Angles in rad.
UNITS: dict[str, tuple[Dim, float]] = {
    "m": (Dim.LENGTH, 1.0),
    "cm": (Dim.LENGTH, 1e-2),
    "mm": (Dim.LENGTH, 1e-3),
    "s": (Dim.TIME, 1.0),
    "ms": (Dim.TIME, 1e-3),
    "deg": (Dim.ANGLE, math.pi / 180.0),
    "rad": (Dim.ANGLE, 1.0),
    "m/s": (Dim.SPEED, 1.0),
    "cm/s": (Dim.SPEED, 1e-2),
    "mm/s": (Dim.SPEED, 1e-3),
    "m/s^2": (Dim.ACCEL, 1.0),
    "cm/s^2": (Dim.ACCEL, 1e-2),
    "mm/s^2": (Dim.ACCEL, 1e-3),
    "deg/s": (Dim.ANGULAR_SPEED, math.pi / 180.0),
    "rad/s": (Dim.ANGULAR_SPEED, 1.0),
    "Hz": (Dim.FREQUENCY, 1.0),
}

#: The SI unit a bare keyword value takes, per dimension .
SI_UNIT: dict[Dim, str] = {
    Dim.LENGTH: "m",
    Dim.TIME: "s",
    Dim.ANGLE: "rad",
    Dim.SPEED: "m/s",
    Dim.ACCEL: "m/s^2",
    Dim.ANGULAR_SPEED: "rad/s",
    Dim.FREQUENCY: "Hz",
}

_QUANTITY = re.compile(r"^([+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?)(.*)$")


def parse_quantity(text: str) -> tuple[float, str]:
    """Split ``"0.12m/s^2"`` into ``(0.12, "m/s^2")``; the unit is ``""`` when bare."""
    m = _QUANTITY.match(text)
    if m is None:  # the lexer only produces matching tokens
        raise ValueError(f"not a quantity: {text!r}")
    return float(m.group(1)), m.group(2)


def units_for(dim: Dim) -> list[str]:
    """The units that fit a dimension, for messages ("expected one of m, cm, mm")."""
    return [u for u, (d, _) in UNITS.items() if d is dim]
