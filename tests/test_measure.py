"""`aouc measure` recovers known descriptors from analytically built trajectories
(tests/synth.py; not the compiler), clean and with joint noise."""

import math

import numpy as np
import pytest

from aou_dsl.diagnostics import AouError
from aou_dsl.measuring.descriptors import measure
from aou_dsl.measuring.recording import read_csv, read_json
from aou_dsl.trajectory import Trajectory as Recording

from .synth import Synth

DEG = math.pi / 180


def _hesitant_like() -> Synth:
    """approach 0.1 m at 0.05, 3 pauses of 1.5 s around 2 retreats of 4 cm at 0.12,
    then the rest of the way."""
    s = Synth()
    s.line(-0.10, 0.05).hold(1.5).line(+0.04, 0.12).hold(1.5).line(+0.04, 0.12).hold(1.5)
    s.line(-0.08, 0.05)
    return s


def _curious_like() -> Synth:
    s = Synth()
    s.line(-0.08, 0.09).arc(20 * DEG, 45 * DEG).hold(1.25).line(-0.05, 0.09)
    s.arc(-40 * DEG, 45 * DEG).hold(1.25).line(-0.05, 0.09).hold(1.25)
    return s


def _fearful_like() -> Synth:
    s = Synth()
    s.line(-0.10, 0.1).hold(1.25).line(+0.06, 0.5).hold(1.25)
    s.shiver(6 * DEG, 2.5, 4).line(-0.12, 0.1).hold(1.25)
    return s


def _tilt_like() -> Synth:
    s = Synth()
    s.line(-0.1, 0.1).tilt(15 * DEG, 40 * DEG).hold(1.0).tilt(-15 * DEG, 40 * DEG).hold(1.0)
    return s


CASES = {"hesitant": _hesitant_like, "curious": _curious_like, "fearful": _fearful_like,
         "tilt": _tilt_like}


@pytest.fixture(scope="module")
def synths():
    return {k: f() for k, f in CASES.items()}


def _check(m, scale: float = 1.0, **expected):
    d = m.descriptors
    for key, want in expected.items():
        got = d[key]
        if want is None or isinstance(want, int):
            assert got == want, (key, got, want)
        elif key.endswith("acceleration"):
            assert got == pytest.approx(want, rel=0.03 * scale), key
        elif key in ("pause_duration",):
            assert abs(got - want) <= 0.02 * scale, (key, got, want)
        elif key in ("retreat_distance",):
            assert abs(got - want) <= 1e-3 * scale, (key, got, want)
        else:  # angles [deg]
            assert abs(got - want) <= 0.5 * scale, (key, got, want)


@pytest.mark.parametrize("noise", [0.0, 2e-4], ids=["clean", "noisy"])
def test_approach_pauses_and_retreats(synths, noise):
    """Known peak acceleration, 3 pauses of 1.5 s, 2 retreats of 4 cm at 0.12 m/s^2."""
    m = measure(synths["hesitant"].recording(noise))
    _check(m, 2.0 if noise else 1.0, approach_acceleration=0.05, pause_count=3,
           pause_duration=1.5, retreat_count=2, retreat_distance=0.04,
           retreat_acceleration=0.12, horizontal_gaze=None, shiver_amplitude=None)


@pytest.mark.parametrize("noise", [0.0, 2e-4], ids=["clean", "noisy"])
def test_gaze_arcs(synths, noise):
    """Two gaze arcs ending 20 deg either side of the start direction, each at a pause."""
    m = measure(synths["curious"].recording(noise))
    _check(m, 2.0 if noise else 1.0, approach_acceleration=0.09, pause_count=3,
           pause_duration=1.25, retreat_count=0, horizontal_gaze=20.0, vertical_gaze=None,
           tilt_angle=None)


@pytest.mark.parametrize("noise", [0.0, 2e-4], ids=["clean", "noisy"])
def test_shiver_and_fast_retreat(synths, noise):
    m = measure(synths["fearful"].recording(noise))
    expected = dict(pause_count=3, pause_duration=1.25, retreat_count=1,
                    retreat_distance=0.06, shiver_amplitude=6.0)
    if not noise:
        expected |= dict(approach_acceleration=0.1, retreat_acceleration=0.5)
    _check(m, 2.0 if noise else 1.0, **expected)
    assert [e.kind for e in m.episodes].count("shiver") == 1


@pytest.mark.parametrize("noise", [0.0, 2e-4], ids=["clean", "noisy"])
def test_tilt(synths, noise):
    m = measure(synths["tilt"].recording(noise))
    # A 15 deg bang-bang roll at 40 deg/s^2 lasts 2 sqrt(15/40) s.
    velocity = 15.0 / (2 * math.sqrt(15 / 40))
    _check(m, 2.0 if noise else 1.0, pause_count=2, tilt_angle=15.0, shiver_amplitude=None)
    assert m.descriptors["tilt_velocity"] == pytest.approx(velocity, rel=0.03)


def test_gaze_lock_of_synthetic_motion_is_zero(synths):
    """The synthetic motions look at the goal; the measured line of sight agrees."""
    assert measure(synths["curious"].recording()).gaze_error < 0.01


def test_nonuniform_sampling(synths):
    """Dropping every third sample makes the clock uneven; the counts stay exact."""
    rec = synths["hesitant"].recording()
    keep = np.ones(len(rec.t), bool)
    keep[1:-1:3] = False
    m = measure(Recording(rec.t[keep], rec.q[keep], rec.joint_names, rec.robot, None, rec.goal))
    _check(m, 2.0, approach_acceleration=0.05, pause_count=3, pause_duration=1.5,
           retreat_count=2, retreat_distance=0.04)


def test_recording_that_starts_and_ends_mid_motion(synths):
    """Cut in the middle of the first approach and of the last: the pauses and retreats
    between are still found, and nothing crashes on the partial episodes."""
    rec = synths["hesitant"].recording()
    cut = slice(300, len(rec.t) - 200)
    m = measure(Recording(rec.t[cut] - rec.t[cut][0], rec.q[cut], rec.joint_names, rec.robot,
                          None, rec.goal))
    _check(m, pause_count=3, pause_duration=1.5, retreat_count=2, retreat_distance=0.04)


def test_extra_finger_columns_are_ignored(synths):
    rec = synths["hesitant"].recording()
    fingers = np.full((len(rec.t), 2), 0.02)
    names = (*rec.joint_names, "panda_finger_joint1", "panda_finger_joint2")
    m = measure(Recording(rec.t, np.hstack([rec.q, fingers]), names, "panda", None, rec.goal))
    assert m.descriptors["retreat_count"] == 2


def test_missing_arm_joint_is_a_diagnostic(synths):
    rec = synths["hesitant"].recording()
    with pytest.raises(AouError) as info:
        measure(Recording(rec.t, rec.q[:, :6], rec.joint_names[:6], "panda", None, rec.goal))
    assert info.value.diagnostics[0].code == "R402"
    assert "panda_joint7" in info.value.diagnostics[0].message


@pytest.mark.parametrize("text,fragment", [
    ('{"format": "aou-trajectory/1"}', "missing key"),
    ('{"format": "other"}', "aou-trajectory/1"),
    ('[1, 2', "not valid JSON"),
    ('{"format": "aou-trajectory/1", "robot": "panda", "joint_names": ["a"], '
     '"goal": {"position": [0, 0, 0]}, "t": [0, 1, 1], "q": [[0], [0], [0]]}', "increase"),
    ('{"format": "aou-trajectory/1", "robot": "panda", "joint_names": ["a"], '
     '"goal": {"position": [0, 0, 0]}, "t": [0, 1, 2], "q": [[0], [NaN], [0]]}', "finite"),
])
def test_bad_json_is_a_clear_diagnostic(text, fragment):
    with pytest.raises(AouError) as info:
        read_json("x.json", text)
    (d,) = info.value.diagnostics
    assert d.code == "R401" and fragment in d.message


def test_csv_round_trip(synths, tmp_path):
    rec = synths["hesitant"].recording()
    lines = ["t," + ",".join(rec.joint_names)]
    lines += [",".join(repr(float(v)) for v in [t, *row])
              for t, row in zip(rec.t, rec.q, strict=True)]
    r2 = read_csv("r.csv", "\n".join(lines), "panda", None, None)
    assert r2.goal == (0.55, 0.0, 0.25)  # the robot's default goal
    assert measure(r2).descriptors["retreat_count"] == 2


def test_csv_errors_name_row_and_column():
    with pytest.raises(AouError) as info:
        read_csv("r.csv", "t,panda_joint1\n0,0\n0.1,abc\n", "panda", None, None)
    assert "row 3" in info.value.diagnostics[0].message
    with pytest.raises(AouError) as info:
        read_csv("r.csv", "time,panda_joint1\n0,0\n", "panda", None, None)
    assert "first column must be `t`" in info.value.diagnostics[0].message


def test_a_tilt_beside_a_shiver_is_a_tilt():
    """A rest-to-rest tilt right after a tremor, with no rest between, is told apart by
    its duration: the shiver's half periods are equal, the tilt lasts longer."""
    from aou_dsl.build import build_source

    res = build_source("tilt 5deg v=8deg/s x1\nshiver 2deg f=2Hz for 1.5s\n", "t.aou",
                       check=False)
    d = res.measured.descriptors
    assert d["tilt_angle"] == pytest.approx(5.0, abs=0.5)
    assert d["shiver_amplitude"] == pytest.approx(2.0, abs=0.5)
