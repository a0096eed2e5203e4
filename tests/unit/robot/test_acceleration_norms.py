"""The magnitude of the end-effector's classical acceleration at every row at once
(``ArmModel.acceleration_norms``, what the compiler's Cartesian peak looks through) is
Pinocchio's, one sample at a time, up to rounding: on the shipped arms (joints about
coordinate axes) and on a hand-made chain whose joints turn about skew and negative axes.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from aou_dsl.robot.load import load_arm


def _pinocchio_norms(arm, q, qd, qdd) -> np.ndarray:
    import pinocchio as pin

    data = arm.model.createData()
    out = np.empty(len(q))
    for k in range(len(q)):
        pin.forwardKinematics(arm.model, data, q[k], qd[k], qdd[k])
        pin.updateFramePlacements(arm.model, data)
        acc = pin.getFrameClassicalAcceleration(arm.model, data, arm.frame_id,
                                                pin.LOCAL_WORLD_ALIGNED).linear
        out[k] = np.linalg.norm(acc)
    return out


def _motions(arm, rows: int, seed: int):
    rng = np.random.default_rng(seed)
    lo = np.maximum(arm.lower, -np.pi)
    hi = np.minimum(arm.upper, np.pi)
    return (rng.uniform(lo, hi, (rows, arm.n)), rng.normal(0, 2, (rows, arm.n)),
            rng.normal(0, 10, (rows, arm.n)))


def _close(got, want) -> bool:
    return bool(np.abs(got - want).max() <= 1e-12 * max(1.0, float(np.abs(want).max())))


@pytest.mark.parametrize("robot", ["panda", "ur5", "z1", "kinova", "xarm7"])
def test_the_norms_of_a_shipped_arm_are_pinocchios(robot):
    arm = load_arm(robot)
    q, qd, qdd = _motions(arm, 200, 3)
    got = arm.acceleration_norms(q, qd, qdd)
    assert got is not None and got.shape == (200,)
    assert _close(got, _pinocchio_norms(arm, q, qd, qdd))


def _chain_arm(axes, joint=None):
    """The panda's spec over a hand-made chain of revolute joints about ``axes`` (or one
    ``joint`` model in the middle), each placed by a random rotation and offset."""
    import pinocchio as pin

    rng = np.random.default_rng(11)
    model = pin.Model()
    parent = 0
    for i, axis in enumerate(axes):
        placement = pin.SE3(pin.exp3(rng.normal(0, 1, 3)), rng.normal(0, 0.2, 3))
        jm = (joint if joint is not None and i == len(axes) // 2 else
              pin.JointModelRevoluteUnaligned(*axis))
        parent = model.addJoint(parent, jm, placement, f"j{i}")
    frame = model.addFrame(pin.Frame("tip", parent, 0, pin.SE3(np.eye(3), rng.normal(
        0, 0.2, 3)), pin.FrameType.OP_FRAME))
    arm = load_arm("panda")
    return replace(arm, model=model, frame_id=frame, lower=-np.pi * np.ones(model.nq),
                   upper=np.pi * np.ones(model.nq))


def test_the_norms_of_joints_about_skew_and_negative_axes_are_pinocchios():
    skew = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    axes = [(0.0, 0.0, -1.0), tuple(skew), (0.0, -1.0, 0.0), (1.0, 0.0, 0.0),
            (-0.6, 0.0, 0.8), (0.0, 1.0, 0.0), (-1.0, 0.0, 0.0)]
    arm = _chain_arm(axes)
    rows = 150
    q, qd, qdd = (x[:, :len(axes)] for x in _motions(arm, rows, 4))
    got = arm.acceleration_norms(q, qd, qdd)
    assert got is not None
    assert _close(got, _pinocchio_norms(arm, q, qd, qdd))


def test_an_arm_with_a_prismatic_joint_has_no_norms_this_way():
    import pinocchio as pin

    arm = _chain_arm([(0.0, 0.0, 1.0)] * 3, joint=pin.JointModelPZ())
    q = np.zeros((2, 3))
    assert arm.acceleration_norms(q, q, q) is None
