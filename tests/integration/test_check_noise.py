"""``aouc check`` on a recording judges its limits on the filtered signal: encoder noise
alone never fails a limit, and a real violation hidden in the noise still fails it.

The recordings are the compiled hesitant behaviour logged by tests/recsim.py (its own
motion, no dynamic replay) with noise up to 1e-3 rad; the violation is a bump added to
one joint whose true acceleration (computed here from its formula, not by the code under
test) exceeds the robot's limit.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from aou_dsl.api import check
from aou_dsl.core.trajectory import Trajectory
from aou_dsl.driver.builder import build_file
from aou_dsl.robot.load import load_arm
from tests.conftest import BEHAVIOURS
from tests.recsim import Logger, record


@pytest.fixture(scope="module")
def hesitant() -> dict:
    res = build_file(str(BEHAVIOURS / "hesitant.aou"), check=False)
    assert res.ok
    return res.document


def _trajectory(rec: dict, q: np.ndarray | None = None) -> Trajectory:
    return Trajectory(rec["t"], rec["q"] if q is None else q, tuple(rec["joint_names"]),
                      rec["robot"], None, tuple(rec["goal"]["position"]))


def _limits(report) -> dict:
    return {c.name: c for c in report.checks
            if c.name in ("joint-position", "joint-velocity", "joint-acceleration")}


@pytest.mark.parametrize("noise,rate", [(3e-4, 1000.0), (1e-3, 250.0), (1e-3, 1000.0)])
def test_noise_alone_never_fails_a_limit(hesitant, noise, rate):
    rec = record(hesitant, Logger(rate=rate, jitter=0.05, drop=0.005, noise=noise, seed=4),
                 dynamic=False)
    checks = _limits(check(_trajectory(rec), dynamic=False))
    assert all(c.ok for c in checks.values()), checks
    assert "filtered signal" in checks["joint-acceleration"].detail


def _bump(t: np.ndarray, t0: float, width: float, height: float) -> np.ndarray:
    """A raised cosine of ``height`` [rad] over ``width`` [s] from ``t0``: its largest
    acceleration is height / 2 * (2 pi / width)^2."""
    x = np.clip((t - t0) / width, 0.0, 1.0)
    return height / 2 * (1 - np.cos(2 * math.pi * x))


def test_a_real_violation_hidden_in_noise_still_fails(hesitant):
    """A 0.1 rad bump over 0.4 s on joint 2 during the first pause (true peak 12.3
    rad/s^2, over the panda's 7.5) under 1e-3 rad of noise at 250 Hz: the acceleration
    check fails there. The same bump a third as high (4.1 rad/s^2) passes."""
    arm = load_arm("panda")
    j = list(arm.joint_names).index("panda_joint2")
    limit = float(arm.amax[j])
    for height, fails in ((0.1, True), (0.033, False)):
        rec = record(hesitant, Logger(rate=250.0, jitter=0.05, noise=1e-3, seed=6),
                     dynamic=False)
        t = np.asarray(rec["t"], float)
        col = list(rec["joint_names"]).index("panda_joint2")
        q = np.array(rec["q"], float)
        q[:, col] += _bump(t, 2.8, 0.4, height)
        true_peak = height / 2 * (2 * math.pi / 0.4) ** 2
        assert (true_peak > limit) is fails
        acc = _limits(check(_trajectory(rec, q), dynamic=False))["joint-acceleration"]
        assert acc.ok is not fails, acc
        if fails:
            assert acc.joint == "panda_joint2" and 2.8 <= acc.time <= 3.2


def test_plot_of_a_recording_draws_the_filtered_speed_over_the_raw(hesitant):
    """The speed panel of a noisy recording: the filtered speed (the filter measure and
    check use) in front, the raw differences faint behind it. During the first pause
    (the arm still, 2.5 to 3.8 s) the raw speed is mostly noise, the filtered one
    several times quieter."""
    from aou_dsl.media.plot import profile_data, profile_figure

    rec = record(hesitant, Logger(rate=1000.0, jitter=0.05, noise=3e-4, seed=2),
                 dynamic=False)
    d = profile_data(_trajectory(rec))
    assert len(d.raw_speed) == len(rec["t"]) and d.noise == pytest.approx(3e-4, rel=0.2)
    still = (d.t > 2.5) & (d.t < 3.8)
    raw_still = (d.raw_t > 2.5) & (d.raw_t < 3.8)
    assert np.median(d.speed[still]) < 0.25 * np.median(d.raw_speed[raw_still])
    lines = profile_figure(d).axes[0].get_lines()
    assert [ln.get_alpha() is not None and ln.get_alpha() < 0.5 for ln in lines] == [
        True, False]


def _staircase(hesitant: dict) -> Trajectory:
    """Hesitant logged at 250 Hz by an encoder of 3.5e-3 rad steps, no other noise."""
    rec = record(hesitant, Logger(rate=250.0, jitter=0.0, drop=0.0, noise=0.0,
                                  quantum=3.5e-3, seed=4), dynamic=False)
    return _trajectory(rec)


def test_a_coarse_encoders_staircase_is_checked_as_measure_reads_it(hesitant):
    """Filtered as steps, a staircase's jumps read as accelerations: hesitant's largest
    joint acceleration read 1.15 rad/s^2 where the compiled motion's is 0.47. Read
    through its crossings, as measure reads it, the check's worst acceleration is the
    motion's."""
    true_peak = float(np.abs(np.asarray(hesitant["qdd"], float)).max())
    worst = _limits(check(_staircase(hesitant), dynamic=False))["joint-acceleration"]
    assert worst.ok and abs(abs(worst.value) - true_peak) <= 0.25 * true_peak


def test_plot_draws_a_staircase_as_measure_reads_it(hesitant):
    """The plot's filtered speed of the staircase follows the compiled motion's within a
    fifth of its peak (filtered as steps it was off by two thirds of it)."""
    from aou_dsl.media.plot import profile_data

    clean = profile_data(_trajectory(hesitant))
    d = profile_data(_staircase(hesitant))
    truth = np.interp(d.t, clean.t, clean.speed)
    assert np.abs(d.speed - truth).max() <= 0.2 * truth.max()


def test_the_speed_legend_covers_no_episode_label(hesitant):
    """The legend of a recording's speed panel (raw and filtered) and the episodes'
    labels along the panel's top, as drawn: no label's box meets the legend's, the
    last approach's label included."""
    from aou_dsl.media.plot import profile_data, profile_figure

    rec = record(hesitant, Logger(rate=250.0, jitter=0.0, noise=1e-3, seed=5),
                 dynamic=False)
    fig = profile_figure(profile_data(_trajectory(rec)))
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    ax = fig.axes[0]
    legend = ax.get_legend().get_window_extent(renderer)
    labels = [t for t in ax.texts if t.get_text()]
    assert len(labels) >= 10
    assert not [t.get_text() for t in labels if t.get_window_extent(renderer).overlaps(legend)]
    assert not ax.title.get_window_extent(renderer).overlaps(legend)
