"""Other ways to stand at the start: the arm's other joint solutions for the same start
pose, tried before a behaviour is refused for its start.

The compiler solves the start pose from the robot's posture (continuation), which picks
one solution: one IK branch of a 6-joint arm (shoulder left or right, elbow up or down,
wrist flipped or not), one point of a 7-joint arm's redundancy. When the reach from there
hits a joint limit or the links touch, another solution of the same hand pose may not.
:func:`other_starts` finds them: IK of the start pose seeded from postures that differ
from the robot's in one joint (turned by a half or a quarter turn either way, or
mirrored), kept when they reach the pose and differ from every solution kept before.
The hand's pose, hence every descriptor, is the same from each: only the joints differ.
"""

from __future__ import annotations

import math

import numpy as np

from ..lang.timeline import Pose
from ..robot.geometry import ReachFrame
from ..robot.ik import solve_path
from ..robot.kinematics import ArmModel

__all__ = ["MAX_STARTS", "SEED_TURNS", "other_starts", "start_alternatives"]

#: The most other start configurations tried.
MAX_STARTS = 6
#: Turns [rad] of one joint of the posture that seed the search (and each mirrored).
SEED_TURNS = (math.pi, -math.pi, math.pi / 2, -math.pi / 2)
#: Two solutions are one when no joint differs by more than this [rad].
SAME = 0.2


def _seeds(arm: ArmModel) -> list[np.ndarray]:
    posture = np.asarray(arm.spec.posture, dtype=float)
    lo, hi = arm.lower, arm.upper
    out = []
    for j in range(arm.n):
        for value in (*(posture[j] + d for d in SEED_TURNS), -posture[j]):
            if lo[j] <= value <= hi[j] and abs(value - posture[j]) > SAME:
                s = posture.copy()
                s[j] = value
                out.append(s)
    return out


def other_starts(arm: ArmModel, frame: ReachFrame, start: Pose,
                 first: np.ndarray | None) -> list[tuple[float, ...]]:
    """Up to :data:`MAX_STARTS` joint configurations that put the hand at the start pose
    ``start``, other than ``first`` (the one the compiler chose, when it found one),
    nearest the robot's posture first."""
    target = frame.target(start)
    posture = np.asarray(arm.spec.posture, dtype=float)
    kept: list[np.ndarray] = [] if first is None else [np.asarray(first, float)]
    found = []
    for seed in _seeds(arm):
        ik = solve_path(arm, [target], seed)
        if not ik.ok:
            continue
        q = ik.q[0]
        if all(np.abs(q - k).max() > SAME for k in kept):
            kept.append(q)
            found.append(q)
    found.sort(key=lambda q: float(np.abs(q - posture).sum()))
    return [tuple(float(v) for v in q) for q in found[:MAX_STARTS]]


def start_alternatives(b, tl, package_dirs: tuple[str, ...], first: np.ndarray | None
                       ) -> list[tuple[float, ...]]:
    """:func:`other_starts` for the behaviour ``b`` laid out as ``tl``, on its robot."""
    from ..robot.geometry import reach_frame
    from ..robot.load import load_arm

    arm = load_arm(b.settings.robot, None, package_dirs)
    spec = arm.spec
    frame = reach_frame(b.settings.goal or spec.goal,
                        b.settings.start_direction or spec.start_direction)
    pose = tl.episodes[0].start if tl.episodes else Pose(b.settings.start)
    return other_starts(arm, frame, pose, first)
