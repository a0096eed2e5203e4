"""The measurement's own Savitzky-Golay filter and peak finder (aou_dsl/measuring/savgol.py,
extrema.py) against their definitions and against SciPy's signal package, which the
measurement used before and whose numbers its thresholds were calibrated on.

The comparison with SciPy is exact equality, bit for bit: the filter does its arithmetic
in the same order, the peak finder only compares and subtracts. SciPy stays a test
dependency; the package itself no longer imports ``scipy.signal``
(tests/integration/test_light_measure.py).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.signal import find_peaks, savgol_coeffs, savgol_filter

from aou_dsl.measuring.extrema import maxima
from aou_dsl.measuring.savgol import savgol, savgol_weights
from aou_dsl.measuring.signal import sg_coefficients, smooth

#: Sample spacings [s] the measurement meets (1 kHz .. 100 Hz) and the unit step.
DELTAS = (1.0, 0.001, 0.002, 0.004, 0.0123)


def _signals(rng: np.random.Generator, n: int, cols: int) -> list[np.ndarray]:
    """Kinds of signal a recording holds: noise, a random walk, a rounded walk (ties and
    repeated steps), a plateau then noise, a constant, a polynomial."""
    shape = (n, cols) if cols else (n,)
    walk = np.cumsum(rng.normal(size=shape), axis=0)
    plateau = rng.normal(size=shape) * 1e-3
    plateau[: n // 2] = 0.25
    t = np.arange(n, dtype=float).reshape((n,) + (1,) * (len(shape) - 1))
    return [rng.normal(size=shape) * 10.0 ** rng.uniform(-6, 1), walk, np.round(walk, 2),
            plateau, np.full(shape, 0.7), 0.3 - 0.02 * t + 1e-4 * t ** 3 + 0 * walk]


def test_weights_equal_scipy_bit_for_bit():
    for window in range(1, 52):
        for order in range(min(window, 6)):
            for deriv in range(4):
                for delta in DELTAS:
                    want = savgol_coeffs(window, order, deriv=deriv, delta=delta, use="dot")
                    assert np.array_equal(savgol_weights(window, order, deriv, delta), want)
                    conv = savgol_coeffs(window, order, deriv=deriv, delta=delta)
                    got = savgol_weights(window, order, deriv, delta, reverse=True)
                    assert np.array_equal(got, conv[::-1])


def test_weights_are_the_least_squares_derivative():
    """From the definition: applied to samples of a polynomial of degree <= order, the
    weights give its derivative at the centre (to rounding)."""
    rng = np.random.default_rng(3)
    for window in (3, 5, 9, 21, 51):
        m = window // 2
        for order in range(1, min(window, 6)):
            p = rng.normal(size=order + 1)
            for deriv in range(3):
                h = 0.004
                t = np.arange(-m, m + 1) * h
                want = np.polyval(np.polyder(p, deriv), 0.0) if deriv <= order else 0.0
                got = savgol_weights(window, order, deriv, h) @ np.polyval(p, t)
                scale = max(1.0, abs(want)) * h ** -deriv
                assert abs(got - want) <= 1e-9 * scale


@pytest.mark.parametrize("n", range(1, 10))
def test_short_signals_equal_scipy(n):
    """Lengths 1..9, every window that fits, orders 0..5, derivatives 0..2."""
    rng = np.random.default_rng(n)
    for x in _signals(rng, n, 2) + _signals(rng, n, 0):
        for window in range(1, n + 1, 2):
            for order in range(min(window, 6)):
                for deriv in range(3):
                    want = savgol_filter(x, window, order, deriv=deriv, delta=0.004, axis=0)
                    got = savgol(x, window, order, deriv, 0.004)
                    assert np.array_equal(got, want), (n, window, order, deriv)


def test_random_signals_equal_scipy():
    """Windows 3..51, orders 1..5, derivatives 0..2, one to three columns or a 1-D
    signal, lengths up to 500."""
    rng = np.random.default_rng(11)
    checked = 0
    for _ in range(150):
        n = int(rng.integers(3, 500))
        cols = int(rng.integers(0, 4))
        for x in _signals(rng, n, cols):
            window = min(int(rng.integers(1, 26)) * 2 + 1, n if n % 2 else n - 1)
            order = min(int(rng.integers(1, 6)), window - 1)
            deriv = int(rng.integers(0, 3))
            delta = float(rng.choice(DELTAS))
            want = savgol_filter(x, window, order, deriv=deriv, delta=delta, axis=0)
            got = savgol(x, window, order, deriv, delta)
            assert np.array_equal(got, want), (n, cols, window, order, deriv, delta)
            checked += 1
    assert checked == 900


def test_long_signals_filtered_block_by_block_equal_scipy():
    """Over a minute at 1 kHz (seven joints, three coordinates, one series) runs through the
    filter a block of rows at a time, blocks whose edges fall anywhere: the same bits
    as SciPy's one pass, for the measurement's windows."""
    from aou_dsl.measuring import savgol as filt

    rng = np.random.default_rng(12)
    for cols in (7, 3, 0):
        n = 70_001 + cols
        assert n * max(cols, 1) > 2 * filt._BLOCK  # several blocks
        x = _signals(rng, n, cols)[1] * 1e-3
        for window, order, deriv in ((61, 2, 1), (61, 3, 0), (15, 2, 1), (301, 1, 1)):
            want = savgol_filter(x, window, order, deriv=deriv, delta=0.001, axis=0)
            got = savgol(x, window, order, deriv, 0.001)
            assert np.array_equal(got, want), (cols, window, order, deriv)


def test_smooth_keeps_its_contract():
    """The measurement's entry points: a window longer than the signal is cut to fit;
    under 3 samples the gradient (or the signal, or zeros) is returned; the cached
    centre weights are those of SciPy's ``use="dot"`` and cannot be changed in place."""
    rng = np.random.default_rng(5)
    x = np.cumsum(rng.normal(size=(40, 3)), axis=0)
    assert np.array_equal(smooth(x, 61, 1, 0.004), savgol_filter(x, 39, 3, 1, 0.004, axis=0))
    assert np.array_equal(smooth(x[:2], 5, 1, 0.004), np.gradient(x[:2], 0.004, axis=0))
    c = sg_coefficients(9, 3, 2, 0.004)
    assert np.array_equal(c, savgol_coeffs(9, 3, 2, 0.004, use="dot"))
    with pytest.raises(ValueError):
        c[0] = 1.0


def _maxima_by_definition(x: np.ndarray) -> tuple[list[int], list[float]]:
    """Local maxima and prominences straight from the definitions, one sample at a time."""
    peaks, proms = [], []
    i = 1
    while i < len(x) - 1:
        j = i
        while j + 1 < len(x) and x[j + 1] == x[i]:
            j += 1
        if x[i - 1] < x[i] and j + 1 < len(x) and x[j + 1] < x[i]:
            p = (i + j) // 2
            bases = []
            for way in (-1, 1):
                k, low = p, x[p]
                while 0 <= k < len(x) and x[k] <= x[p]:
                    low = min(low, x[k])
                    k += way
                bases.append(low)
            peaks.append(p)
            proms.append(x[p] - max(bases))
        i = j + 1
    return peaks, proms


def _sequences(rng: np.random.Generator) -> list[np.ndarray]:
    """Short and long sequences with ties, plateaus, ramps and noise."""
    out = [np.zeros(0), np.array([1.0]), np.array([0.0, 1.0]), np.array([0.0, 1.0, 0.0]),
           np.array([0.0, 1.0, 1.0, 0.0]), np.array([0.0, 1.0, 1.0]),
           np.array([1.0, 1.0, 1.0]), np.array([0.0, 2.0, 2.0, 1.0, 2.0, 2.0, 2.0, 0.0])]
    for n in list(range(1, 10)) * 20 + [200, 1000, 5000]:
        out += [rng.normal(size=n), rng.integers(0, 3, size=n).astype(float),
                np.round(np.cumsum(rng.normal(size=n)), 1),
                np.repeat(rng.normal(size=n), rng.integers(1, 4, size=n))[:n],
                np.abs(np.sin(np.arange(n) * 0.05)) + 1e-3 * rng.normal(size=n)]
    return out


def test_maxima_follow_the_definition_and_equal_scipy():
    rng = np.random.default_rng(17)
    for x in _sequences(rng):
        idx, prom = maxima(x)
        if len(x) <= 1000:
            want_idx, want_prom = _maxima_by_definition(x)
            assert idx.tolist() == want_idx and prom.tolist() == want_prom
        ref, props = find_peaks(x, prominence=0.0)
        assert np.array_equal(idx, ref)
        assert np.array_equal(prom, props["prominences"])


def test_maxima_on_a_long_recording_are_fast_enough():
    """100 000 noisy samples (a peak every few samples): vectorised, well under a
    second of CPU."""
    import time

    x = np.random.default_rng(2).normal(size=100_000)
    start = time.process_time()
    idx, prom = maxima(x)
    assert time.process_time() - start < 1.0
    ref, props = find_peaks(x, prominence=0.0)
    assert np.array_equal(idx, ref) and np.array_equal(prom, props["prominences"])
    assert math.isfinite(float(prom.sum()))


def test_rows_equal_the_whole_filters_rows_bit_for_bit():
    """A stretch of rows filtered on its own (the hold test's rests) is the same numbers
    as those rows of the whole recording filtered, at the ends and across them, and
    SciPy's filter gives them too."""
    from aou_dsl.measuring.savgol import savgol_rows

    rng = np.random.default_rng(12)
    for cols in (0, 3, 7):
        for x in _signals(rng, 180, cols):
            for window, order, deriv in ((61, 3, 0), (61, 2, 1), (5, 3, 0), (9, 2, 2)):
                whole = savgol(x, window, order, deriv, 0.001)
                assert np.array_equal(whole, savgol_filter(
                    x, window, order, deriv=deriv, delta=0.001, axis=0))
                for a, b in ((0, 180), (0, 10), (25, 40), (10, 100), (150, 180),
                             (170, 175), (40, 40), (-5, 500)):
                    for laid in (x, np.asfortranarray(x)):  # a recording's: by column
                        got = savgol_rows(laid, window, order, deriv, 0.001, a, b)
                        assert np.array_equal(got, whole[max(a, 0):b]), (window, a, b)


def test_one_dimensional_sums_equal_scipy_to_rounding():
    """The recording's fast filter of a 1-D travel (NumPy's correlation for each
    window's sum) against SciPy's filter (mode 'interp'): the ends bit for bit (fitted
    alike), the rest within rounding of the signal's scale, for values and the first
    and second derivatives, at the windows a recording's filter takes."""
    from aou_dsl.measuring.savgol import savgol_1d

    rng = np.random.default_rng(21)
    for n in (61, 62, 200, 2500):
        for x in _signals(rng, n, 0):
            for window, order, deriv in ((61, 2, 1), (61, 3, 0), (31, 2, 1), (15, 3, 2),
                                         (5, 2, 1)):
                if window > n:
                    continue
                for delta in (0.001, 0.004):
                    want = savgol_filter(x, window, order, deriv=deriv, delta=delta)
                    got = savgol_1d(x, window, order, deriv, delta)
                    half = window // 2
                    scale = float(np.abs(x).max() + 1e-300) * delta ** -deriv
                    assert np.array_equal(got[:half], want[:half])
                    assert np.array_equal(got[n - half:], want[n - half:])
                    assert np.abs(got - want).max() <= 1e-13 * scale, (n, window, deriv)
