"""A number with its unit in a statement's text (``60deg``, ``-0.2m``, ``f=2.5Hz``): one
pattern, read by every fit and hint that finds or changes a value.

A quantity stands alone: after a space, ``=`` or the statement's start, before a space,
``;``, ``#`` or the end (so ``5mm`` is never read as ``5m`` and ``m``).
"""

from __future__ import annotations

import math
import re

__all__ = ["NUMBER", "QUANTITY", "UNITS", "first", "keyed"]

#: A decimal number as the language writes it, signed.
NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
#: The units of a positional value: their dimension and their size in SI units.
UNITS = {"m": ("length", 1.0), "cm": ("length", 0.01), "mm": ("length", 0.001),
         "deg": ("angle", math.pi / 180.0), "rad": ("angle", 1.0)}
#: A number and its unit (groups ``number`` and ``unit``; a unit may be absent, as in
#: ``a=1.2``), standing alone.
QUANTITY = re.compile(rf"(?<![^\s=])(?P<number>{NUMBER})(?P<unit>[A-Za-z/^0-9]*)"
                      r"(?=\s|;|#|$)")
#: A keyed value (``f=2.5Hz``, ``for 2s``): groups ``key`` and the quantity's.
_KEYED = re.compile(rf"(?<![\w=])(?P<key>for(?=\s)|\w+(?==))[\s=]*(?P<number>{NUMBER})"
                    r"(?P<unit>\S*)")


def first(stmt: str, dimension: str | None = None) -> re.Match[str] | None:
    """The first positional quantity of ``stmt`` (not a keyed one) with a unit of
    :data:`UNITS`, of ``dimension`` (``angle``, ``length``) when one is given."""
    for m in QUANTITY.finditer(stmt):
        unit = UNITS.get(m["unit"])
        if unit is None or (dimension is not None and unit[0] != dimension):
            continue
        if m.start() > 0 and stmt[m.start() - 1] == "=":
            continue
        return m
    return None


def keyed(text: str) -> list[tuple[str, str, str]]:
    """Each keyed value of ``text`` (``f=1.4Hz for 2.15s``) as ``(key, number, unit)``,
    in order."""
    return [(m["key"], m["number"], m["unit"]) for m in _KEYED.finditer(text)]
