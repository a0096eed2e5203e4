"""Recordings an approach's first speed-up and last slow-down do not describe: one the
log cuts while the hand still moves fast, and one whose hand surges mid-way. Made from
a compiled behaviour through the recording simulator (tests/recsim.py), so the truth is
what the file declares."""

from __future__ import annotations

import numpy as np

from aou_dsl.core.trajectory import Trajectory
from aou_dsl.measuring.measured import measure
from aou_dsl.robot.batch_fk import batch_fk
from aou_dsl.robot.load import load_arm
from tests.conftest import BEHAVIOURS
from tests.integration.test_recordings import build
from tests.recsim import noisy, record


def _recorded(name: str) -> tuple[dict, dict]:
    doc, want, _ = build((BEHAVIOURS / f"{name}.aou").read_text(), name)
    return record(doc, noisy(1e-4, 250.0, 7), dynamic=False), want


def _trajectory(rec: dict, k: int) -> Trajectory:
    return Trajectory(rec["t"][:k], rec["q"][:k], tuple(rec["joint_names"]), rec["robot"],
                      None, tuple(rec["goal"]["position"]))


def test_a_log_cut_while_the_hand_slows_down_is_not_trusted_on_its_peak():
    """The fearful behaviour's first approach, logged until its hand has slowed to 90 %
    of its top speed and no further: most of its stop is not in the log, and the peak
    read from what is there is no measurement. R411 names the approach's acceleration
    and it is untrusted. The whole log is not cut, and reads the declared value."""
    rec, want = _recorded("fearful")
    arm = load_arm(rec["robot"])
    cols = [rec["joint_names"].index(j) for j in arm.joint_names]
    pos = batch_fk(arm, np.asarray(rec["q"], float)[:, cols])[0]
    t = np.asarray(rec["t"], float)
    w = 12  # 48 ms: the hand's speed from its displacement, above the noise
    speed = np.linalg.norm(pos[w:] - pos[:-w], axis=1) / (t[w:] - t[:-w])
    whole = measure(_trajectory(rec, len(t)))
    first = whole.episodes[0]
    assert first.kind == "approach"
    top = int(np.argmax(speed[:int(np.searchsorted(t, first.t_end)) - w]))
    k = top + int(np.argmax(speed[top:] < 0.9 * speed[top])) + w
    m = measure(_trajectory(rec, k))
    cut = [d for d in m.diagnostics if d.code == "R411" and "cuts a motion" in d.message]
    assert cut, [d.message for d in m.diagnostics]
    assert cut[0].fields["descriptors"] == ["approach_acceleration"]
    assert not m.uncertainty["approach_acceleration"].stable
    assert not [d for d in whole.diagnostics if "cuts a motion" in d.message]
    assert whole.uncertainty["approach_acceleration"].stable
    assert abs(whole.descriptors.get("approach_acceleration") - want["approach_acceleration"]) \
        < 0.05 * want["approach_acceleration"]
