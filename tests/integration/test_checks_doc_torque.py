"""docs/checks.md's torque example of a noisy held pose is what the check gives: the
pose, rate, noise and share it states are read from the page and the check run on them."""

from __future__ import annotations

import re

import numpy as np

from aou_dsl.robot.load import load_arm
from aou_dsl.safety.torque import check_torque
from tests.conftest import ROOT

EXAMPLE = re.compile(
    r"held pose \(the Panda's ready pose, (?P<pose>[-\d., ]+) rad\) logged for "
    r"(?P<sec>[\d.]+) s at (?P<rate>[\d.]+) Hz with (?P<noise>[\de.-]+) rad of Gaussian "
    r"noise on every joint (?P<verdict>passes|fails) joint-torque at (?P<share>\d+) % of "
    r"(?P<joint>\w+)'s effort")


def test_the_documented_noisy_held_pose_gives_the_documented_torque():
    text = " ".join((ROOT / "docs" / "checks.md").read_text().split())
    m = EXAMPLE.search(text)
    assert m is not None, "docs/checks.md no longer states the held-pose example"
    pose = np.array([float(x) for x in m["pose"].split(",")])
    rate, sec, noise = float(m["rate"]), float(m["sec"]), float(m["noise"])
    arm = load_arm("panda")
    t = np.arange(0.0, sec, 1.0 / rate)
    shares = []
    for seed in range(3):  # any draw of the noise: the gravity torque dominates
        q = pose + np.random.default_rng(seed).normal(0.0, noise, (len(t), len(pose)))
        qd = np.gradient(q, t, axis=0)
        check, worst = check_torque(arm, t, q, qd, np.gradient(qd, t, axis=0))
        assert check.ok is (m["verdict"] == "passes")
        assert check.joint == m["joint"]
        shares.append(round(worst * 100))
    assert shares == [int(m["share"])] * 3
