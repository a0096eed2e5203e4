"""The limit checks name the sample, joint, value and limit where a motion comes nearest
its limits, and fail past them: a velocity one joint exceeds at one sample, a position
past the lower end of a range, a jerk a controller computes from positions sent at its
rate (timed by the newest tick of its difference), each against limits given per
joint, worked out here from the definitions."""

from __future__ import annotations

import numpy as np
import pytest

from aou_dsl.robot.load import load_arm
from aou_dsl.safety.limits import SLACK, check_limits, check_rates

JOINTS = ("a", "b", "c")


def _rest(arm, n: int = 400) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(n) / 250.0
    return t, np.tile(np.asarray(arm.spec.posture, float), (n, 1))


def test_a_velocity_over_one_joints_limit_fails_there():
    arm = load_arm("panda")
    t, q = _rest(arm)
    qd, qdd = np.zeros_like(q), np.zeros_like(q)
    qd[:, 0] = 0.9 * arm.vmax[0]  # near but within, everywhere
    qd[123, 5] = -1.2 * arm.vmax[5]  # past, once, on another joint
    pos, vel, acc = check_limits(arm, t, q, qd, qdd)
    assert pos.ok and acc.ok
    assert not vel.ok
    assert (vel.time, vel.joint) == (float(t[123]), arm.joint_names[5])
    assert vel.value == -1.2 * arm.vmax[5] and vel.limit == arm.vmax[5]


def test_a_velocity_within_its_slack_passes_and_names_the_nearest_sample():
    arm = load_arm("panda")
    t, q = _rest(arm)
    qd, qdd = np.zeros_like(q), np.zeros_like(q)
    qd[200, 2] = arm.vmax[2] * (1.0 + SLACK / 2)
    _, vel, _ = check_limits(arm, t, q, qd, qdd)
    assert vel.ok and (vel.time, vel.joint) == (float(t[200]), arm.joint_names[2])


def test_a_position_past_the_lower_end_fails_against_that_end():
    arm = load_arm("panda")
    t, q = _rest(arm)
    q[50:60, 3] = arm.lower[3] - 0.01
    pos, _, _ = check_limits(arm, t, q, np.zeros_like(q), np.zeros_like(q))
    assert not pos.ok and pos.joint == arm.joint_names[3] and pos.time == float(t[50])
    assert pos.value == pytest.approx(arm.lower[3] - 0.01, abs=1e-12)
    assert pos.limit == pytest.approx(arm.lower[3], abs=1e-12)


def test_a_jump_of_acceleration_fails_the_jerk_at_its_newest_tick():
    rate, t0 = 1000.0, 2.0
    n = 60
    q = np.zeros((n, 3))
    k = 30  # joint c accelerates at 4 rad/s^2 from tick k on
    q[k:, 2] = 0.5 * 4.0 * ((np.arange(k, n) - (k - 1)) / rate) ** 2
    jmax = np.array([100.0, 100.0, 1000.0])
    (jerk,) = check_rates(JOINTS, q, rate, t0=t0, jmax=jmax)
    d3 = np.diff(q, 3, axis=0) * rate**3
    i = int(np.argmax(np.abs(d3[:, 2])))
    assert not jerk.ok and jerk.joint == "c" and jerk.limit == 1000.0
    assert jerk.value == d3[i, 2] and abs(jerk.value) > 1000.0
    assert jerk.time == t0 + (i + 3) / rate  # the newest of the four ticks


def test_each_order_is_checked_against_its_own_limits():
    rate = 500.0
    q = np.zeros((20, 3))
    q[10:, 0] = np.arange(10) / 128.0  # 3.90625 rad/s from tick 10 on, exactly
    vmax, amax, jmax = np.full(3, 3.5), np.full(3, 1e6), np.full(3, 1e12)
    vel, acc, jerk = check_rates(JOINTS, q, rate, vmax=vmax, amax=amax, jmax=jmax)
    assert [c.name for c in (vel, acc, jerk)] == ["joint-rate-velocity",
                                                 "joint-rate-acceleration", "joint-jerk"]
    assert not vel.ok and vel.value == 500.0 / 128.0 and vel.joint == "a"
    assert vel.time == 11 / rate  # the first of the equal differences, at its newer tick
    assert acc.ok and jerk.ok
    assert check_rates(JOINTS, q[:3], rate, jmax=jmax) == []  # too short for a third
