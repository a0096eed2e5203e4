"""The kinematics of the re-noised copies (aou_dsl/measuring/uncertainty.py): the hand's
pose of a copy is the smoothed recording's plus the Jacobian times the copy's noise.

That Jacobian, computed for all samples at once, is held to Pinocchio's
``computeFrameJacobian`` on the vendor arms; the first-order pose to the exact one
within what the noise squared explains; and the intervals measured with it to those
measured with every copy's exact kinematics.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from aou_dsl.core.trajectory import Trajectory
from aou_dsl.measuring.linearised import Linearised
from aou_dsl.measuring.measured import _measure, measure
from aou_dsl.measuring.uncertainty import attach
from aou_dsl.robot.batch_fk import batch_fk, batch_fk_jacobian
from aou_dsl.robot.load import load_arm
from tests.conftest import BEHAVIOURS
from tests.integration.test_recordings import build
from tests.recsim import noisy, record


@pytest.mark.parametrize("robot", ["panda", "ur5"])
def test_the_batch_jacobian_is_pinocchios(robot):
    arm = load_arm(robot)
    q = np.random.default_rng(3).uniform(-2.0, 2.0, (20, arm.model.nq))
    pos, rot, jac = batch_fk_jacobian(arm, q)
    want_pos, want_rot = batch_fk(arm, q)
    assert np.array_equal(pos, want_pos) and np.array_equal(rot, want_rot)
    data = arm.model.createData()
    for k in range(len(q)):
        want = pin.computeFrameJacobian(arm.model, data, q[k], arm.frame_id,
                                        pin.LOCAL_WORLD_ALIGNED)
        assert np.allclose(jac[k], want, atol=1e-12), k


@pytest.mark.parametrize("robot", ["panda", "ur5"])
def test_a_copys_pose_is_the_exact_one_to_the_noise_squared(robot):
    """1e-3 rad on every joint moves the hand by millimetres; the first-order pose
    misses the exact one by about the noise squared times the arm's reach."""
    arm = load_arm(robot)
    rng = np.random.default_rng(4)
    q0 = np.cumsum(rng.normal(0.0, 2e-3, (500, arm.model.nq)), axis=0) + 0.3
    dq = rng.normal(0.0, 1e-3, q0.shape)
    fk = Linearised(arm)
    fk(q0, "grid")  # the base: exact, and the point the copies are expanded about
    pos, rot = fk(q0 + dq, "grid")
    want_pos, want_rot = batch_fk(arm, q0 + dq)
    base_pos, base_rot = batch_fk(arm, q0)
    moved = np.abs(want_pos - base_pos).max()
    assert moved > 1e-3
    assert np.abs(pos - want_pos).max() < 3e-5 < 0.02 * moved
    assert np.abs(rot - want_rot).max() < 3e-5
    # A rotation stays one (to third order).
    eye = np.einsum("nji,njk->nik", rot, rot)
    assert np.abs(eye - np.eye(3)).max() < 1e-7


def test_intervals_with_first_order_copies_are_those_with_exact_ones():
    """The fearful (retreats, a shiver) logged at 250 Hz with 6e-4 rad: every interval
    measured with the copies' first-order kinematics is within 2 % of its width of the
    one measured with each copy's own forward kinematics."""
    doc = build((BEHAVIOURS / "fearful.aou").read_text(), "fearful")[0]
    rec = record(doc, noisy(6e-4, 250.0, 3), dynamic=False)
    tr = Trajectory(rec["t"], rec["q"], tuple(rec["joint_names"]), rec["robot"], None,
                    tuple(rec["goal"]["position"]))
    fast = measure(tr)
    exact, jn = _measure(tr)
    attach(exact, tr, jn, lambda r, pinned, _fk: _measure(r, pinned))
    checked = 0
    for k, s in fast.uncertainty.items():
        e = exact.uncertainty[k]
        assert (s.stable, s.absent_in) == (e.stable, e.absent_in), k
        if s.low is None or s.sd in (None, 0.0):
            assert (s.low, s.high) == (e.low, e.high), k
            continue
        width = e.high - e.low
        assert abs(s.low - e.low) <= 0.02 * width and abs(s.high - e.high) <= 0.02 * width, k
        checked += 1
    assert checked >= 4


def test_the_long_slope_through_the_fft_is_the_savitzky_golay_one():
    """The slow-motion check's 0.3 s slope at 1 kHz (301 weights) runs through the FFT:
    the same values as the direct filter, ends included, to rounding."""
    from aou_dsl.measuring.rest import _long_slope
    from aou_dsl.measuring.signal import smooth

    rng = np.random.default_rng(5)
    t = np.arange(20000) * 1e-3
    q = np.column_stack([0.3 * np.sin(1.7 * t) + 1.2, 0.05 * t ** 2 - 0.4,
                         rng.normal(0.0, 3e-4, len(t))])
    got, want = _long_slope(q, 301, 1e-3), smooth(q, 301, 1, 1e-3, order=1)
    assert got.shape == want.shape
    assert np.abs(got - want).max() < 1e-12
