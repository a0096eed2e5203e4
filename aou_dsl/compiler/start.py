"""C301-C303 at the start pose: blamed on what puts the end-effector there.

The start pose lies ``start`` from the goal (the default distance when the file has no
``start`` line), along the start direction: when the robot cannot reach it, the first
statement is not to blame, the ``start`` line is (the ``goal`` line when no start
distance would do, or when the file has no ``start``). The hint gives the furthest
start, in whole centimetres, at which every pose of the motion is reached (checked by
IK), when there is one.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from ..core.codes import C301, C302, C303
from ..core.diagnostics import Diagnostic, refused
from ..fit.refusals import StartUnreachable
from ..lang.ir import Behaviour
from ..lang.timeline import Pose, Timeline
from ..robot.geometry import ReachFrame
from ..robot.ik import IKFailure, IKStatus, solve_path
from ..robot.kinematics import ArmModel

__all__ = ["CODES", "start_diagnostic"]

CODES = {IKStatus.UNREACHABLE: C301, IKStatus.JOINT_LIMIT: C302}


def start_diagnostic(arm: ArmModel, frame: ReachFrame, b: Behaviour, failure: IKFailure,
                     follows: Callable[[Timeline], bool]) -> Diagnostic:
    """The diagnostic for a start pose IK does not reach; ``follows(timeline)`` tells
    whether IK follows every pose of a timeline."""
    s = b.settings
    joint = f" ({failure.joint})" if failure.joint else ""
    said = "as `start` sets it" if "start" in s.spans else \
        "the default start distance: the file has no `start`"
    other = "move the goal (`goal`) or the start direction (`from`)"
    blame = ("start", "goal", "start_direction", "robot")
    if not _reached(arm, frame, math.floor(s.standoff * 100) + 1):
        blame = ("goal", "start_direction", "start", "robot")  # no start would do
        hint = f"no start distance brings the start pose within reach: {other}"
    else:
        fits = _furthest_start(arm, frame, b, follows)
        hint = f"at `start {fits}cm` every pose of the motion is within reach; or {other}" \
            if fits is not None else f"a smaller `start`, or {other}"
    where = next((s.spans[k] for k in blame if k in s.spans), b.span)
    return refused(CODES.get(failure.status, C303), f"the start pose, {s.start:g} m from "
                   f"the goal ({said}): {failure.status.value}{joint} on {s.robot}", where,
                   StartUnreachable(failure.status.name.lower(), 0.0, failure.joint, s.start),
                   hint=hint)


def _reached(arm: ArmModel, frame: ReachFrame, cm: int) -> bool:
    """Whether IK reaches the start pose ``cm`` centimetres from the goal."""
    return solve_path(arm, [frame.target(Pose(cm / 100))]).ok


def _valid(b: Behaviour, cm: int) -> Timeline | None:
    """The behaviour's timeline with its start ``cm`` centimetres from the goal, when the
    file would still be valid so (an approach may not pass the standoff)."""
    from ..lang.values import Ctx
    from ..lang.whole_file import check_whole

    moved = b.replace(settings=b.settings.replace(start=cm / 100))
    ctx = Ctx(b.span.path)
    tl = check_whole(ctx, moved)
    return tl if tl is not None and not ctx.has_errors() else None


def _furthest_start(arm: ArmModel, frame: ReachFrame, b: Behaviour,
                    follows: Callable[[Timeline], bool]) -> int | None:
    """The furthest start [cm] closer than the file's at which the start pose is reached
    (bisection) and then, stepping closer, the whole motion is (checked): None when no
    such start is found in a few steps."""
    s = b.settings
    good, bad = math.floor(s.standoff * 100) + 1, math.ceil(s.start * 100)
    while bad - good > 1:
        mid = (good + bad) // 2
        good, bad = (mid, bad) if _reached(arm, frame, mid) else (good, mid)
    for cm in range(good, max(good - 8, math.floor(s.standoff * 100)), -1):
        tl = _valid(b, cm)
        if tl is not None and follows(tl):
            return cm
    return None
