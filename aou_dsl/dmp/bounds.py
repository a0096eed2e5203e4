"""The bounds of the DMP modules, each a named constant (docs/dmp.md lists them), and
the checks of a rollout's options.

A ``.dmp`` folder is untrusted (:mod:`.reader`): every number the library would loop on
is bounded before it is used, and a file beyond a bound is refused (D608).
"""

from __future__ import annotations

import math
from typing import Any

from ..core.codes import I504
from ..core.diagnostics import AouError, Span, diag

__all__ = ["DIVERGED", "MAX_COORD", "MAX_DURATION", "MAX_EXECUTION_TIME",
           "MAX_FOLDER_BYTES", "MAX_GAIN", "MAX_INT_DT", "MAX_JOINT", "MAX_LEAD",
           "MAX_MANIFEST_BYTES", "MAX_NAME", "MAX_PARTS", "MAX_PART_BYTES", "MAX_RATE",
           "MAX_SAMPLES", "MAX_STEPS", "MAX_WEIGHTS", "MIN_GOAL_DISTANCE", "MIN_INT_DT",
           "MIN_RATE", "Diverged", "check_goal", "check_options"]

#: Largest manifest read [bytes] (a shipped behaviour's is about 10 kB).
MAX_MANIFEST_BYTES = 4 * 1024 * 1024
#: Largest part file read [bytes] (a shipped motion's is 0.1 to 0.4 MB).
MAX_PART_BYTES = 32 * 1024 * 1024
#: Most bytes read from one folder, manifest and parts together.
MAX_FOLDER_BYTES = 128 * 1024 * 1024
#: Most parts in a manifest (as many as a behaviour file may have episodes).
MAX_PARTS = 1000
#: Longest sequence, and longest part [s] (as long as a behaviour file may move).
MAX_DURATION = 600.0
#: Longest execution time of one part's DMP [s].
MAX_EXECUTION_TIME = 600.0
#: Range of a DMP's integration step ``int_dt`` [s] (aou writes 0.001).
MIN_INT_DT, MAX_INT_DT = 1e-4, 1e-2
#: Most integration steps of one DMP at its own execution time (``execution_time /
#: int_dt``).
MAX_STEPS = 1_000_000
#: Most basis functions per dimension of one DMP (aou writes 400 per second).
MAX_WEIGHTS = 100_000
#: Range of the sample rate [Hz], and most samples of the sequence at its rate.
MIN_RATE, MAX_RATE = 1.0, 1000.0
MAX_SAMPLES = 2_000_000
#: Longest lead-in of a motion's DMP before its episode [s] (aou writes a few
#: milliseconds: three basis functions, or one sample).
MAX_LEAD = 10.0
#: Largest coordinate of a position or goal [m], and largest joint value [rad].
MAX_COORD = 10.0
MAX_JOINT = 100.0
#: Largest transformation-system gain ``alpha_y``, ``beta_y``.
MAX_GAIN = 1e4
#: Longest name (robot, frame, joint, behaviour, file) [characters].
MAX_NAME = 4096
#: Least distance from the start to a goal [m]: a rollout scales by the ratio of two.
MIN_GOAL_DISTANCE = 1e-4
#: A motion whose rolled-out position leaves this distance [m] from the base has
#: diverged (a part file's gains or weights that make no motion): D602.
DIVERGED = 1000.0

_WHERE = Span.whole_file("<dmp>")


class Diverged(Exception):
    """A motion's rollout is not finite or leaves :data:`DIVERGED`."""


def check_options(time_scale: float, intensity: float | None, pinned: tuple[str, ...],
                  accelerations: tuple[str, ...]) -> None:
    """A rollout's time scale in [0.25, 4], intensity in [0, 1], and only
    ``accelerations`` pinned (I504)."""
    if not (isinstance(time_scale, int | float) and 0.25 <= time_scale <= 4.0):
        raise AouError(diag(I504, f"the time scale must be a number in [0.25, 4], found "
                            f"{time_scale!r}", _WHERE))
    if intensity is not None and not (isinstance(intensity, int | float)
                                      and 0.0 <= intensity <= 1.0):
        raise AouError(diag(I504, f"the intensity must be a number in [0, 1], found "
                            f"{intensity!r}", _WHERE))
    bad = [p for p in pinned if p not in accelerations]
    if bad:
        raise AouError(diag(I504, f"only accelerations can be pinned "
                            f"({', '.join(accelerations)}), found {', '.join(bad)}",
                            _WHERE))


def check_goal(goal: tuple[float, ...], start: Any) -> None:
    """A goal that is finite and :data:`MIN_GOAL_DISTANCE` from the start (I504)."""
    if not all(math.isfinite(x) for x in goal) or \
            math.dist(goal, [float(x) for x in start]) < MIN_GOAL_DISTANCE:
        raise AouError(diag(I504, f"the goal {goal} must be finite and differ from where "
                            f"the motion starts ({', '.join(f'{x:.4g}' for x in start)})",
                            _WHERE))
