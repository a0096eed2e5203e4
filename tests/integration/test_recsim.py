"""The recording simulator does what it claims: timing, noise, quantisation, cuts, columns,
units, determinism, and a simulated arm that follows the trajectory it is given."""

from __future__ import annotations

import csv
import io
import json
import math

import numpy as np
import pytest

from tests.conftest import BEHAVIOURS
from tests.recsim import PRESETS, Logger, dynamic_replay, record, to_csv_text, to_json_doc

PANDA = [f"panda_joint{i}" for i in range(1, 8)]
POSTURE = np.array([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.785398])


def _doc(robot: str = "panda", names=PANDA, posture=POSTURE, duration: float = 4.0,
         rate: float = 250.0, still: int = 6, amplitude: float = 0.2) -> dict:
    """A smooth rest-to-rest document of the trajectory format: every joint but column
    ``still`` swings by ``amplitude`` [rad] (a raised cosine, out and back); column ``still``
    holds its posture value exactly. ``t`` (N,), ``q``/``qd`` (N, J)."""
    t = np.arange(int(duration * rate) + 1) / rate
    w = 2 * math.pi / duration
    s = 0.5 * amplitude * (1 - np.cos(w * t))
    sd = 0.5 * amplitude * w * np.sin(w * t)
    gains = np.linspace(1.0, 0.5, len(names))
    gains[still] = 0.0
    q = posture + np.outer(s, gains)
    qd = np.outer(sd, gains)
    return {"format": "aou-trajectory/1", "behaviour": "swing", "state": None,
            "robot": robot, "ee_frame": None, "joint_names": list(names),
            "goal": {"position": [0.55, 0.0, 0.25]}, "t": t.tolist(), "q": q.tolist(),
            "qd": qd.tolist()}


def _exact(doc: dict, t: np.ndarray) -> np.ndarray:
    """The analytic positions of :func:`_doc`'s motion at times ``t`` [s], shape (K, J)."""
    tt = np.asarray(doc["t"])
    q0, q = np.asarray(doc["q"])[0], np.asarray(doc["q"])
    duration = tt[-1]
    amp = q[len(q) // 2] - q0  # the swing's peak, per joint
    return q0 + np.outer(0.5 * (1 - np.cos(2 * math.pi / duration * t)), amp)


@pytest.fixture(scope="module")
def doc() -> dict:
    return _doc()


def test_rate_and_jitter_statistics(doc):
    """The median step is the nominal period and the steps' spread is the set jitter."""
    rec = record(doc, Logger(rate=500.0, jitter=0.1, seed=7), dynamic=False)
    steps = np.diff(rec["t"])
    period = 1 / 500.0
    assert abs(np.median(steps) / period - 1) < 0.01
    assert abs(np.std(steps / period) / 0.1 - 1) < 0.15
    assert steps.min() >= Logger().min_step


def test_drops_and_gaps_happen_at_the_set_rates(doc):
    """Dropped samples double a step as often as set; long gaps occur as often as set and
    never exceed the longest gap (plus the steps a drop around them adds)."""
    period = 1 / 1000.0
    log = Logger(rate=1000.0, drop=0.05, gap_probability=0.01, max_gap=0.0167, seed=3)
    rec = record(doc, log, dynamic=False)
    steps = np.diff(rec["t"]) / period
    n = len(steps)
    doubled = np.mean((steps > 1.5) & (steps < 2.5))
    assert abs(doubled / 0.05 - 1) < 0.3
    gaps = np.sum(steps > 3.0 - 1e-9)
    expected = 0.01 * len(rec["t"]) / 0.95
    assert 0.5 * expected < gaps < 1.6 * expected
    assert steps.max() <= 16.7 + 3 and n > 3000


def test_ros_preset_timing_matches_a_real_joint_states_log(doc):
    """The ROS preset's steps have a median of 1.75 ms and range from 0.04 ms to about
    16.7 ms, as measured on a real /joint_states bag."""
    rec = record(doc, PRESETS["ros_joint_states"], dynamic=False)
    steps = np.diff(rec["t"]) * 1e3
    assert abs(np.median(steps) / 1.75 - 1) < 0.05
    assert steps.min() >= 0.04 - 1e-12
    assert 5.0 < steps.max() < 16.7 + 2 * 1.75


def test_cubic_interpolation_follows_the_motion(doc):
    """Samples at jittered instants lie on the smooth motion (error < 1e-9 rad), far
    closer than a straight line between the document's samples would (> 1e-7 rad)."""
    rec = record(doc, Logger(rate=333.0, jitter=0.3, seed=2), dynamic=False)
    err = np.abs(rec["q"] - _exact(doc, rec["t_true"])).max()
    assert err < 1e-9
    tt, q = np.asarray(doc["t"]), np.asarray(doc["q"])
    linear = np.column_stack([np.interp(rec["t_true"], tt, q[:, j]) for j in range(7)])
    assert np.abs(linear - _exact(doc, rec["t_true"])).max() > 1e-7


def test_noise_std_on_moving_joints_and_none_on_a_still_one(doc):
    """Moving joints carry noise of the set std (within 20 %); the joint that never moves
    reads its exact value in every row."""
    rec = record(doc, Logger(rate=1000.0, noise=1e-4, seed=11), dynamic=False)
    err = rec["q"] - rec["q_true"]
    std = err[:, :6].std(axis=0)
    assert np.all(np.abs(std / 1e-4 - 1) < 0.2), std
    col = rec["q"][:, 6]
    assert np.all(col == doc["q"][0][6])


def test_per_joint_noise(doc):
    """A noise std per joint reaches each joint with its own value (within 20 %)."""
    sigma = (1e-5, 2e-5, 5e-5, 1e-4, 2e-4, 5e-4, 1e-4)
    rec = record(doc, Logger(rate=1000.0, noise=sigma, seed=5), dynamic=False)
    std = (rec["q"] - rec["q_true"])[:, :6].std(axis=0)
    assert np.all(np.abs(std / np.array(sigma[:6]) - 1) < 0.2), std


def test_quantum_grid_is_respected_in_the_csv(doc):
    """With an encoder resolution every written position is a multiple of it."""
    quantum = 2.6e-7
    rec = record(doc, Logger(rate=500.0, noise=1e-4, quantum=quantum, seed=1), dynamic=False)
    rows = list(csv.reader(io.StringIO(to_csv_text(rec))))
    q = np.array(rows[1:], float)[:, 1:]
    k = q / quantum
    assert np.abs(k - np.round(k)).max() < 1e-3
    assert len(np.unique(np.diff(np.unique(q[:, 0])).round(12))) > 1  # not all one step


def test_decimals_are_written_exactly(doc):
    """With ``decimals=6`` every position cell has six decimals and the value is on the
    1e-6 grid; times keep full precision."""
    rec = record(doc, Logger(rate=250.0, decimals=6), dynamic=False)
    rows = list(csv.reader(io.StringIO(to_csv_text(rec))))
    for row in rows[1:50]:
        assert all(len(cell.split(".")[1]) == 6 for cell in row[1:])
    q = np.array(rows[1:], float)[:, 1:]
    assert np.abs(q * 1e6 - np.round(q * 1e6)).max() < 1e-6
    assert np.abs(q - rec["q_true"]).max() <= 5e-7 + 1e-12


def test_start_offset_begins_mid_motion(doc):
    """A start offset cuts that much of the motion: the log's first sample is taken within
    one period after it, while the arm is moving, and its clock starts at 0."""
    rec = record(doc, Logger(rate=200.0, start=1.2, seed=4), dynamic=False)
    assert 1.2 <= rec["t_true"][0] < 1.2 + 1 / 200.0
    assert rec["t"][0] == 0.0
    assert np.allclose(rec["q"][0], _exact(doc, rec["t_true"][:1])[0], atol=1e-7)
    assert np.abs(rec["q"][1] - rec["q"][0]).max() > 1e-4  # moving


def test_extra_columns_and_shuffled_order(doc):
    """Extra columns hold their constant value; shuffling reorders the columns but every
    joint keeps its own values."""
    extra = (("panda_finger_joint1", 0.04), ("panda_finger_joint2", 0.04))
    plain = record(doc, Logger(rate=250.0, extra=extra, seed=9), dynamic=False)
    mixed = record(doc, Logger(rate=250.0, extra=extra, shuffle=True, seed=9), dynamic=False)
    assert plain["joint_names"] == PANDA + ["panda_finger_joint1", "panda_finger_joint2"]
    assert sorted(mixed["joint_names"]) == sorted(plain["joint_names"])
    assert mixed["joint_names"] != plain["joint_names"]
    for j, name in enumerate(plain["joint_names"]):
        k = mixed["joint_names"].index(name)
        assert np.array_equal(plain["q"][:, j], mixed["q"][:, k])
    assert np.all(plain["q"][:, 7:] == 0.04)


def test_continuous_joints_wrap_and_others_do_not():
    """With wrapping, a UR joint (limits a full turn apart) that passes pi is written in
    [-pi, pi) and unwraps to the motion; panda joints (limited) are never wrapped."""
    ur = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
          "wrist_2_joint", "wrist_3_joint"]
    posture = np.array([3.0, -1.3, 1.8, -2.1, -1.5708, 0.0])
    d = _doc("ur5", ur, posture, still=5, amplitude=0.5)
    rec = record(d, Logger(rate=250.0, wrap=True), dynamic=False)
    pan = rec["q"][:, 0]
    assert pan.min() >= -math.pi and pan.max() < math.pi and pan.min() < 0
    assert np.allclose(np.unwrap(pan), rec["q_true"][:, 0])
    assert np.array_equal(rec["q"][:, 1:], rec["q_true"][:, 1:])
    panda = _doc(posture=POSTURE + np.array([0, 0, 0, 0, 0, 1.1, 0]))  # joint6 passes pi
    rec = record(panda, Logger(rate=250.0, wrap=True), dynamic=False)
    assert np.array_equal(rec["q"], rec["q_true"])


def test_wrong_units(doc):
    """Time in ms and angles in degrees scale exactly; prismatic extra columns keep
    metres."""
    extra = (("panda_finger_joint1", 0.04),)
    base = record(doc, Logger(rate=250.0, extra=extra, seed=1), dynamic=False)
    wrong = record(doc, Logger(rate=250.0, extra=extra, time_unit="ms", angle_unit="deg",
                               seed=1), dynamic=False)
    assert np.allclose(wrong["t"], base["t"] * 1000.0)
    assert np.allclose(wrong["q"][:, :7], np.degrees(base["q"][:, :7]))
    assert np.all(wrong["q"][:, 7] == 0.04)


def test_seed_makes_the_log_deterministic(doc):
    """The same seed writes the same bytes; another seed writes other ones."""
    log = PRESETS["ros_joint_states"]
    a = to_csv_text(record(doc, log, dynamic=False))
    b = to_csv_text(record(doc, log, dynamic=False))
    c = to_csv_text(record(doc, log.with_(seed=log.seed + 1), dynamic=False))
    assert a == b and a != c


def test_json_writer_has_the_trajectory_format(doc):
    """The JSON writer gives a trajectory-format document that round-trips through JSON,
    with the goal only when asked for."""
    rec = record(doc, Logger(rate=100.0, decimals=6), dynamic=False)
    out = json.loads(json.dumps(to_json_doc(rec)))
    assert out["format"] == "aou-trajectory/1"
    assert out["robot"] == "panda" and out["joint_names"] == PANDA
    assert out["goal"] == {"position": [0.55, 0.0, 0.25]}
    assert np.array(out["q"]).shape == (len(out["t"]), 7)
    assert "goal" not in to_json_doc(rec, with_goal=False)


def test_every_preset_records(doc):
    """Each preset produces a strictly increasing log with every arm joint present."""
    for name, log in PRESETS.items():
        rec = record(doc, log, dynamic=False)
        assert np.all(np.diff(rec["t"]) > 0), name
        assert set(PANDA) <= set(rec["joint_names"]), name


def test_dynamic_replay_of_a_short_motion(doc):
    """The simulated arm starts at q[0], returns a signal at the physics rate and follows
    the reference within a few mrad, with a constant joint that barely moves."""
    t, q = dynamic_replay(doc, physics_rate=1000.0)
    assert np.allclose(np.diff(t), 1e-3) and t[0] == 0.0 and len(t) == 4001
    assert np.abs(q[0] - POSTURE).max() < 1e-3
    assert np.abs(q - _exact(doc, t)).max() < 5e-3
    assert np.ptp(q[:, 6]) < 1e-3


@pytest.fixture(scope="module")
def hesitant(tmp_path_factory) -> dict:
    from aou_dsl.cli.commands import main

    out = tmp_path_factory.mktemp("recsim") / "hesitant.json"
    assert main(["compile", str(BEHAVIOURS / "hesitant.aou"), "-o", str(out)]) == 0
    return json.loads(out.read_text())


@pytest.mark.slow
def test_dynamic_replay_tracks_the_hesitant_behaviour(hesitant):
    """On the hesitant behaviour the simulated arm tracks the compiled motion within a few
    mrad, lags it by a few milliseconds, and ends where it ends."""
    from scipy.interpolate import CubicHermiteSpline

    t, q = dynamic_replay(hesitant)
    ref = CubicHermiteSpline(hesitant["t"], hesitant["q"], hesitant["qd"], axis=0)(t)
    assert np.abs(q - ref).max() < 5e-3
    lags = range(0, 20)
    best = min(lags, key=lambda k: np.abs(q[k:] - ref[:len(ref) - k]).max())
    assert 1 <= best <= 10
    assert np.abs(q[-1] - ref[-1]).max() < 2e-3


@pytest.mark.slow
def test_dynamic_recording_keeps_still_joints_exact(hesitant):
    """A dynamic recording of the hesitant behaviour with noise: the noise lands on the
    moving joints only, and an added constant column is constant to the last bit."""
    log = PRESETS["franka_fci"]
    rec = record(hesitant, log)
    names = rec["joint_names"]
    finger = rec["q"][:, names.index("panda_finger_joint1")]
    assert np.all(finger == 0.04)
    arm = [names.index(n) for n in PANDA]
    err = rec["q"][:, arm] - rec["q_true"]
    assert np.all(np.abs(err.std(axis=0) / 3e-5 - 1) < 0.2)
