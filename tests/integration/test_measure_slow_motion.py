"""Segmentation under noise: a slow motion's start or end, hidden under the noise for a
while, is no episode of its own.

At 250 Hz with 6e-4 or 1e-3 rad of encoder noise, a retreat or an approach at 0.05 to
0.1 m/s^2 moves under the rest threshold for its first and last few tenths of a second,
and the noise lets it out again for a few samples: a short rest run inside the motion.
Read as the instant between two episodes, it cut the retreat in two, and neither piece
counted (a retreat counts between two pauses), in every re-noised copy alike: a
confident wrong count. The recordings below are the ones that showed it (the
behaviours the calibration generates, written out here, logged by tests/recsim.py with
the seed the calibration gives them). The expected counts are what the files declare.
"""

from __future__ import annotations

import pytest

from tests.integration.test_measure_noise import logged
from tests.integration.test_recordings import build
from tests.recsim import noisy as logger

#: A slow retreat between two pauses, then two shivers: its end hides for 0.3 s.
SLOW_END = """behaviour hesitant-a : fearful
sequence {
  pause 1140ms
  retreat 3.87cm a=0.0528
  pause 1.55s
  shiver 0.1363rad f=1.76Hz for 1.45s
  pause 0.701s
  shiver 2.78deg f=2.02Hz for 1420ms
  pause 1490ms
}
"""

#: A retreat from a pause into a gaze, on the panda: its start hides.
SLOW_START = """robot panda
from (-0.65, -0.1, 0.75)
start 291mm
retreat 0.0464m a=108mm/s^2
gaze vertical 0.1027rad v=23.5deg/s x1
tilt 26.4deg x1
pause 0.491s x3
"""

#: Slow approaches and retreats among shivers: both ends of a retreat hide.
MIXED = """behaviour probe : confident
start 30.7cm
sequence {
  approach 25.3mm a=21cm/s^2 v=0.22; shiver 7.95deg f=1.85Hz for 1.27s
  approach -32.7mm
  pause 1.21s
  approach a=0.0469
  pause 1.7s
  retreat 1.42cm a=0.168
  shiver 7.53deg f=1.74 for 1210ms
  approach; pause 347ms; approach -0.0182m a=1280mm/s^2
  pause 0.924s
  approach -0.0512m; pause 0.762s
}
robot panda
"""

#: A retreat at 0.058 m/s^2 between pauses, after a gaze, a tilt and shivers.
CURIOUS = """behaviour hesitant-a : curious
start 0.355m
effort W=-0.75 T=1 S=0.5 F=0.25
sequence {
  shiver 5.93deg f=2.04Hz
  pause 1.68s
  gaze horizontal -3.634e-1rad v=30.4deg/s
  pause 0.773s
  approach -41.6mm a=0.106m/s^2
  tilt 33.1deg v=22.6deg/s x1; pause 1.85s x1
  shiver 6.19deg; pause 0.496s
  approach
  retreat 0.0585m a=0.19
  pause 1.73s
  retreat 6.17cm a=0.0578
  pause 0.826s
}
standoff 10cm
"""

#: Approaches and a retreat at 0.11 m/s^2 between pauses.
PEEK = """behaviour Peek_2 : curious
from (-0.55, 0.1, 0.83)
standoff 0.102m; effort W=-0.5 T=-0.75 S=-0.75 F=-1

approach a=0.11m/s^2; retreat 0.0405m a=1.23e2mm/s^2; pause 1.6s x3
gaze vertical 0.2708rad v=40deg/s
"""


#: The recordings that showed it: a behaviour, the noise [rad] and the logger's seed.
SHOWN = [(SLOW_END, 6e-4, 9759), (SLOW_START, 1e-3, 1600), (MIXED, 1e-3, 4300),
         (CURIOUS, 1e-3, 6400), (PEEK, 1e-3, 10000)]


def test_a_slow_retreat_is_one_retreat_under_noise():
    """Logged at 250 Hz, each reads the counts its file declares, each declared retreat
    read as one retreat covering most of it (no piece of one is a retreat of its own).
    A count the copies do not all read is said (R411), never given as trusted and
    wrong; here at most one of the five is left so (at 1e-3 rad a copy can still cut a
    retreat at 0.06 m/s^2)."""
    trusted = 0
    for text, noise, seed in SHOWN:
        doc, want, timeline = build(text, "slow")
        _, m = logged(doc, logger(noise, 250.0, seed))
        for k in ("retreat_count", "pause_count"):
            s = m.uncertainty[k]
            assert m.descriptors[k] == want[k], (seed, k, m.descriptors[k], want[k])
            assert s.low <= want[k] <= s.high, (seed, k, s)
        trusted += all(m.uncertainty[k].stable for k in ("retreat_count", "pause_count"))
        read = [(e.t_start, e.t_end) for e in m.episodes if e.kind == "retreat"]
        for kind, t0, t1 in timeline:
            if kind == "retreat":
                (a, b), = [(a, b) for a, b in read if a < t1 and b > t0]
                assert min(b, t1) - max(a, t0) >= 0.7 * (t1 - t0), (seed, (a, b), (t0, t1))
    assert trusted >= len(SHOWN) - 1


#: Two retreats back to back, and two approaches: each stops where the next starts.
BACK_TO_BACK = """robot panda
goal (0.55, 0, 0.25)
sequence {
  pause 1s
  retreat 3cm a=0.05
  retreat 3cm a=0.05
  pause 1s
  approach 2cm a=0.05
  approach 2cm a=0.05
  pause 1s
}
"""


@pytest.mark.parametrize("noise,rate,seed", [(3e-4, 250.0, 0), (6e-4, 1000.0, 1),
                                             (1e-3, 250.0, 2)])
def test_a_stop_between_two_motions_the_same_way_is_kept(noise, rate, seed):
    """The other side: two slow retreats that each stop where the next starts are two
    retreats (neither between two pauses, so none counts). Where the motion on both
    sides of a short rest is followed back to zero inside that rest, the rest is a stop,
    never merged away: no log reads one counted retreat that every copy agrees on."""
    doc, want, _ = build(BACK_TO_BACK, "b2b")
    assert want["retreat_count"] == 0
    _, m = logged(doc, logger(noise, rate, seed))
    s = m.uncertainty["retreat_count"]
    assert m.descriptors["retreat_count"] == 0 and s.stable, (m.descriptors, s)
    assert sum(e.kind == "retreat" for e in m.episodes) >= 2


#: A small, slow shiver (1.83 deg at 1.32 Hz on the ur5's wrist) between two slow
#: approaches, with no pause beside it: it fades in and out over a cycle each.
FADING_SHIVER = """from (-0.6, 0, 0.8)
tilt 0.1452rad v=10.9 x0
shiver 1.83deg f=1.32Hz for 1.59s
pause 3.15e-1s x2
approach a=0.0965; robot ur5; standoff 9.12cm
"""


def test_a_shivers_hidden_first_swing_is_no_pause():
    """At 250 Hz and 1e-3 rad the shiver's first half-cycle (about 0.15 of its
    amplitude) hides under the noise, and the first lobe that stands out swings the
    other way. Its start was then fitted as a power of time alone, which misses the
    hidden swing, so the fit was refused and the approach's stop and the hidden swing
    read as a pause of 0.3 s on each side of the shiver, in every copy. Fitted with the
    power times the oscillation, the shiver starts where it does: no pause beside it
    (a count the copies may still dispute, never a confident 4)."""
    doc, want, timeline = build(FADING_SHIVER, "fading")
    assert want["pause_count"] == 2
    _, m = logged(doc, logger(1e-3, 250.0, 7000))
    s = m.uncertainty["pause_count"]
    assert m.descriptors["pause_count"] == 2 and s.low <= 2 <= s.high, (m.descriptors, s)
    shiver = next((a, b) for kind, a, b in timeline if kind == "shiver")
    assert not [e for e in m.episodes if e.kind == "pause"
                and e.t_start < shiver[1] and e.t_end > shiver[0]]


def test_a_pause_beside_a_slow_approach_ends_where_the_approach_starts():
    """The hesitant's approaches at 0.05 m/s^2 logged at 250 Hz with 6e-4 rad: their
    last and first 0.3 s hide under the short filter's threshold and are found by the
    0.3 s one. Each pause's edge beside them is followed down the approach's ramp to
    where it stops or starts, as far as that ramp takes to cross the rest test's own
    threshold (the long filter's is ten times lower: read in its units, the edge was
    held 0.1 s short, and every pause beside a slow approach read 0.1 s long). Each
    pause read within 30 ms of the declared one at both edges."""
    from tests.conftest import BEHAVIOURS

    doc, _, timeline = build((BEHAVIOURS / "hesitant.aou").read_text(), "hesitant")
    _, m = logged(doc, logger(6e-4, 250.0, 4))
    read = [(e.t_start, e.t_end) for e in m.episodes if e.kind == "pause"]
    declared = [(a, b) for kind, a, b in timeline if kind == "pause"]
    assert len(read) == len(declared) == 5
    for (a, b), (t0, t1) in zip(read, declared, strict=True):
        assert abs(a - t0) < 0.03 and abs(b - t1) < 0.03, ((a, b), (t0, t1))
