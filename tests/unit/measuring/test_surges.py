"""The phases of an approach that surges: its speed dips well below the top in the middle
and rises again; the surge's acceleration is read, not only the first speed-up and the
last slow-down (aou_dsl/measuring/surges.py)."""

from __future__ import annotations

import numpy as np

from aou_dsl.measuring.peaks import episode_peak, phase_peak
from aou_dsl.measuring.surges import phases, surges

H = 0.002


def _travel(accels: list[tuple[float, float]]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times, travel and speed of a hand that holds each acceleration [m/s^2] for its
    duration [s] in turn, from rest: integrated exactly on a 2 ms clock."""
    a = np.concatenate([np.full(int(round(d / H)), acc) for acc, d in accels])
    v = np.concatenate([[0.0], np.cumsum(a) * H])
    x = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1])) * H])
    return np.arange(len(v)) * H, x, v


# Speeds up gently to 0.15 m/s, slows to 0.03 m/s, surges at 1.2 m/s^2 back to 0.15 m/s,
# then stops gently: the surge's 1.2 m/s^2 is the peak.
SURGING = [(0.3, 0.5), (-0.3, 0.4), (1.2, 0.1), (-0.3, 0.5)]


def _peak(t: np.ndarray, x: np.ndarray, speed: np.ndarray) -> float:
    found = [f for ph in phases(speed, H, True, True)
             if (f := phase_peak(t, x, ph.a, ph.b, 0.0, 0.0, None, 2.0 if ph.at_dip else 1.0,
                                 (ph.lo, ph.hi))) is not None]
    return episode_peak(found).value


def test_a_surge_in_the_middle_is_read():
    t, x, v = _travel(SURGING)
    assert len(surges(v, H)) == 2
    assert abs(_peak(t, x, v) - 1.2) < 0.02 * 1.2


def test_one_speed_up_and_one_slow_down_is_one_surge_read_as_before():
    """A compiled approach's profile (a trapezoid, and one with a cruise that wobbles by
    10 % of its speed, above the dip's 80 %): one surge, its two phases from rest to 95 %
    of the top and back, as the phases were always read."""
    for profile in ([(0.5, 0.3), (0.0, 0.4), (-0.5, 0.3)],
                    [(0.5, 0.3), (-0.1, 0.15), (0.1, 0.15), (-0.5, 0.3)]):
        t, x, v = _travel(profile)
        assert surges(v, H) == [(0, len(v) - 1)]
        fast = np.flatnonzero(v >= 0.95 * v.max())
        got = [(p.a, p.b) for p in phases(v, H, True, True)]
        assert got == [(0, int(fast[0])), (int(fast[-1]), len(v) - 1)]
        assert abs(_peak(t, x, v) - 0.5) < 0.01


def test_a_dip_of_noise_or_a_brief_wobble_is_no_surge():
    """A dip the noise could make, or one shorter than a surge lasts, splits nothing."""
    t, x, v = _travel(SURGING)
    assert len(surges(v, H, noise=0.03)) == 1  # 6 stds of 0.03 m/s exceed the 0.12 rise
    _, _, v = _travel([(0.5, 0.3), (0.0, 0.4), (-0.5, 0.3)])
    wobble = v.copy()
    k = len(v) // 2
    wobble[k:k + 10] *= 0.5  # 20 ms at half the speed
    assert len(surges(wobble, H)) == 1
