"""Each compiler stage on its own: geometry, IK, timing, sampling and output, checked
against properties written from their definitions."""

import json
import math

import numpy as np
import pytest

from aou_dsl.compiler.output import encode, output_paths
from aou_dsl.compiler.pipeline import _clock, compile_behaviour
from aou_dsl.compiler.timing import TimeLaw, limit_ratios, time_path
from aou_dsl.core.diagnostics import AouError
from aou_dsl.core.files import write_atomic
from aou_dsl.lang.linter import lint_source
from aou_dsl.lang.timeline import Pose
from aou_dsl.robot.geometry import reach_frame, rotation_angles
from aou_dsl.robot.ik import IKStatus, solve_path
from aou_dsl.robot.load import load_arm

GOAL = (0.55, 0.0, 0.25)
FROM = (-0.6, 0.0, 0.8)


def _plane_angle(g0, g, normal):
    a = g0 - (g0 @ normal) * normal
    b = g - (g @ normal) * normal
    return math.degrees(math.atan2(np.cross(a, b) @ normal, a @ b))


@pytest.mark.parametrize("h,v", [(20, 0), (0, 15), (30, 10), (-25, -20), (45, 30)])
def test_a_pose_has_the_declared_plane_angles_and_looks_at_the_goal(h, v):
    """The goal vector's angle in each plane (normals: the start pose's y and x axes) is
    the pose's, the end-effector is `d` from the goal, and its z axis points at it."""
    frame = reach_frame(GOAL, FROM)
    x0, y0, _ = frame.R0.T
    p0, _ = frame.target(Pose(0.3))
    p, r = frame.target(Pose(0.3, math.radians(h), math.radians(v), math.radians(17)))
    g0, g = np.array(GOAL) - p0, np.array(GOAL) - p
    assert _plane_angle(g0, g, y0) == pytest.approx(h, abs=1e-9)
    assert _plane_angle(g0, g, x0) == pytest.approx(v, abs=1e-9)
    assert np.linalg.norm(g) == pytest.approx(0.3)
    assert r[:, 2] @ (g / np.linalg.norm(g)) == pytest.approx(1.0)
    assert np.allclose(r.T @ r, np.eye(3))


def test_rotation_angles_are_the_identity_in_one_plane():
    """A look in one plane only needs no rotation about the other axis."""
    assert rotation_angles(0.3, 0.0) == pytest.approx((0.3, 0.0))
    assert rotation_angles(0.0, 0.2) == pytest.approx((0.0, 0.2))


def test_ik_follows_a_line_continuously():
    """A short approach is solved to within 0.1 mm, continuously, inside the limits."""
    arm = load_arm("panda")
    frame = reach_frame(GOAL, FROM)
    targets = [frame.target(Pose(d)) for d in np.linspace(0.3, 0.2, 21)]
    res = solve_path(arm, targets)
    assert res.ok and res.q.shape == (21, 7)
    pos, rot = arm.fk(res.q)
    assert np.abs(pos - np.array([t[0] for t in targets])).max() < 1e-4
    assert np.abs(np.diff(res.q, axis=0)).max() < 0.35
    assert np.all(res.q > arm.lower) and np.all(res.q < arm.upper)


def test_ik_reports_an_unreachable_target():
    """A target 2 m away fails as unreachable at its index, not with an exception."""
    arm = load_arm("panda")
    frame = reach_frame((2.0, 0.0, 0.3), FROM)
    res = solve_path(arm, [frame.target(Pose(0.3))])
    assert not res.ok and res.failure.status in (IKStatus.UNREACHABLE, IKStatus.JOINT_LIMIT)
    assert res.failure.index == 0


def test_bang_bang_time_law():
    """Rest to rest over L in T: s(0)=0, s(T)=L, peak speed 2L/T at T/2, |s''| = 4L/T^2."""
    law = TimeLaw.bang_bang(0.5, 2.0)
    s, sd, sdd = law(np.array([0.0, 1.0, 2.0]))
    assert s == pytest.approx([0.0, 0.25, 0.5]) and sd == pytest.approx([0.0, 0.5, 0.0])
    assert np.abs(law.u) == pytest.approx([0.5, 0.5]) and law.duration == pytest.approx(2.0)


def test_time_path_reaches_the_declared_acceleration_within_joint_limits():
    """A straight approach timed at a=0.1 m/s^2 peaks at the declared acceleration and
    keeps every joint within its planned limits, densely checked."""
    arm = load_arm("panda")
    frame = reach_frame(GOAL, FROM)
    s = np.linspace(0.0, 0.1, 21)
    res = solve_path(arm, [frame.target(Pose(0.3 - x)) for x in s])
    seg, fail = time_path(arm, s, res.q, 0.1, 0.25, cartesian=True)
    assert seg is not None and fail is None
    assert np.abs(seg.law.u).max() == pytest.approx(0.1, rel=0.03)
    rv, ra = limit_ratios(arm, seg)
    assert rv.max() <= 1.001 and ra.max() <= 1.001
    q, qd, _ = seg.sample(np.array([0.0, seg.duration]))
    assert np.abs(qd).max() < 1e-9  # rest to rest


@pytest.mark.parametrize("total,rate", [(1.0, 250.0), (1.003, 250.0), (2.5, 1.0), (0.7, 3.0)])
def test_the_clock_ends_exactly_at_the_end(total, rate):
    """Samples start at 0, increase strictly, and the last is the motion's true end."""
    t = _clock(total, rate)
    assert t[0] == 0.0 and t[-1] == pytest.approx(total) and np.all(np.diff(t) > 0)


def test_a_compiled_behaviour_ends_at_rest_at_its_planned_end():
    """The last sample is the planned end and every joint is at rest there, whatever the
    rate."""
    lint = lint_source("approach a=0.2\npause 0.5s", "t.aou")
    for rate in (250.0, 7.0):
        from aou_dsl.compiler.pipeline import CompileOptions

        res = compile_behaviour(lint.behaviour, CompileOptions(rate=rate), lint.timeline)
        tr = res.trajectory
        assert tr.t[-1] == pytest.approx(lint.timeline.planned_duration, rel=0.2)
        assert tr.t[-1] == pytest.approx(sum(s.duration for s in res.segments))
        assert np.abs(tr.qd[-1]).max() < 1e-9


def test_encodings_carry_the_same_samples():
    """JSON, CSV and NPZ hold the same t and q; the same document gives the same bytes."""
    import io
    import zipfile

    doc = {"format": "aou-trajectory/1", "robot": "panda", "ee_frame": "f",
           "goal": {"position": [0.5, 0.0, 0.25]}, "joint_names": ["a", "b"], "t": [0.0, 0.1],
           "q": [[0.1, 0.2], [0.3, 0.4]], "qd": [[0, 0], [0, 0]], "qdd": [[0, 0], [0, 0]]}
    assert json.loads(encode(doc, "json"))["q"] == doc["q"]
    lines = encode(doc, "csv").decode().splitlines()
    assert "# goal: 0.5,0.0,0.25" in lines and "# robot: panda" in lines
    rows = [r for r in lines if not r.startswith("#")]
    assert rows[0] == "t,a,b" and rows[2] == "0.1,0.3,0.4"
    with zipfile.ZipFile(io.BytesIO(encode(doc, "npz"))) as zf:
        q = np.load(io.BytesIO(zf.read("q.npy")))
    assert q.tolist() == doc["q"]
    assert encode(doc, "npz") == encode(doc, "npz")


def test_write_atomic_never_overwrites_an_input(tmp_path):
    """Writing over an input is refused and leaves it intact; nothing else appears."""
    src = tmp_path / "a.aou"
    src.write_text("pause 1s\n")
    with pytest.raises(AouError) as err:
        write_atomic(str(src), b"x", inputs=[str(src)])
    assert err.value.diagnostics[0].code == "I502"
    assert src.read_text() == "pause 1s\n" and sorted(p.name for p in tmp_path.iterdir()) == [
        "a.aou"]


def test_folder_outputs_mirror_the_input_tree_and_refuse_collisions(tmp_path):
    """Files found in a folder keep their relative path; two inputs on one output fail."""
    dests, fmt = output_paths([("in/x/same.aou", "in"), ("in/y/same.aou", "in")], "out", None)
    assert fmt == "json" and dests == ["out/x/same.json", "out/y/same.json"]
    with pytest.raises(AouError):
        output_paths([("x/same.aou", None), ("y/same.aou", None)], str(tmp_path), None)
