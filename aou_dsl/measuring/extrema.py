"""Local maxima of a sequence and how far each stands out (its prominence), with NumPy
only: the measurement finds the dips of a motion's speed with them, and SciPy's signal
package, which offers the same, costs a cold command about a second to import.

A local maximum is a sample, or a run of equal samples (a plateau), higher than the
sample just before it and the one just after it; neither end of the sequence is one. A
plateau is reported at its middle sample (the left one of two middles).

A maximum's prominence is its height above the higher of its two bases. Its base on one
side is the lowest sample met walking from it that way, up to the first sample higher
than it or the end of the sequence.
"""

from __future__ import annotations

import numpy as np

__all__ = ["maxima"]


def maxima(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The local maxima of the finite 1-D sequence ``x`` (their indices, increasing) and
    their prominences."""
    x = np.asarray(x, dtype=np.float64)
    n = len(x)
    if n < 3:
        return np.zeros(0, np.intp), np.zeros(0)
    change = np.flatnonzero(x[1:] != x[:-1]) + 1
    starts = np.concatenate([[0], change])
    ends = np.concatenate([change - 1, [n - 1]])
    inner = (starts >= 1) & (ends <= n - 2)
    starts, ends = starts[inner], ends[inner]
    higher = (x[starts - 1] < x[starts]) & (x[ends + 1] < x[ends])
    peaks = (starts[higher] + ends[higher]) // 2
    return peaks, _prominences(x, peaks)


def _prominences(x: np.ndarray, peaks: np.ndarray) -> np.ndarray:
    """The prominence of each of ``peaks`` in ``x``.

    Each side is walked by doubling tables (the maximum and the minimum of every block
    of 1, 2, 4, ... samples): from the largest block down, a peak's reach is extended
    by the next block when no sample in it is higher than the peak, and the block's
    minimum joins the side's base. So every peak walks in log(len(x)) vectorised steps,
    whatever the distance to its bases."""
    if len(peaks) == 0:
        return np.zeros(0)
    highs, lows = _block_tables(x)
    top = x[peaks]
    left = _base(highs, lows, peaks, top, -1)
    right = _base(highs, lows, peaks, top, +1)
    return top - np.maximum(left, right)


def _block_tables(x: np.ndarray) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """``highs[k][i]`` and ``lows[k][i]``: the maximum and the minimum of
    ``x[i:i + 2**k]``, for every block that fits in ``x``."""
    highs, lows = [x], [x]
    size = 1
    while 2 * size <= len(x):
        hi, lo = highs[-1], lows[-1]
        highs.append(np.maximum(hi[:-size], hi[size:]))
        lows.append(np.minimum(lo[:-size], lo[size:]))
        size *= 2
    return highs, lows


def _base(highs: list[np.ndarray], lows: list[np.ndarray], peaks: np.ndarray,
          top: np.ndarray, way: int) -> np.ndarray:
    """The lowest sample from each peak (itself included) walking ``way`` (-1 left, +1
    right) up to, not including, the first sample higher than the peak."""
    n = len(highs[0])
    reach = peaks.copy()  # the farthest sample walked so far
    base = top.copy()
    for k in range(len(highs) - 1, -1, -1):
        size = 1 << k
        first = reach - size if way < 0 else reach + 1  # the next block's first sample
        fits = (first >= 0) & (first + size <= n)
        at = np.where(fits, first, 0)
        step = fits & (highs[k][at] <= top)
        base = np.where(step, np.minimum(base, lows[k][at]), base)
        reach = np.where(step, reach + way * size, reach)
    return base
