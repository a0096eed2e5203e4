"""The torque check asks what following a trajectory takes (inverse dynamics), so it can
fail; the dynamic replay's tracking error is a check of its own."""

import json

import numpy as np
import pytest

from aou_dsl.cli.commands import EXIT_ERRORS, main
from aou_dsl.core.trajectory import Trajectory
from aou_dsl.robot.load import load_arm
from aou_dsl.safety.replay import replay
from aou_dsl.safety.torque import TRACKING_LIMIT, check_torque, inverse_dynamics
from tests.conftest import BEHAVIOURS
from tests.inputgen import json_doc, motion

RATE = 250.0
ARM = load_arm("panda")
POSTURE = np.array(ARM.spec.posture)


def _swing(freq: float, amp: float = 0.3, seconds: float = 2.0):
    """The Panda's shoulder (joint 2) swinging at ``freq`` Hz, the derivatives exact."""
    t = np.arange(int(seconds * RATE)) / RATE
    w = 2 * np.pi * freq
    q = np.tile(POSTURE, (len(t), 1))
    qd, qdd = np.zeros_like(q), np.zeros_like(q)
    q[:, 1] += amp * np.sin(w * t)
    qd[:, 1] = amp * w * np.cos(w * t)
    qdd[:, 1] = -amp * w * w * np.sin(w * t)
    return t, q, qd, qdd


def test_at_rest_the_torques_hold_the_arm_against_gravity_alone():
    """Still, the torque is gravity's: none on the vertical first axis, some on the
    shoulder, and it does not change with time."""
    q = np.tile(POSTURE, (3, 1))
    tau = inverse_dynamics(ARM, q, np.zeros_like(q), np.zeros_like(q))
    assert abs(tau[0, 0]) < 1e-9  # joint 1 turns about the vertical: gravity gives no torque
    assert abs(tau[0, 1]) > 1.0
    assert np.allclose(tau, tau[0])


def test_a_swing_too_fast_for_the_shoulder_fails_the_torque_check_at_its_joint():
    """At 4 Hz the shoulder needs several times its 87 N m; at 0.2 Hz it does not. The
    failure names the joint, the sample of the peak and the torque past the limit."""
    t, q, qd, qdd = _swing(4.0)
    check, ratio = check_torque(ARM, t, q, qd, qdd)
    assert not check.ok and check.name == "joint-torque"
    assert check.joint == "panda_joint2" and ratio > 2.0
    assert abs(check.value) == pytest.approx(ratio * 87.0) and check.limit == 87.0
    tau = inverse_dynamics(ARM, q, qd, qdd)
    assert check.time == pytest.approx(t[np.argmax(np.abs(tau[:, 1]))])
    slow, _ = check_torque(ARM, *_swing(0.2))
    assert slow.ok


def test_the_replay_of_a_too_fast_swing_fails_torque_and_tracking(tmp_path, capsys):
    """`aouc check`: the motors capped at their limit read back at most their limit (the
    old check could not fail), but inverse dynamics and the lag both fail, each with its
    own code."""
    t, q, qd, qdd = _swing(4.0)
    tr = Trajectory(t, q, ARM.joint_names, "panda", None, (0.55, 0.0, 0.25), qd, qdd)
    report = replay(tr, dynamic=True)
    failed = {c.name: c for c in report.failed()}
    assert report.dynamic["motor_torque_max_ratio"] <= 1.0 + 1e-9
    assert report.dynamic["torque_max_ratio"] > 2.0
    assert failed["joint-torque"].joint == "panda_joint2"
    assert failed["tracking-error"].joint == "panda_joint2"
    assert abs(failed["tracking-error"].value) > TRACKING_LIMIT
    path = tmp_path / "fast.json"
    path.write_text(json.dumps(json_doc(t, q, qd=qd.tolist(), qdd=qdd.tolist())))
    assert main(["check", str(path)]) == EXIT_ERRORS
    err = capsys.readouterr().err
    assert " C320 " in err and " C321 " in err


def test_noise_is_not_torque_but_a_swing_hidden_in_noise_still_fails():
    """A held pose recorded with 1 mrad of noise: the replay's motors saturate chasing it
    (their read-back torque is exactly the cap, which the old check passed at 100 %),
    while the torque the motion takes, from the filtered signal as the limits judge a
    recording, is gravity's and passes. The shoulder swing too fast for its motor,
    recorded with the same noise, still fails."""
    rng = np.random.default_rng(3)
    t, q = motion(n=500, rate=RATE)
    tr = Trajectory(t, q + rng.normal(0.0, 1e-3, q.shape), ARM.joint_names, "panda", None,
                    (0.55, 0.0, 0.25))
    report = replay(tr, dynamic=True)
    (torque,) = [c for c in report.checks if c.name == "joint-torque"]
    assert report.dynamic["motor_torque_max_ratio"] == pytest.approx(1.0)
    assert torque.ok and "filtered signal" in torque.detail, torque
    t, q, _, _ = _swing(4.0)
    swing = Trajectory(t, q + rng.normal(0.0, 1e-3, q.shape), ARM.joint_names, "panda",
                       None, (0.55, 0.0, 0.25))
    (torque,) = [c for c in replay(swing, dynamic=True).checks if c.name == "joint-torque"]
    assert not torque.ok and torque.joint == "panda_joint2", torque


def test_a_shipped_behaviour_passes_torque_and_tracking_on_the_panda(capsys):
    assert main(["check", str(BEHAVIOURS / "fearful.aou"), "--format", "json"]) == 0
    report = json.loads(capsys.readouterr().out)
    checks = {c["name"]: c for c in report["checks"]}
    assert checks["joint-torque"]["ok"] and checks["tracking-error"]["ok"]
    assert 0.0 < report["dynamic"]["torque_max_ratio"] < 1.0
    assert report["dynamic"]["tracking_max_rad"] < TRACKING_LIMIT
