"""A path's waypoint targets, made at once, are each pose's own target to the bit; and the
IK's per-waypoint checks still stop a path where a target is not a number or the
solution jumps."""

import math

import numpy as np
import pytest

from aou_dsl.lang.timeline import Pose
from aou_dsl.robot.geometry import reach_frame
from aou_dsl.robot.ik import IKStatus, solve_path
from aou_dsl.robot.load import load_arm

GOAL = (0.55, 0.0, 0.25)
FROM = (-0.6, 0.0, 0.8)


def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.mark.parametrize("start,end", [
    (Pose(0.3), Pose(0.18)),  # an approach: one turn for every waypoint
    (Pose(0.2, 0.0, 0.0, 0.0), Pose(0.26, 0.0, 0.0, 0.0)),  # a retreat
    (Pose(0.2, -0.3, 0.1, 0.2), Pose(0.2, 0.4, 0.1, 0.2)),  # a gaze: a turn each
    (Pose(0.2, 0.1, -0.05, 0.0), Pose(0.2, 0.1, -0.05, math.radians(30))),  # a tilt
    (Pose(0.25, -0.0, 0.0, -0.0), Pose(0.2, 0.0, -0.0, 0.0)),  # signed zeros
])
def test_a_paths_targets_are_each_poses_own_to_the_bit(start, end):
    frame = reach_frame(GOAL, FROM)
    fractions = [float(f) for f in np.linspace(0.0, 1.0, 23)]
    got = frame.targets(start, end, fractions)
    want = [frame.target(start.lerp(end, f)) for f in fractions]
    assert len(got) == len(want)
    for (p, r), (wp, wr) in zip(got, want, strict=True):
        assert _same_bits(p, wp) and _same_bits(r, wr)


def test_a_paths_shared_rotations_cannot_be_changed_by_a_user():
    frame = reach_frame(GOAL, FROM)
    (p0, r0), (_, r1) = frame.targets(Pose(0.3), Pose(0.2), [0.0, 1.0])
    assert r0 is r1  # an approach keeps its orientation: turned once
    with pytest.raises(ValueError):
        r0[0, 0] = 1.0
    with pytest.raises(ValueError):  # its positions, made at once, are kept as well
        p0[0] = 1.0


@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_a_target_that_is_no_number_stops_the_path_there(bad):
    arm = load_arm("panda")
    frame = reach_frame(GOAL, FROM)
    targets = [frame.target(Pose(d)) for d in np.linspace(0.3, 0.25, 6)]
    p, r = targets[4]
    targets[4] = (p, np.where(np.eye(3, dtype=bool), bad, r))  # a rotation with `bad`
    res = solve_path(arm, targets)
    assert res.failure is not None and res.failure.status is IKStatus.UNREACHABLE
    assert res.failure.index == 4 and res.q.shape == (4, 7)
    targets[4] = (np.array([p[0], bad, p[2]]), r)  # a position with `bad`
    res = solve_path(arm, targets)
    assert res.failure is not None and res.failure.index == 4


def test_a_solution_that_jumps_between_neighbours_is_a_branch_flip():
    """Two targets far apart (the second solved from the first): the joints move more
    than a step allows, and the path stops at the second, naming a joint."""
    arm = load_arm("panda")
    frame = reach_frame(GOAL, FROM)
    near = frame.target(Pose(0.3))
    far = frame.target(Pose(0.3, math.radians(40), math.radians(-25), math.radians(60)))
    res = solve_path(arm, [near, far])
    assert res.failure is not None and res.failure.status is IKStatus.DISCONTINUITY
    assert res.failure.index == 1 and res.failure.joint in arm.joint_names
