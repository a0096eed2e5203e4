"""The kinematics-agreement check can fail: a compiler model that puts the hand 2 mm away
from where the URDF (the replay's own kinematics, and PyBullet's) puts it is refused at
the sample where they disagree most, with that distance; the arm's true model passes the
same motion."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from aou_dsl.core.trajectory import Trajectory
from aou_dsl.robot.load import load_arm
from aou_dsl.safety import replay as replay_module

GOAL = (0.55, 0.0, 0.25)
RATE = 250.0


def _motion(arm) -> Trajectory:
    """Joint 4 turns 0.3 rad and back, rest to rest, from the posture."""
    s = np.linspace(0.0, 1.0, 300)
    q = np.tile(np.array(arm.spec.posture), (len(s), 1))
    q[:, 3] += 0.3 * np.sin(np.pi * s) ** 2
    return Trajectory(s * (len(s) - 1) / RATE, q, arm.joint_names, "panda", None, GOAL)


def _agreement(monkeypatch, arm):
    monkeypatch.setattr(replay_module, "load_arm", lambda *args, **kwargs: arm)
    report = replay_module.replay(_motion(load_arm("panda")))
    (check,) = [c for c in report.checks if c.name == "kinematics-agreement"]
    return check, report


def test_a_model_two_millimetres_off_the_urdf_fails_the_agreement_check(monkeypatch):
    import pinocchio as pin

    arm = load_arm("panda")
    model = pin.Model(arm.model)
    placement = model.jointPlacements[5]  # joint 5's origin, 2 mm along its parent's z
    placement.translation = placement.translation + np.array([0.0, 0.0, 0.002])
    model.jointPlacements[5] = placement
    wrong = replace(arm, model=model)
    check, report = _agreement(monkeypatch, wrong)
    assert not check.ok and not report.ok
    assert check.value == pytest.approx(0.002, abs=1e-6)  # a shift moves the hand as far
    assert check.limit == replay_module.AGREE_POSITION
    assert report.agreement["position_mm"] == pytest.approx(2.0, abs=1e-3)


def test_the_arms_own_model_agrees_on_the_same_motion(monkeypatch):
    check, report = _agreement(monkeypatch, load_arm("panda"))
    assert check.ok and check.value < 1e-6 and report.ok
