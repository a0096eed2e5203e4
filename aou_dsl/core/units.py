"""Units of the language: every quantity becomes an SI float with a checked dimension.

Angles are stored in radians, angular speeds in rad/s; output converts to degrees
where the descriptors are in degrees.
"""

from __future__ import annotations

import enum
import math
import re

__all__ = ["Dim", "UNITS", "as_unit", "parse_quantity", "suggest_unit", "units_for"]


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


#: Spellings people write for a unit, lower case -> the unit (the parts of a compound
#: unit, `deg/sec`, are looked up one by one).
_SPELLINGS: dict[str, str] = {
    **dict.fromkeys(("s", "sec", "secs", "second", "seconds"), "s"),
    **dict.fromkeys(("ms", "msec", "msecs", "millisecond", "milliseconds"), "ms"),
    **dict.fromkeys(("deg", "degs", "degree", "degrees"), "deg"),
    **dict.fromkeys(("rad", "rads", "radian", "radians"), "rad"),
    **dict.fromkeys(("hz", "hertz"), "Hz"),
    **dict.fromkeys(("m", "meter", "meters", "metre", "metres"), "m"),
    **dict.fromkeys(("cm", "centimeter", "centimeters", "centimetre", "centimetres"), "cm"),
    **dict.fromkeys(("mm", "millimeter", "millimeters", "millimetre", "millimetres"), "mm"),
    "mps": "m/s", "cmps": "cm/s", "mmps": "mm/s", "dps": "deg/s", "degps": "deg/s",
    "mps2": "m/s^2", "mpss": "m/s^2", "s2": "s^2", "sec2": "s^2", "ss": "s^2",
    "secs2": "s^2",
}


def _respell(unit: str) -> str | None:
    """``unit`` in the language's spelling (`sec` -> `s`, `m/s2` -> `m/s^2`), or None."""
    whole = _SPELLINGS.get(unit.lower())
    if whole is not None and "/" in whole:
        return whole
    num, _, den = unit.lower().partition("/")
    if den.endswith(("^2", "2")):
        den = den.removesuffix("^2").removesuffix("2") + "2"
    top, bottom = _SPELLINGS.get(num), _SPELLINGS.get(den) if den else ""
    if top is None or bottom is None:
        return None
    return f"{top}/{bottom}" if bottom else top


def as_unit(word: str) -> str | None:
    """The unit ``word`` is (in the language's spelling: `sec` -> `s`), or None."""
    meant = word if word in UNITS else _respell(word)
    return meant if meant in UNITS else None


def suggest_unit(unit: str, dim: Dim) -> str | None:
    """The unit of ``dim`` that ``unit`` most likely means: another spelling of it
    (`sec`, `Seconds`, `degrees`, `HZ`, `mps`, `m/s2`), else the closest by its letters;
    None when no unit of ``dim`` is close."""
    meant = _respell(unit)
    if meant in UNITS and UNITS[meant][0] is dim:
        return meant
    import difflib  # only for a misspelt unit

    fits = units_for(dim)
    close = difflib.get_close_matches(unit.lower(), [u.lower() for u in fits], n=1,
                                      cutoff=0.6)
    return next((u for u in fits if close and u.lower() == close[0]), None)
