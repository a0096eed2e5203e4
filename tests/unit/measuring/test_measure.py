"""`aouc measure` recovers known descriptors from analytically built trajectories
(tests/synth.py; not the compiler), clean and with joint noise."""

import json
import math

import numpy as np
import pytest

from aou_dsl.core.diagnostics import AouError
from aou_dsl.core.trajectory import Trajectory as Recording
from aou_dsl.lang.descriptors import REGISTRY
from aou_dsl.measuring.measured import measure
from aou_dsl.measuring.recording import read_csv, read_json, read_recording
from tests.conftest import BEHAVIOURS
from tests.synth import Synth

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


def _csv(rec, comments=()) -> str:
    lines = [*comments, "t," + ",".join(rec.joint_names)]
    lines += [",".join(repr(float(v)) for v in [t, *row])
              for t, row in zip(rec.t, rec.q, strict=True)]
    return "\n".join(lines) + "\n"


def test_csv_round_trip_takes_the_goal_from_its_comment(synths):
    rec = synths["curious"].recording()
    text = _csv(rec, ["# format: aou-trajectory/1", "# robot: panda", "# ee_frame: None",
                      "# goal: 0.55,0.0,0.25"])
    r2 = read_csv("r.csv", text)
    assert r2.robot == "panda" and r2.ee_frame is None and r2.goal == (0.55, 0.0, 0.25)
    m = measure(r2)
    assert m.descriptors["horizontal_gaze"] == pytest.approx(20.0, abs=0.5)
    assert not [d for d in m.diagnostics if d.code == "R405"]


def test_a_recording_without_a_goal_still_measures_what_it_can(synths):
    """No goal: R405 says so; gazes and the line of sight are unknown; pauses, and
    approaches and retreats read along the hand's forward axis, are measured."""
    rec = synths["hesitant"].recording()
    m = measure(read_csv("r.csv", _csv(rec), "panda", None, None))
    assert [d.code for d in m.diagnostics] == ["R405"]
    _check(m, pause_count=3, pause_duration=1.5, retreat_count=2, retreat_distance=0.04,
           approach_acceleration=0.05, retreat_acceleration=0.12, horizontal_gaze=None,
           vertical_gaze=None)
    assert m.line_of_sight is None and math.isnan(m.gaze_error)
    out = m.to_json()
    assert out["line_of_sight"] is None and out["gaze_error_deg"] is None


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
    from aou_dsl.driver.builder import build_source

    res = build_source("tilt 5deg v=8deg/s x1\nshiver 2deg f=2Hz for 1.5s\n", "t.aou",
                       check=False)
    d = res.measured.descriptors
    assert d["tilt_angle"] == pytest.approx(5.0, abs=0.5)
    assert d["shiver_amplitude"] == pytest.approx(2.0, abs=0.5)


# --- reading: every format, units, goals, and what a bad file gets -------------------------


def _fails(code: str, fn, *args, **kw):
    with pytest.raises(AouError) as info:
        fn(*args, **kw)
    (d,) = info.value.diagnostics
    assert d.code == code, d.message
    return d


def test_a_nan_row_is_named_by_its_line(tmp_path):
    path = tmp_path / "r.csv"
    path.write_text("# robot: panda\nt,panda_joint1\n0,0\n0.1,nan\n0.2,0\n")
    d = _fails("R401", read_recording, str(path))
    assert "row 4" in d.message and "panda_joint1" in d.message


def test_a_short_row_is_named_by_its_line(tmp_path):
    path = tmp_path / "r.csv"
    path.write_text("t,panda_joint1,panda_joint2\n0,0,0\n0.1,0\n0.2,0,0\n")
    d = _fails("R401", read_recording, str(path), robot="panda")
    assert "row 3 has 2 columns" in d.message


@pytest.mark.parametrize("rows,fragment", [
    ("[[0, 0], [0], [0, 0]]", "sample 1 has 1 values"),
    ("[[0, 0], [0, NaN], [0, 0]]", "sample 1"),
])
def test_bad_json_rows_are_named(rows, fragment):
    text = ('{"format": "aou-trajectory/1", "robot": "panda", "joint_names": ["a", "b"], '
            f'"t": [0, 0.1, 0.2], "q": {rows}}}')
    d = _fails("R401", read_json, "x.json", text)
    assert fragment in d.message


def _write_csv(tmp_path, rec, name="r.csv", scale_t=1.0, scale_q=1.0) -> str:
    lines = ["t," + ",".join(rec.joint_names)]
    lines += [",".join(repr(float(v)) for v in [t * scale_t, *(row * scale_q)])
              for t, row in zip(rec.t, rec.q, strict=True)]
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def _same(a, b):
    for k in REGISTRY:
        if isinstance(a[k], float):
            assert b[k] == pytest.approx(a[k], rel=1e-6, abs=1e-9), k
        else:
            assert a[k] == b[k], k


def test_degrees_are_refused_unless_the_unit_is_given(tmp_path, synths):
    rec = synths["hesitant"].recording()
    goal = rec.goal
    base = measure(read_recording(_write_csv(tmp_path, rec), robot="panda", goal=goal))
    path = _write_csv(tmp_path, rec, "deg.csv", scale_q=180 / math.pi)
    d = _fails("R404", read_recording, path, robot="panda", goal=goal)
    assert "degrees" in d.message and "--angle-unit" in d.hint
    _same(base.descriptors, measure(read_recording(path, robot="panda", goal=goal,
                                                   angle_unit="deg")).descriptors)


def test_milliseconds_are_refused_unless_the_unit_is_given(tmp_path, synths):
    rec = synths["hesitant"].recording()
    goal = rec.goal
    base = measure(read_recording(_write_csv(tmp_path, rec), robot="panda", goal=goal))
    path = _write_csv(tmp_path, rec, "ms.csv", scale_t=1000.0)
    d = _fails("R404", read_recording, path, robot="panda", goal=goal)
    assert "milliseconds" in d.message
    _same(base.descriptors, measure(read_recording(path, robot="panda", goal=goal,
                                                   time_unit="ms")).descriptors)


def test_files_written_by_aou_are_trusted_at_any_rate(tmp_path):
    """A trajectory compiled at 1 Hz has one sample a second: aou wrote it, so its clock
    is seconds."""
    from aou_dsl.cli.commands import main

    out = tmp_path / "slow.json"
    assert main(["compile", str(BEHAVIOURS / "inactive.aou"), "-o", str(out),
                 "--rate", "1", "--no-check"]) == 0
    rec = read_recording(str(out))
    assert rec.goal is not None and np.median(np.diff(rec.t)) == pytest.approx(1.0)


def _doc(rec, goal=True) -> dict:
    doc = {"format": "aou-trajectory/1", "robot": rec.robot, "ee_frame": None,
           "joint_names": list(rec.joint_names), "t": rec.t.tolist(), "q": rec.q.tolist()}
    if goal:
        doc["goal"] = {"position": list(rec.goal)}
    return doc


def test_a_json_without_goal_takes_the_goal_given(tmp_path, synths):
    rec = synths["curious"].recording()
    path = tmp_path / "r.json"
    path.write_text(json.dumps(_doc(rec, goal=False)))
    assert read_recording(str(path)).goal is None
    given = read_recording(str(path), goal=rec.goal)
    assert given.goal == tuple(rec.goal)
    assert measure(given).descriptors["horizontal_gaze"] == pytest.approx(20.0, abs=0.5)


def test_goal_final_is_the_hands_last_position(tmp_path, synths):
    import pinocchio as pin

    from aou_dsl.robot.load import load_arm

    rec = synths["hesitant"].recording()
    path = tmp_path / "r.json"
    path.write_text(json.dumps(_doc(rec, goal=False)))
    final = read_recording(str(path), goal="final")
    arm = load_arm("panda")
    data = arm.model.createData()
    pin.framesForwardKinematics(arm.model, data, rec.q[-1])
    assert np.allclose(final.goal, data.oMf[arm.frame_id].translation, atol=1e-9)
    m = measure(final)
    assert m.descriptors["retreat_count"] == 2 and m.line_of_sight is not None
    _fails("R405", read_recording, str(path), goal="middle")


def test_npz_written_by_aou_reads_back(tmp_path):
    from aou_dsl.compiler.output import encode
    from aou_dsl.driver.builder import build_source

    res = build_source((BEHAVIOURS / "fearful.aou").read_text(), "fearful.aou", check=False)
    path = tmp_path / "f.npz"
    path.write_bytes(encode(res.document, "npz"))
    rec = read_recording(str(path))
    assert rec.robot == "panda" and rec.goal == tuple(res.document["goal"]["position"])
    assert np.array_equal(rec.q, np.asarray(res.document["q"]))
    _same(res.measured.descriptors, measure(rec).descriptors)


# --- signals: noise per joint, rounding, wraps, clocks -------------------------------------


def test_noise_is_estimated_per_moving_joint_and_rounding_recognised(synths):
    from aou_dsl.measuring.signal import joint_noise

    rec = synths["hesitant"].recording()
    sigma = np.array([1e-5, 3e-5, 1e-4, 1.5e-4, 5e-5, 2e-5, 0.0])
    q = rec.q + np.random.default_rng(3).normal(0, 1, rec.q.shape) * sigma
    q[:, 6] = q[0, 6]  # a joint that never moves, constant to the last bit
    jn = joint_noise(rec.t, q)
    assert np.allclose(jn.sigma[:6], sigma[:6], rtol=0.25) and jn.sigma[6] == 0
    assert not jn.moving[6] and jn.moving[:6].all()
    rounded = joint_noise(rec.t, np.round(rec.q, 6))
    assert np.allclose(rounded.quantum, 1e-6, rtol=1e-3)
    assert np.allclose(rounded.effective, 1e-6 / math.sqrt(12), rtol=0.05)


def test_rounded_positions_keep_accelerations(synths):
    """q rounded to 6 decimals at 250 Hz: peaks within 3 % (central differences of the
    rounded positions would read them 20 to 40 % high)."""
    rec = synths["hesitant"].recording()
    m = measure(rec.with_(q=np.round(rec.q, 6)))
    _check(m, approach_acceleration=0.05, retreat_acceleration=0.12, pause_count=3,
           retreat_count=2)


def test_a_wrapped_continuous_joint_is_unwrapped(synths):
    rec = synths["tilt"].recording()
    q = rec.q.copy()
    # Joint 7 reported as if it wrapped at +-pi: a turn subtracted past its middle value.
    mid = 0.5 * (q[:, 6].min() + q[:, 6].max())
    q[:, 6] = np.where(q[:, 6] > mid, q[:, 6] - 2 * math.pi, q[:, 6])
    assert np.abs(np.diff(q[:, 6])).max() > math.pi
    _same(measure(rec).descriptors, measure(rec.with_(q=q)).descriptors)


def test_a_jittered_noisy_clock_keeps_the_counts(synths):
    """A fifth of the samples dropped at random, 1e-4 rad of noise."""
    rec = synths["hesitant"].recording(1e-4, seed=4)
    keep = np.random.default_rng(5).random(len(rec.t)) > 0.2
    keep[[0, -1]] = True
    m = measure(rec.with_(t=rec.t[keep], q=rec.q[keep]))
    _check(m, 2.5, pause_count=3, pause_duration=1.5, retreat_count=2,
           retreat_distance=0.04)


def test_a_logging_gap_does_not_split_a_pause(synths):
    """16 ms without samples in the middle of every pause."""
    rec = synths["hesitant"].recording(1e-4, seed=6)
    keep = np.ones(len(rec.t), bool)
    for centre in (3.6, 6.2, 8.9):  # inside the three holds
        i = int(np.searchsorted(rec.t, centre))
        keep[i:i + 4] = False
    m = measure(rec.with_(t=rec.t[keep], q=rec.q[keep]))
    _check(m, 2.5, pause_count=3, pause_duration=1.5)


def test_joint_noise_is_reported(synths):
    m = measure(synths["hesitant"].recording(1e-4, seed=2))
    assert len(m.joint_noise) == 7
    assert np.allclose(m.joint_noise, 1e-4, rtol=0.25) and m.noise == max(m.joint_noise)


# --- tilts and shivers, compiled and measured ---------------------------------------------


def _built(text: str):
    from aou_dsl.driver.builder import build_source

    res = build_source(text, "t.aou", check=False)
    assert res.ok, [(d.code, d.message) for d in res.diagnostics]
    return res


@pytest.mark.parametrize("text", [
    "tilt 10deg v=5deg/s x3",
    "sequence {\n  tilt 10deg v=5deg/s\n  shiver 4deg\n  tilt -10deg v=5deg/s\n  pause 1s\n}",
    "sequence {\n  approach 0.1m\n  tilt 15deg\n  shiver 4deg f=3Hz\n  tilt -15deg\n}",
    "shiver 1deg f=7Hz",
    "tilt 200deg",
    "tilt 2deg v=20deg/s",
    "tilt 10deg v=1deg/s x3",
])
def test_rolls_measure_as_declared(text):
    """Tilts and shivers are told apart by their speed profile and frequency: slow
    alternating tilts stay tilts, a tremor between two tilts does not take them in, a
    7 Hz shiver is seen, a 200 deg tilt reads 200, a slow tilt holds no pause."""
    from aou_dsl.lang.descriptors import compare

    res = _built(text)
    assert compare(res.declared, res.measured.descriptors) == []
    kinds = [e.kind for e in res.measured.episodes]
    assert kinds.count("tilt") == sum(k == "tilt" for k, _, _ in res.trajectory.episodes)
    assert kinds.count("shiver") == sum(k == "shiver" for k, _, _ in res.trajectory.episodes)


@pytest.mark.parametrize("f", [1.0, 1.5, 3.0, 5.0, 7.0])
def test_every_shiver_frequency_the_compiler_accepts_is_seen(f):
    res = _built(f"shiver 1deg f={f}Hz for 2s\n")
    assert res.measured.descriptors["shiver_amplitude"] == pytest.approx(1.0, abs=0.5)
    assert res.measured.descriptors["tilt_angle"] is None


# --- output ---------------------------------------------------------------------------------


def test_json_has_each_episode_and_the_line_of_sight(synths):
    m = measure(synths["curious"].recording())
    out = m.to_json()
    assert [e["kind"] for e in out["episodes"]] == [e.kind for e in m.episodes]
    for e in out["episodes"]:
        assert set(e) == {"kind", "start", "end", "counts", "values"}
        if e["kind"] == "pause":
            assert e["values"]["duration"] == pytest.approx(e["end"] - e["start"], abs=1e-3)
    # The synthetic motion looks at the goal throughout.
    assert out["line_of_sight"]["max_deg"] < 0.01
    assert len(m.line_of_sight.angle) == len(m.line_of_sight.t) > 100


def test_episode_times_are_on_the_recordings_own_clock(synths):
    rec = synths["hesitant"].recording()
    stamped = rec.with_(t=rec.t + 1.7e9)
    a, b = measure(rec).to_json(), measure(stamped).to_json()
    for x, y in zip(a["episodes"], b["episodes"], strict=True):
        assert y["start"] == pytest.approx(x["start"] + 1.7e9, abs=1e-3)


def test_plot_of_a_recording_shades_its_measured_episodes(synths):
    from aou_dsl.media.plot import profile_data, profile_figure

    rec = synths["curious"].recording()
    d = profile_data(rec)
    kinds = [e.kind for e in measure(rec).episodes]
    assert d.measured and [k for k, _, _ in d.episodes] == kinds
    fig = profile_figure(d)
    assert len(fig.axes) == 5  # speed, distance, joints, velocities, line of sight
    assert [t.get_text() for t in fig.axes[0].texts] == kinds
    assert len(fig.axes[0].patches) == len(kinds)


# --- the self-check ------------------------------------------------------------------------


def test_an_acceleration_the_joints_cannot_produce_is_an_error(synths):
    """The measured peak is checked against J qdd + Jdot qd from the same joints: a peak
    they cannot produce is R406, never a reported value."""
    from aou_dsl.measuring import episodes as E
    from aou_dsl.measuring import measured as D

    ctx, bounds, _ = D._context(synths["hesitant"].recording())
    piece = next(p for p in E.pieces(ctx, bounds) if isinstance(p, E.Piece))
    u = (piece.p1 - piece.p0) / np.linalg.norm(piece.p1 - piece.p0)
    peak, _ = E.peak_acceleration(ctx, piece, u)  # consistent: no error
    assert peak == pytest.approx(0.05, rel=0.03)
    at = (piece.i0 + piece.i1) // 4
    with pytest.raises(AouError) as info:
        E._self_check(ctx, 10 * peak, at, 51, u, 0.0)
    assert info.value.diagnostics[0].code == "R406"


# --- peak accelerations of any smooth profile, and pauses beside a shiver --------------------


class _MinJerk(Synth):
    """Moves along the minimum-jerk law: s = L (10 u^3 - 15 u^4 + 6 u^5), u = t / T. Its
    acceleration is a bell that peaks at 10 sqrt(3) / 3 L / T^2, not a plateau."""

    @staticmethod
    def _bang(length: float, a: float, rate: float) -> np.ndarray:
        length = abs(length)
        duration = math.sqrt(10 * math.sqrt(3) / 3 * length / a)
        u = np.minimum(np.arange(1, int(math.ceil(duration * rate)) + 1) / rate / duration, 1)
        return length * (10 * u**3 - 15 * u**4 + 6 * u**5)


class _Cycloid(Synth):
    """Moves along the cycloidal law: s = L (u - sin(2 pi u) / (2 pi)), whose acceleration
    is one period of a sine, peaking at 2 pi L / T^2."""

    @staticmethod
    def _bang(length: float, a: float, rate: float) -> np.ndarray:
        length = abs(length)
        duration = math.sqrt(2 * math.pi * length / a)
        u = np.minimum(np.arange(1, int(math.ceil(duration * rate)) + 1) / rate / duration, 1)
        return length * (u - np.sin(2 * math.pi * u) / (2 * math.pi))


@pytest.mark.parametrize("law", [_MinJerk, _Cycloid], ids=["minimum-jerk", "cycloidal"])
@pytest.mark.parametrize("noise", [0.0, 1e-4], ids=["clean", "noisy"])
def test_a_bell_shaped_acceleration_reads_its_peak(law, noise):
    """A profile that holds no level (its acceleration a bell) peaks above any mean of it:
    its peak is read as the peak, within 1.5 % clean and 3 % under 1e-4 rad of noise."""
    s = law()
    s.line(-0.10, 0.05).hold(1.0).line(+0.05, 0.2).hold(1.0)
    m = measure(s.recording(noise, seed=3))
    peaks = [e.values["peak_acceleration"] for e in m.episodes if e.kind != "pause"]
    assert peaks == pytest.approx([0.05, 0.2], rel=0.03 if noise else 0.015)


def test_the_joints_path_takes_the_noise_across_it_out_of_the_travel():
    """Joints that move along one path (each a smooth function of the travel s) carry
    noise across that path too; moved back onto the path, the travel keeps only the
    noise along it, and says how much that is."""
    from aou_dsl.measuring.peaks import path_travel

    rng = np.random.default_rng(5)
    s = 0.03 * (1 - np.cos(np.linspace(0, math.pi, 120))) / 2  # the true travel [m]
    g = np.array([3.0, -2.0, 1.0, 4.0, -1.0, 2.0, 0.5])  # d(joint)/ds at s = 0 [rad/m]
    # The hand's travel is s + a . noise: a . g = 1 (it moves with the path), and it takes
    # noise across the path as well (a component orthogonal to g, twice as large).
    across = np.array([1.0, 1.0, 0.0, -0.5, 0.0, 0.0, 0.0])
    across -= (across @ g) / (g @ g) * g
    a = g / (g @ g) + 2.0 / np.linalg.norm(g) * across / np.linalg.norm(across)
    k = np.array([1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0])  # curvature across the hand's axis
    k = k - (a @ k) / (a @ a) * a
    q = np.outer(s, g) + np.outer(s**2, 20 * k)
    sigma = np.full(7, 1e-4)
    noise = rng.normal(0.0, 1e-4, q.shape)
    hand = s + (noise @ a)
    got = path_travel(hand, q + noise, sigma)
    assert got is not None
    travel, left = got
    assert left == pytest.approx(1e-4 / np.linalg.norm(g), rel=0.2)
    assert np.std(travel - s) == pytest.approx(left, rel=0.25)
    assert np.std(travel - s) < 0.6 * np.std(hand - s)
    # joints that do not follow one path are left alone
    assert path_travel(hand, q + rng.normal(0.0, 1e-3, q.shape), sigma) is None


class _SoftShiver(Synth):
    """A shiver whose envelope fades in and out linearly over its first and last cycle
    (not the compiler's sin^2)."""

    def shiver(self, amplitude: float, f: float, cycles: int) -> Synth:
        duration = cycles / f
        t = np.arange(1, int(round(duration * self.rate)) + 1) / self.rate
        env = np.minimum(np.minimum(t, duration - t) * f, 1.0)
        for x in amplitude / 2 * np.sin(2 * math.pi * f * t) * env:
            self._add(self._pose(), float(x))
        return self


@pytest.mark.parametrize("law", [Synth, _SoftShiver], ids=["sin2-envelope", "linear-envelope"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_pause_beside_a_shiver_ends_where_the_shiver_starts(law, seed):
    """A shiver's soft start and end hide under the noise (100 Hz, 1.5e-4 rad); the pauses
    on either side still measure within 50 ms."""
    s = law(rate=100.0)
    s.line(-0.05, 0.1).hold(1.0).shiver(2 * DEG, 1.2, 3).hold(1.2)
    m = measure(s.recording(1.5e-4, seed=seed))
    pauses = [e.t_end - e.t_start for e in m.episodes if e.kind == "pause"]
    assert len(pauses) == 2
    assert pauses == pytest.approx([1.0, 1.2], abs=0.05)
