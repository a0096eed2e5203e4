"""Recordings from coarse encoders: positions rounded to steps of 1e-3 to 3.5e-3 rad, no
other noise. Their error is a staircase (constant over a pause, stepping in motion), not
white noise."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from aou_dsl.core.diagnostics import Severity
from aou_dsl.lang.descriptors import REGISTRY
from aou_dsl.measuring.signal import joint_noise
from tests.conftest import BEHAVIOURS
from tests.integration.test_measure_noise import logged
from tests.integration.test_recordings import build, generated
from tests.recsim import Logger, record

#: A generated behaviour whose 250 Hz coarse log has a tilt's short approach piece of a
#: few distinct steps.
SHY = """behaviour _shy : curious
robot ur5
start 32.8cm
sequence {
  pause 1.78s
  retreat 46.5mm a=0.0416; tilt 28.4deg v=2.61e1deg/s x1; pause 1050ms
  approach a=0.0592 x0
}
from (-3, 0, 4)
"""


#: A generated behaviour: a small shiver, a pause and two tilts, on the UR5.
SHIVER = "robot ur5\nshiver 1.66deg f=1.32Hz for 1590ms\npause 8.92e-1s\ntilt +23.6deg x2\n"


def _log(text: str, stem: str, quantum: float, seed: int):
    doc, want, _ = build(text, stem)
    log = Logger(rate=250.0, jitter=0.0, drop=0.0, noise=0.0, quantum=quantum, seed=seed)
    return want, logged(doc, log)[1]


def test_a_coarse_encoders_log_is_measured_not_a_traceback():
    """A short piece of a 3.5e-3 rad staircase can hold fewer distinct travels than the
    path fit has terms: the measurement read it as a singular system and stopped with
    a traceback instead of a result."""
    want, m = _log(SHY, "_shy", 3.5e-3, 35)
    assert not [d for d in m.diagnostics if d.severity == Severity.ERROR]
    assert set(m.uncertainty) >= set(want)


def test_a_count_a_staircase_can_flip_is_not_trusted():
    """At 1e-3 rad steps the small shiver's rounded swings read as a second pause. Every
    copy read it too while the copies' noise was white: a staircase stays put where white
    noise averages out. Copies rounded to the same steps on a shifted grid flip it, and
    R411 says the count is not to be trusted."""
    want, m = _log(SHIVER, "shiver", 1e-3, 15)
    assert m.descriptors["pause_count"] != want["pause_count"] == 1
    assert not m.uncertainty["pause_count"].stable
    (warn,) = [d for d in m.diagnostics if d.code == "R411"]
    assert "pause_count" in warn.fields["descriptors"]


#: A generated behaviour: one slow retreat between two pauses, on the UR5. Three of its
#: joints step only a few times at 3.5e-3 rad; the others step every few samples.
RETREAT = """# generated from the language contract
behaviour _shy
retreat 5.54cm a=0.285m/s^2
pause 1900ms x2; robot ur5
"""


def test_a_slow_retreat_on_a_staircase_is_one_retreat():
    """Filtered as a staircase, the slow retreat's speed dipped between jumps, and the
    joints that step only a few times showed no resolution of their own: their one
    jump read as motion out of no noise. It read as five pieces none of which counted,
    retreat_count 0 in the recording and every copy, with no warning. Read through
    its crossings, it is one retreat of the declared distance and acceleration."""
    want, m = _log(RETREAT, "_retreat", 3.5e-3, 124)
    assert want["retreat_count"] == 1
    assert m.descriptors["retreat_count"] == 1
    assert m.uncertainty["retreat_count"].stable
    got, declared = m.descriptors["retreat_distance"], want["retreat_distance"]
    assert abs(got - declared) <= REGISTRY["retreat_distance"].tolerance(declared)
    got, declared = m.descriptors["retreat_acceleration"], want["retreat_acceleration"]
    assert abs(got - declared) <= REGISTRY["retreat_acceleration"].tolerance(declared)


def test_a_joint_that_steps_a_few_times_shares_the_arms_resolution():
    """The wrist joints move the retreat by one or two steps each: too few to show a
    resolution, but every step a whole multiple of the one the other joints show."""
    doc, _, _ = build(RETREAT, "_retreat")
    log = Logger(rate=250.0, jitter=0.0, drop=0.0, noise=0.0, quantum=3.5e-3, seed=124)
    rec = record(doc, log, dynamic=False)
    q = np.asarray(rec["q"], float)
    jn = joint_noise(np.asarray(rec["t"], float), q)
    steps = [int((np.diff(q[:, j]) != 0).sum()) for j in range(q.shape[1])]
    few = [j for j, n in enumerate(steps) if 0 < n < 10]
    assert few, steps  # the case this test is about
    assert np.allclose(jn.quantum[jn.moving], 3.5e-3)
    # A joint that moves by steps of no common size keeps no resolution.
    q[:, few[0]] += np.linspace(0.0, 1e-3, len(q)) ** 2
    assert joint_noise(np.asarray(rec["t"], float), q).quantum[few[0]] == 0.0


def test_a_value_over_episodes_the_copies_count_differently_is_not_trusted():
    """A shiver's rounded swing reads as a short pause in some copies: the pause count
    is not to be trusted (R411), and neither is the pauses' median duration, which an
    extra pause moves by half the gap between two pauses."""
    want, m = _log(GEN0, "_gen0", 3.5e-3, 105)
    assert not m.uncertainty["pause_count"].stable
    assert m.descriptors["pause_duration"] is not None
    assert not m.uncertainty["pause_duration"].stable
    (warn,) = [d for d in m.diagnostics if d.code == "R411"]
    assert {"pause_count", "pause_duration"} <= set(warn.fields["descriptors"])
    assert "pause episodes the copies count differently" in warn.message


#: A generated behaviour: shivers, tilts, a gaze and four pauses on the UR5.
GEN0 = """behaviour reach_it-3 : inactive
robot ur5; goal (0.451m, 0.113, 0.15)
start 0.317m
sequence {
  pause 1.76s
  shiver 2.95deg f=1.26Hz for 1.67s
  pause 1.49s
  tilt -17.2deg v=1.17e1deg/s
  shiver 2.35deg f=1.14Hz for 1840ms
  gaze vertical -6.85deg
  pause 789ms
  tilt -25.6deg v=18.1deg/s
  pause 0.697s
  retreat 35.8mm x0
}
effort W=1 T=0.5 S=-1 F=-0.5
"""


#: The encoders' steps [rad]: a 12-bit encoder's (2 pi / 4096 is 1.5e-3; 3.5e-3 is one
#: behind a gear), and finer ones.
STEPS = (3.5e-3, 1e-3, 3e-4)


def staircase_table(items, step: float) -> dict[str, list[bool]]:
    """Over the compiled behaviours ``items`` logged at 250 Hz with positions rounded to
    ``step`` and no other noise: for each count the copies agree on, whether it is
    exact ("counts"); for each value they agree on, whether its interval holds the
    declared value ("held"), and whether it is right at least by the descriptor's
    tolerance where it is not ("not wrong": a value outside both is confidently
    wrong)."""
    out: dict[str, list[bool]] = {"counts": [], "held": [], "not wrong": []}
    for i, (doc, want, _) in enumerate(items):
        m = logged(doc, Logger(rate=250.0, jitter=0.0, drop=0.0, noise=0.0, quantum=step,
                               seed=100 + i))[1]
        for k, d in REGISTRY.items():
            s, w, v = m.uncertainty[k], want[k], m.descriptors[k]
            if not s.stable:
                continue
            if d.is_count:
                out["counts"].append(int(v or 0) == int(w or 0))
            elif w is not None and v is not None:
                held = bool(s.low <= w <= s.high)
                out["held"].append(held)
                out["not wrong"].append(held or abs(v - w) <= d.tolerance(w))
    return out


def _items(n: int):
    shipped = [build((BEHAVIOURS / f"{s}.aou").read_text(), s)
               for s in ("confident", "curious", "hesitant", "fearful", "inactive")]
    return shipped + [b for _, b in generated(n, 7)]


@pytest.mark.slow
@pytest.mark.parametrize("step", STEPS[:2])
def test_a_staircase_gives_no_confident_wrong_count_or_value(step):
    """The shipped behaviours and eight generated ones on coarse encoders: every count
    the copies agree on is exact, and every value they agree on is inside its interval
    or within its tolerance. Before the staircase was read through its crossings, one
    slow retreat read as five pieces (its count 0, in every copy), and values held
    their interval in 87 % of cases."""
    table = staircase_table(_items(8), step)
    assert len(table["counts"]) >= 20 and all(table["counts"])
    assert len(table["held"]) >= 20 and all(table["not wrong"])
    assert np.mean(table["held"]) >= 0.9


if __name__ == "__main__":  # docs/measure.md's table: python -m ... [N generated]
    items = _items(int(sys.argv[1]) if len(sys.argv) > 1 else 40)
    print(f"{len(items)} behaviours at 250 Hz, positions rounded, no other noise")
    for step in STEPS:
        tab = staircase_table(items, step)
        print(f"  steps of {step:g} rad: trusted counts exact {sum(tab['counts'])} of "
              f"{len(tab['counts'])}; trusted values held {np.mean(tab['held']):.1%} "
              f"({len(tab['held'])}), confidently wrong "
              f"{len(tab['not wrong']) - sum(tab['not wrong'])}")
