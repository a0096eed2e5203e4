"""R403 on a noisy recording: episodes of one kind that differ by more than the
tolerance are noted only where the noise cannot explain the difference.

Hesitant declares five equal pauses; logged with 1e-3 rad of encoder noise they read
up to 0.05 s apart, more than the 0.033 s tolerance, and R403 used to say they differ.
A sequence that declares pauses of 1.4 s and 1.9 s, and retreats of 4 and 8 cm, must
still be noted through the same noise. The declared values come from the files, not
from what measure printed.
"""

from __future__ import annotations

import pytest

from aou_dsl.lang.descriptors import REGISTRY, spread
from tests.conftest import BEHAVIOURS
from tests.integration.test_measure_noise import logged
from tests.integration.test_recordings import build
from tests.recsim import noisy

UNEVEN = """behaviour uneven : hesitant
robot panda
start 0.30m
standoff 0.10m
sequence {
  approach 0.06m a=0.05
  pause 1.4s
  approach 0.04m a=0.05
  pause 1.9s
  retreat 0.04m a=0.12
  pause 1.4s
  retreat 0.08m a=0.12
  pause 1.9s
  approach a=0.05
}
"""


def _noted(m) -> dict[str, list[float]]:
    return {d.fields["descriptor"]: d.fields["values"] for d in m.diagnostics
            if d.code == "R403"}


@pytest.mark.parametrize("seed", [100, 101, 102])
def test_equal_pauses_read_apart_by_noise_are_not_noted(seed):
    doc, want, _ = build((BEHAVIOURS / "hesitant.aou").read_text(), "hesitant")
    _, m = logged(doc, noisy(1e-3, 250.0, seed))
    pauses = spread(m.episodes)["pause_duration"]
    assert len(pauses) == 5
    assert "pause_duration" not in _noted(m)
    # the interval still holds the declared pause
    s = m.uncertainty["pause_duration"]
    assert s.low <= want["pause_duration"] <= s.high


def test_the_reading_apart_is_what_the_note_was_about():
    """The case the test above stands on: the noise does read the equal pauses further
    apart than the tolerance, so a note on the spread alone would be given."""
    doc, want, _ = build((BEHAVIOURS / "hesitant.aou").read_text(), "hesitant")
    _, m = logged(doc, noisy(1e-3, 250.0, 100))
    pauses = spread(m.episodes)["pause_duration"]
    tol = REGISTRY["pause_duration"].tolerance(want["pause_duration"])
    assert max(pauses) - min(pauses) > tol


@pytest.mark.parametrize("noise,rate", [(3e-4, 1000.0), (1e-3, 250.0)])
def test_declared_unequal_episodes_are_still_noted_through_noise(noise, rate):
    built = build(UNEVEN, "uneven")
    assert built is not None
    doc, _, _ = built
    _, m = logged(doc, noisy(noise, rate, 1))
    noted = _noted(m)
    assert sorted(noted) >= ["pause_duration", "retreat_distance"]
    assert max(noted["pause_duration"]) - min(noted["pause_duration"]) > 0.4
    assert max(noted["retreat_distance"]) - min(noted["retreat_distance"]) > 0.03
