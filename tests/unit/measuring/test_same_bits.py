"""The measurement's faster forms against the NumPy forms they replace, to the bit: the
rows' sums (and the norms made of them), the median of a hold, the ramp's line, the
peak finder asked for some of its peaks, the dips it looks for, each row's leading
joint and the filter at a few samples. Each is checked on values that tell orders of
summation apart (magnitudes over many decades), on signed zeros, ties and both layouts
of a recording's joints."""

from __future__ import annotations

import warnings
from types import SimpleNamespace

import numpy as np

from aou_dsl.measuring.extrema import maxima
from aou_dsl.measuring.holds import _crossings, _dips
from aou_dsl.measuring.signal import (
    filter_at,
    filters_at,
    line_fit,
    median0,
    row_sum,
    sg_coefficients,
)


def _wide(rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    """Values over sixteen decades, both signs: any other order of summation rounds
    otherwise somewhere."""
    return rng.normal(size=shape) * 10.0 ** rng.integers(-8, 8, size=shape)


def test_row_sum_is_numpys_row_sum_and_the_norms_square_sum():
    rng = np.random.default_rng(1)
    for cols in range(1, 10):
        a = _wide(rng, (5000, cols))
        a[rng.random(a.shape) < 0.05] = -0.0
        got, want = row_sum(a), a.sum(axis=1)
        assert np.array_equal(got, want) and np.array_equal(np.signbit(got), np.signbit(want))
        assert np.array_equal(np.sqrt(row_sum(a * a)), np.linalg.norm(a, axis=1))
        f = np.asfortranarray(a)  # a recording's joints lie by columns
        assert np.array_equal(row_sum(f), f.sum(axis=1))


def test_median0_is_numpys_median_along_the_first_axis():
    rng = np.random.default_rng(2)
    for n in [*range(1, 25), 200, 201, 667, 668]:
        for kind in range(3):
            for shape in ((n,), (n, 7)):
                a = rng.normal(size=shape)
                if kind == 1:  # zeros of both signs
                    a = np.where(rng.random(shape) < 0.5, -0.0, 0.0)
                elif kind == 2:  # ties
                    a = np.round(a)
                for x in (a, np.asfortranarray(a)):
                    want, got = np.median(x, axis=0), median0(x)
                    assert np.shape(got) == np.shape(want)
                    assert np.array_equal(got, want)
                    assert np.array_equal(np.signbit(got), np.signbit(want))


def test_line_is_polyfit_of_degree_one():
    rng = np.random.default_rng(3)
    for k in [2, 3, 5, 30, 250, 600]:
        for _ in range(100):
            x = np.cumsum(rng.uniform(0.2, 2.0, k)) * 10.0 ** float(rng.integers(-4, 1))
            x -= x[0]
            y = rng.normal(size=k) * 10.0 ** float(rng.integers(-3, 3))
            assert line_fit(x, y) == tuple(float(c) for c in np.polyfit(x, y, 1))


def test_line_warns_where_polyfit_warns():
    x, y = np.full(5, 2.0), np.arange(5.0)  # x no line can be told along
    for fit in (line_fit, lambda a, b: np.polyfit(a, b, 1)):
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            fit(x, y)
        assert [w.category for w in seen] == [np.exceptions.RankWarning]


def test_maxima_asked_for_some_peaks_give_them_as_all_peaks_do():
    rng = np.random.default_rng(4)
    for _ in range(200):
        x = np.round(rng.normal(size=int(rng.integers(3, 400))), int(rng.integers(0, 3)))
        among = rng.random(len(x)) < 0.3
        idx, prom = maxima(x)
        sub, sub_prom = maxima(x, among)
        asked = among[idx]
        assert np.array_equal(sub, idx[asked])
        assert np.array_equal(sub_prom, prom[asked])


def _signals(level: np.ndarray, v: np.ndarray) -> SimpleNamespace:
    """What ``_dips`` and ``_crossings`` read of a recording's rest signals: joint
    velocities ``v`` (N, n) over thresholds of 1, whose largest ratio is ``level``."""
    n = len(level)
    thr = np.ones_like(v)
    return SimpleNamespace(level=level, v=v, thr=thr, ratio=np.abs(v) / thr, v_long=v,
                           thr_long=thr, ratio_long=np.abs(v) / thr, window=0,
                           t=np.arange(n) * 0.001, h=0.001, carried=None,
                           q=np.cumsum(v, axis=0) * 0.001)


def _plain_dips(level: np.ndarray, taken: np.ndarray) -> set[int]:
    """The minima of the level (at the samples) outside the rests and under 30 % of the
    peaks beside them, every minimum's prominence looked up."""
    idx, prom = maxima(-level)
    kept = ~taken[idx] & ~(level[idx] > 0.3 * (level[idx] + prom))
    return set(idx[kept].tolist())


def test_dips_are_those_of_every_minimum_looked_at():
    """Noisy speed with a few real dips, rests marked at random: the dips found are
    those the prominences of every minimum give (none dropped by the bound, none added)."""
    rng = np.random.default_rng(5)
    for trial in range(40):
        n = 3000
        base = 8.0 + 6.0 * np.sin(np.arange(n) * rng.uniform(0.002, 0.02))
        level = np.abs(base + rng.normal(0, rng.uniform(0.1, 3.0), n))
        for at in rng.integers(50, n - 50, 4):  # dips through zero speed
            level[at - 20:at + 21] *= np.abs(np.linspace(-1, 1, 41)) ** rng.uniform(0.5, 2)
        if trial % 4 == 0:
            level[rng.random(n) < 0.2] *= 0.1  # much under the rest level
        v = level[:, None] * np.array([[1.0, 0.5]])  # never reverses: dips at samples
        taken = np.zeros(n, bool)
        for a in rng.integers(0, n - 100, 3):
            taken[a:a + int(rng.integers(5, 100))] = True
        got = {k for _, _, k in _dips(_signals(level, v), taken)}
        assert got == _plain_dips(level, taken)


def test_leading_joint_at_a_crossing_is_numpys_first_largest():
    rng = np.random.default_rng(6)
    v = np.round(rng.normal(size=(4000, 7)), 1)  # ties between joints
    level = np.abs(v).max(axis=1)
    r = _signals(level, v)
    idx, lead, between = _crossings(r)
    pair = r.ratio[:-1] + r.ratio[1:]
    j = np.argmax(pair, axis=1)
    rows = np.arange(len(j))
    want = np.flatnonzero(v[rows, j] * v[rows + 1, j] < 0)
    assert np.array_equal(idx, want)
    assert np.array_equal(lead, j[want])


def test_filter_at_equals_the_gathered_windows_in_either_layout():
    rng = np.random.default_rng(7)
    x = _wide(rng, (6001, 7))
    for q in (x, np.asfortranarray(x), np.asfortranarray(x)[:-1], x[::1, :3]):
        for window in (3, 5, 61, 301, 1001):
            half = window // 2
            spread = np.sort(rng.integers(half, len(q) - half, 5))
            k = int(rng.integers(2 * half, len(q) - 2 * half))  # the self-check's five:
            close = np.unique(np.linspace(k - half, k + half, 5).round().astype(int))
            for at in (spread, close, close[::-1]):  # windows overlapping, in any order
                gathered = np.moveaxis(q[at[:, None] + np.arange(-half, half + 1)], 1, -1)
                want = [gathered @ sg_coefficients(window, 3, d, 0.001) for d in (1, 2)]
                for d in (1, 2):
                    assert np.array_equal(filter_at(q, window, d, 0.001, at), want[d - 1])
                both = filters_at(q, window, (1, 2), 0.001, at)
                assert all(np.array_equal(g, w) for g, w in zip(both, want, strict=True))
