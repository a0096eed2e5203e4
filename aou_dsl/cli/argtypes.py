"""The checked value types of ``aouc``'s options: a value that is not a finite number in
its range is a usage error (exit 2) whose message names the range."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable

__all__ = ["HEIGHT", "LENGTH", "RATE", "UNIT_RANGE", "force_option", "frame_size", "int_in",
           "number", "point"]


def number(lo: float, hi: float, *, lo_open: bool = False, what: str = "a number"
           ) -> Callable[[str], float]:
    """An argparse type: a finite float in [lo, hi] (or (lo, hi] with ``lo_open``)."""
    def parse(text: str) -> float:
        try:
            x = float(text)
        except ValueError:
            x = math.nan
        ok = math.isfinite(x) and (x > lo if lo_open else x >= lo) and x <= hi
        if not ok:
            bracket = "(" if lo_open else "["
            raise argparse.ArgumentTypeError(
                f"expected {what} in {bracket}{lo:g}, {hi:g}], found `{text}`")
        return x
    return parse


def int_in(lo: int, hi: int) -> Callable[[str], int]:
    """An argparse type: a whole number in [lo, hi]."""
    def parse(text: str) -> int:
        try:
            x = int(text)
        except ValueError:
            x = lo - 1
        if not lo <= x <= hi:
            raise argparse.ArgumentTypeError(f"expected a whole number in [{lo}, {hi}], "
                                             f"found `{text}`")
        return x
    return parse


def point(text: str) -> tuple[float, float, float]:
    """argparse type of X,Y,Z options (metres, finite, within 10 m)."""
    parts = text.strip("()").split(",")
    coord = number(-10.0, 10.0, what="a coordinate in metres")
    if len(parts) != 3:
        raise argparse.ArgumentTypeError(f"expected X,Y,Z in metres, found `{text}`")
    x, y, z = (coord(p) for p in parts)
    return (x, y, z)


def frame_size(text: str) -> tuple[int, int]:
    """argparse type of --size WxH (pixels, 16 to 4096 each)."""
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        w = h = -1
    if not (16 <= w <= 4096 and 16 <= h <= 4096):
        raise argparse.ArgumentTypeError(f"expected WxH in pixels, each from 16 to 4096, "
                                         f"e.g. 640x480, found `{text}`")
    return (w, h)


RATE = number(1.0, 10000.0, what="a sample rate in Hz")
LENGTH = number(0.0, 2.0, what="a length in metres")
HEIGHT = number(-2.0, 2.0, what="a height in metres")
UNIT_RANGE = number(-1.0, 1.0, what="a coordinate of the C-V plane")


def force_option(p: argparse.ArgumentParser) -> None:
    p.add_argument("--force", action="store_true",
                   help="replace an existing output file aou did not write (without it, "
                   "only aou's own outputs are replaced)")
