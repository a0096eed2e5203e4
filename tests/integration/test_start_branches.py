"""A pose that works before a refusal: when the start the compiler chose leads to links
that touch or a joint at its limit, the other joint solutions of the same start pose are
tried; a behaviour is refused only when none passes, saying what was tried."""

from __future__ import annotations

import numpy as np

from aou_dsl.compiler.branches import other_starts
from aou_dsl.driver.builder import build_source
from aou_dsl.lang.timeline import Pose
from aou_dsl.robot.geometry import reach_frame
from aou_dsl.robot.load import load_arm

LEVEL = """behaviour level : hesitant
robot ur5
from (-1, 0, 0.3)
approach a=0.05
pause 1.67s x5
retreat 0.06m a=0.12 x3
"""


def test_other_start_solutions_reach_the_same_pose_and_differ():
    arm = load_arm("ur5")
    frame = reach_frame(arm.spec.goal, (-1.0, 0.0, 0.3))
    pose = Pose(0.30)
    found = other_starts(arm, frame, pose, None)
    assert len(found) >= 2
    p, r = frame.target(pose)
    for q in found:
        pos, rot = arm.fk(np.array([q]))
        assert np.abs(pos[0] - p).max() < 1e-4 and np.abs(rot[0] - r).max() < 1e-3
    for i, a in enumerate(found):
        for b in found[i + 1:]:
            assert np.abs(np.subtract(a, b)).max() > 0.2


def test_a_level_approach_on_the_ur5_compiles_from_another_solution():
    """The posture's own solution makes upper arm and wrist touch; another passes every
    check and measures as declared."""
    res = build_source(LEVEL, "level.aou")
    assert res.ok, [(d.code, d.message) for d in res.diagnostics]
    assert not [d for d in res.diagnostics if d.code in ("C306", "C310")]
    start = res.header["checks"]["start_configuration"]
    assert "self-collision" in start["why"]
    assert np.allclose(res.trajectory.q[0], start["q"], atol=1e-3)
    m = res.header["descriptors"]
    assert m["measured"]["pause_count"] == 5 and m["measured"]["retreat_count"] == 3


def test_a_start_no_solution_reaches_is_refused_saying_what_was_tried():
    res = build_source("robot z1\ngoal (0.1, 0, 0.05)\napproach\npause 1s\n", "low.aou")
    (err,) = [d for d in res.diagnostics if d.severity.name == "ERROR"]
    assert err.code in ("C301", "C302")
    assert "no other joint solution of the start pose" in err.hint
    assert err.fields["start_solutions_tried"] == 0
