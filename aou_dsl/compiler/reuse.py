"""What a recompilation keeps: each motion episode's IK and time law, by what they depend
on (the arm, the reach, the episode's path and bounds, where it starts; not its place in
the file). A changed pause, or any other statement, leaves the other episodes' solutions
as they were, so recompiling after one value changes re-solves only what it changed.
The results are the same objects a first compile makes: the output is byte for byte the
same (tests/integration/test_session.py compares). The arm is known by its key
(:attr:`~aou_dsl.robot.kinematics.ArmModel.key`), which holds the content of its robot's
files: an edited robot file is solved again.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

import numpy as np

from ..core.memo import Keyed, cached
from ..robot.ik import solve_path
from .kind_timing import timing_of
from .timing import time_path

if TYPE_CHECKING:
    from ..lang.timeline import Episode
    from ..robot.geometry import ReachFrame
    from ..robot.kinematics import ArmModel

__all__ = ["solved_path", "timed_path"]


class CompileOptions(Protocol):
    """What of the compiler's options a path's solution depends on."""

    step_length: float
    step_angle: float
    package_dirs: tuple[str, ...]


def _motion_key(arm: ArmModel, frame: ReachFrame, ep: Episode, q: np.ndarray,
                options: CompileOptions) -> tuple:
    """What one motion episode's IK and timing depend on: the arm (its files' content
    included), the reach, the episode's path and bounds (not its place in the file),
    where it starts."""
    return (arm.key, arm.frame_id, frame.goal.tobytes(), frame.R0.tobytes(), ep.kind,
            ep.start, ep.end, ep.a, ep.vmax, ep.plane, q.tobytes(), options.step_length,
            options.step_angle, options.package_dirs)


def solved_path(arm, frame, ep, q, options, targets):
    """IK of an episode's waypoints from ``q``; kept for recompilations (a changed pause
    or another statement leaves the other episodes' paths as they were)."""
    if not arm.key:  # an arm not loaded from files: nothing to know it by
        return solve_path(arm, targets, q)
    return _solved(Keyed(_motion_key(arm, frame, ep, q, options), (arm, targets, q)))


@cached(maxsize=256)
def _solved(probe: Keyed):
    arm, targets, q = probe.value
    return solve_path(arm, targets, q)


def timed_path(arm, frame, ep, q, options, s, q_path):
    """:func:`time_path` of an episode's solved path; kept like :func:`solved_path`."""
    if not arm.key:
        return _time(arm, s, q_path, ep)
    key = (*_motion_key(arm, frame, ep, q, options), "timed")
    return _timed(Keyed(key, (arm, s, q_path, ep)))


@cached(maxsize=256)
def _timed(probe: Keyed):
    return _time(*probe.value)


def _time(arm, s, q_path, ep):
    return time_path(arm, s, q_path, ep.a, ep.vmax, cartesian=timing_of(ep.kind).translation)
