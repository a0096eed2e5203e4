"""A staircase read through its crossings: a ramp rounded to steps comes back as the
ramp, and a ramp that stops comes back stopped, each within what the samples can say
(a crossing is known to half a sample in time; a hold to half a step)."""

from __future__ import annotations

import numpy as np

from aou_dsl.measuring.signal import JointNoise
from aou_dsl.measuring.staircase import dequantised, held_offsets, staircase_joints

STEP = 3.5e-3
H = 4e-3  # 250 Hz


def _jn(quantum: float, sigma: float = 0.0) -> JointNoise:
    return JointNoise(np.array([sigma]), np.array([quantum]), np.array([True]))


def test_a_rounded_ramp_reads_back_as_the_ramp():
    t = np.arange(0.0, 2.0, H)
    speed = 0.05  # rad/s: a step every 70 ms, 17 samples on each
    truth = 0.01 + speed * t
    stairs = np.round(truth / STEP) * STEP
    got = dequantised(t, stairs[:, None], _jn(STEP))[:, 0]
    inner = (t > 0.2) & (t < 1.8)  # the ends hold: the log shows no crossing there
    assert np.abs(got - truth)[inner].max() <= speed * H / 2 + 1e-12
    assert np.abs(stairs - truth)[inner].max() > 0.45 * STEP  # what the steps were


def test_a_ramp_that_stops_reads_back_stopped():
    t = np.arange(0.0, 3.0, H)
    truth = np.where(t < 1.0, 0.05 * t, 0.05)  # 0.05 rad/s, then still for 2 s
    stairs = np.round(truth / STEP) * STEP
    got = dequantised(t, stairs[:, None], _jn(STEP))[:, 0]
    still = t > 1.3
    assert np.ptp(got[still]) == 0.0  # a hold, not a slow ramp across it
    assert abs(got[still][0] - 0.05) <= STEP / 2


def test_only_a_joint_whose_rounding_is_its_noise_is_a_staircase():
    assert staircase_joints(_jn(STEP, sigma=1e-4)).all()  # 3.5e-3 / sqrt(12) = 1e-3
    assert not staircase_joints(_jn(STEP, sigma=2e-3)).any()
    assert not staircase_joints(_jn(0.0)).any()
    t = np.arange(0.0, 1.0, H)
    q = np.round(np.sin(t)[:, None] / STEP) * STEP
    assert dequantised(t, q, _jn(STEP, sigma=2e-3)) is q


def test_the_copies_hold_anywhere_within_a_step_and_cross_where_the_log_did():
    t = np.arange(0.0, 3.0, H)
    truth = np.where(t < 1.0, 0.05 * t, 0.05)
    stairs = (np.round(truth / STEP) * STEP)[:, None]
    rng = np.random.default_rng(1)
    offsets = np.stack([held_offsets(t, stairs, _jn(STEP), rng)[:, 0] for _ in range(200)])
    assert np.abs(offsets).max() <= STEP / 2
    # Over the long hold each copy draws its own place: together they fill the step.
    assert np.ptp(offsets[:, -1]) > 0.8 * STEP
    # At a crossing (the middle between two steps, when the log jumped) none.
    jump = int(np.flatnonzero(np.diff(stairs[:, 0]) != 0)[3]) + 1
    crossing = (t[jump - 1] + t[jump]) / 2
    at = [np.interp(crossing, t, o) for o in offsets]
    assert np.abs(at).max() <= 1e-12
