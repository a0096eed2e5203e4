"""Recordings from coarse encoders: positions rounded to steps of 1e-3 to 3.5e-3 rad, no
other noise. Their error is a staircase (constant over a pause, stepping in motion), not
white noise."""

from __future__ import annotations

from aou_dsl.core.diagnostics import Severity
from tests.integration.test_measure_noise import logged
from tests.integration.test_recordings import build
from tests.recsim import Logger

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
