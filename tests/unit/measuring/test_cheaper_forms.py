"""The measurement's cheaper forms of a few computations against the plain ones they
replace, written here from their definitions: the roll's relative rotations (a matrix
product of the stack), the quadratic's curvature weights (their formula at each step),
the surges' walk over the speed (one sample at a time, as NumPy scalars), the profile's
run lengths, the rows' maxima and the peak finder's prominences."""

from __future__ import annotations

import math

import numpy as np
import pytest

from aou_dsl.measuring.peaks import _uniform_weights
from aou_dsl.measuring.roll import roll_angle
from aou_dsl.measuring.signal import centred_mean
from aou_dsl.measuring.surges import DIP, DISTINCT, SURGE, surges


def _rotations(rng: np.random.Generator, n: int) -> np.ndarray:
    """``n`` rotations turning a little from one to the next about random axes, with
    stretches held exactly (a hand at rest: entries of exactly zero in the relative
    rotations)."""
    out = np.empty((n, 3, 3))
    r = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    for k in range(n):
        if k % 7 < 3:  # held
            out[k] = r
            continue
        w = rng.normal(size=3) * 0.05
        angle = float(np.linalg.norm(w))
        x, y, z = w / angle
        skew = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
        turn = np.eye(3) + math.sin(angle) * skew + (1 - math.cos(angle)) * skew @ skew
        r = turn @ r
        out[k] = r
    return out


def test_roll_angle_equals_the_stacked_products_bit_for_bit():
    rng = np.random.default_rng(5)
    for rot in (_rotations(rng, 400), np.repeat(np.eye(3)[None], 5, axis=0),
                np.linalg.qr(rng.normal(size=(300, 3, 3)))[0]):
        rel = np.einsum("nji,njk->nik", rot[:-1], rot[1:])
        step = np.arctan2(rel[:, 1, 0] - rel[:, 0, 1], rel[:, 0, 0] + rel[:, 1, 1])
        want = np.concatenate([[0.0], np.cumsum(step)])
        got = roll_angle(rot)
        assert np.array_equal(got, want)
        assert np.array_equal(np.signbit(got), np.signbit(want))


def test_roll_angle_counts_turns_past_half_a_turn():
    """From the definition: a hand turned steadily about its forward axis by 400 deg."""
    a = np.linspace(0.0, math.radians(400.0), 200)
    c, s = np.cos(a), np.sin(a)
    rot = np.zeros((len(a), 3, 3))
    rot[:, 0, 0], rot[:, 0, 1], rot[:, 1, 0], rot[:, 1, 1] = c, -s, s, c
    rot[:, 2, 2] = 1.0
    assert np.allclose(roll_angle(rot), a, atol=1e-12)


@pytest.mark.parametrize("w", [3, 4, 5, 17, 60, 301])
def test_uniform_weights_equal_their_formula_at_any_step(w):
    rng = np.random.default_rng(w)
    for h in [0.001, 0.004, 1.0, *rng.uniform(1e-4, 1e-2, 20)]:
        k = np.arange(w) - 0.5 * (w - 1)
        d = k * k - float(np.mean(k * k))
        want = 2.0 * d / (float(d @ d) * h * h)
        assert np.array_equal(_uniform_weights(w, float(h)), want)


def _walked_dips(speed: np.ndarray, noise: float) -> list[int]:
    """The surges' walk over the speed as first written: one NumPy scalar at a time."""
    least, rise = SURGE * float(speed.max()), DISTINCT * noise
    dips: list[int] = []
    top, low, low_i, falling = float(speed[0]), 0.0, 0, False
    for i in range(1, len(speed)):
        v = float(speed[i])
        if not falling:
            top = max(top, v)
            if top >= least and v < DIP * top and top - v > rise:
                falling, low, low_i = True, v, i
        elif v < low:
            low, low_i = v, i
        elif v >= least and low < DIP * v and v - low > rise:
            dips.append(low_i)
            falling, top = False, v
    return dips


def test_surges_dips_are_the_plain_walks():
    """Speeds with several surges, noise, plateaus and ties (rounded): the dips the
    surges split at are those the walk one sample at a time finds."""
    from aou_dsl.measuring.surges import _dips

    h = 0.001
    rng = np.random.default_rng(2)
    t = np.arange(0.0, 2.0, h)
    for k in range(300):
        noise = float(rng.choice([0.0, 0.002, 0.01, 0.05]))
        speed = np.abs(np.sin(math.pi * t * rng.uniform(0.3, 6.0))) * 0.2
        speed = np.abs(speed + rng.normal(size=len(t)) * noise)
        if k % 3 == 0:
            speed = np.round(speed, int(rng.integers(1, 4)))
        speed = speed[: int(rng.integers(2, len(t)))]
        if k % 2:
            speed = centred_mean(speed, int(rng.integers(0, 60)))
        least = SURGE * float(speed.max())
        assert _dips(speed, least, DISTINCT * noise) == _walked_dips(speed, noise)
    assert len(surges(np.abs(np.sin(math.pi * t * 3.0)), h)) == 6


def _plain_run(t: np.ndarray, a: int, b: int, level: float, noise: float, shortest: float,
               resolution: float) -> int:
    """The profile's run as first written: the weights' norm at every length tried."""
    length = b - a + 1
    step = float(t[b] - t[a]) / max(length - 1, 1)
    w = min(max(3, int(math.ceil(shortest / step - 1e-9)) + 1), length)
    while w < length:
        k = np.arange(w) - 0.5 * (w - 1)
        d = k * k - float(np.mean(k * k))
        if noise * float(np.linalg.norm(2.0 * d / (float(d @ d) * step * step))) <= (
                resolution * level):
            break
        w = min(w + max(1, w // 8), length)
    return w


def test_run_length_equals_the_weights_norm_at_every_length():
    """Random phases, levels and noises, and the edge cases: each run found is the one
    the weights' own norm picks, including where that norm sits on the bound."""
    from aou_dsl.measuring.peaks import _run, _uniform_gain

    rng = np.random.default_rng(4)
    for _ in range(150):
        h = float(rng.uniform(5e-4, 1e-2))
        length = int(rng.integers(3, 3000))
        t = np.cumsum(rng.uniform(0.9, 1.1, length)) * h
        level = float(10.0 ** rng.uniform(-3, 1)) * rng.choice([1.0, -1.0, 0.0])
        noise = float(10.0 ** rng.uniform(-8, -3)) * rng.choice([1.0, 0.0])
        shortest, res = float(rng.choice([0.0, 0.06])), float(rng.choice([0.015, 0.005]))
        assert _run(t, 0, length - 1, level, noise, shortest, res) == _plain_run(
            t, 0, length - 1, level, noise, shortest, res)
    # On the bound: the level that makes a run's noise exactly the resolution.
    t = np.arange(500) * 0.001
    step = float(t[-1] - t[0]) / 499
    for w in (3, 10, 57, 200):
        level = 1e-4 * _uniform_gain(w, step) / 0.015
        for lv in (level, np.nextafter(level, 0.0), np.nextafter(level, 1.0)):
            assert _run(t, 0, 499, lv, 1e-4, 0.0, 0.015) == _plain_run(
                t, 0, 499, lv, 1e-4, 0.0, 0.015)


def test_row_max_is_numpys_row_maximum():
    from aou_dsl.measuring.signal import row_max

    rng = np.random.default_rng(6)
    for shape in ((1, 1), (5, 1), (300, 7), (40, 3)):
        a = rng.normal(size=shape)
        a[rng.random(shape) < 0.05] = np.nan
        a[rng.random(shape) < 0.05] = np.inf
        assert np.array_equal(row_max(a), a.max(axis=1), equal_nan=True)


def test_maxima_keep_numpys_prominences_on_ties_and_plateaus():
    """Rounded noise (plateaus, equal neighbours), a constant and a ramp: the peaks and
    prominences :func:`.extrema.maxima` finds are those of a plain walk from each peak to
    the first higher sample on either side."""
    from aou_dsl.measuring.extrema import maxima

    rng = np.random.default_rng(9)
    cases = [np.round(rng.normal(size=int(rng.integers(3, 120))), int(rng.integers(0, 3)))
             for _ in range(200)] + [np.full(9, 0.5), np.arange(9.0)]
    for x in cases:
        idx, prom = maxima(x)
        want_idx, want_prom = [], []
        i, n = 1, len(x)
        while i < n - 1:
            j = i
            while j + 1 < n and x[j + 1] == x[i]:
                j += 1
            if x[i - 1] < x[i] and j < n - 1 and x[j + 1] < x[i]:
                left = i - 1
                base_l = x[left]
                while left >= 0 and x[left] <= x[i]:
                    base_l = min(base_l, x[left])
                    left -= 1
                right = j + 1
                base_r = x[right]
                while right < n and x[right] <= x[i]:
                    base_r = min(base_r, x[right])
                    right += 1
                want_idx.append((i + j) // 2)
                want_prom.append(x[i] - max(base_l, base_r))
            i = j + 1
        assert idx.tolist() == want_idx
        assert np.allclose(prom, want_prom, rtol=0, atol=0)


def test_thresholds_equal_their_formula_with_and_without_a_gap():
    """One row for every sample where all were logged, the full table across a gap:
    either way the numbers of the plain expression, sample by sample."""
    from aou_dsl.measuring.onset import REST_SPEED
    from aou_dsl.measuring.rest import _thresholds
    from aou_dsl.measuring.signal import NOISE_SIGMAS

    noise = np.array([3e-4, 0.0, 1e-6, 2e-3])
    for density in (np.ones(50), np.r_[np.ones(20), np.full(10, 0.25), np.ones(20)]):
        scale = 1.0 / np.sqrt(np.clip(density, 1e-3, 1.0))[:, None]
        want = np.maximum(NOISE_SIGMAS * noise[None, :] * 5.1 * scale, REST_SPEED)
        got = _thresholds(noise, 5.1, scale)
        assert got.shape == want.shape and np.array_equal(got, want)
