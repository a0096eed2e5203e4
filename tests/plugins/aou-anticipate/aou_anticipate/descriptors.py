"""The descriptors the plugin adds: how many anticipations a behaviour makes, and how far
one draws back (the median over them, to the millimetre)."""

from __future__ import annotations

from aou_dsl.lang.descriptors import Aggregate, Descriptor

from .kind import NAME

__all__ = ["COUNT", "DEFINITIONS", "DESCRIPTORS", "DISTANCE"]

COUNT = Descriptor("anticipate_count", "", NAME, "", Aggregate.COUNT, "count")
DISTANCE = Descriptor("anticipate_distance", "m", NAME, "distance", Aggregate.MEDIAN, "length",
                      abs_tol=1e-3)

#: The records, in the order they are reported (after aou's own).
DESCRIPTORS = (COUNT, DISTANCE)

#: What each measures, in words (an editor's hover).
DEFINITIONS = {
    COUNT.name: "number of anticipations: moves away from the goal directly followed by "
    "an approach, with no pause between them",
    DISTANCE.name: "distance the end-effector draws back in one anticipation",
}
