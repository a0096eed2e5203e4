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


def maxima(x: np.ndarray, among: np.ndarray | None = None
           ) -> tuple[np.ndarray, np.ndarray]:
    """The local maxima of the finite 1-D sequence ``x`` (their indices, increasing) and
    their prominences; with ``among`` (booleans, one per sample), only the maxima
    reported at a sample it marks (each one's prominence is the same either way: the
    walks see every sample; only those not asked for are not walked)."""
    x = np.asarray(x, dtype=np.float64)
    n = len(x)
    if n < 3:
        return np.zeros(0, np.intp), np.zeros(0)
    change = np.flatnonzero(x[1:] != x[:-1]) + 1
    starts = np.concatenate([[0], change])
    ends = np.concatenate([change - 1, [n - 1]])
    # Neighbouring runs hold different values: a run is a crest when the step into it
    # rises (or it starts ``x``) and the step out of it falls (or it ends ``x``); a peak
    # is a crest at neither end.
    up = x[change] > x[change - 1]
    crest = np.concatenate([[True], up]) & np.concatenate([~up, [True]])
    peak = crest.copy()
    peak[0] = peak[-1] = False
    first, last = starts[peak], ends[peak]
    if among is not None:
        asked = among[(first + last) // 2]
        first, last = first[asked], last[asked]
    # Both ends of every crest, and of ``x``: in order already (a crest ends before the
    # next starts), so merged without a sort; a crest of one sample is one mark.
    ordered = np.concatenate([[0], np.column_stack([starts[crest], ends[crest]]).ravel(),
                              [n - 1]])
    marks = ordered[np.concatenate([[True], ordered[1:] != ordered[:-1]])]
    prominences = _prominences(x, marks, first, last)
    return (first + last) // 2, prominences


def _prominences(x: np.ndarray, marks: np.ndarray, first: np.ndarray,
                 last: np.ndarray) -> np.ndarray:
    """The prominence of each peak, the run of equal samples ``first``..``last``.

    Walking from a peak, the first sample higher than it lies on the flank of a crest
    higher than it (a run of equal samples with no higher neighbour), or is an end of
    ``x``. So each side is a walk over ``marks`` (both ends of every crest, and both
    ends of ``x``) to the first one higher than the peak, and the base is the lowest
    sample of the stretches between the marks walked over. Both are looked up in
    doubling tables (the highest mark and the lowest stretch of every block of 1, 2, 4,
    ... consecutive marks): from the largest block down, a peak's walk goes on over
    the next block when no mark in it is higher than the peak. So every peak walks in
    log(len(marks)) vectorised steps, whatever the distance to its bases."""
    if len(first) == 0:
        return np.zeros(0)
    stretch = np.minimum.reduceat(x, marks)  # x[marks[j]:marks[j + 1]], and x[-1]
    highs, lows = _block_tables(x[marks]), _block_tables(stretch, np.minimum)
    top = x[first]
    left = _walk(highs, lows, np.searchsorted(marks, first), top, -1)
    right = _walk(highs, lows, np.searchsorted(marks, last), top, +1)
    return top - np.maximum(left, right)


def _block_tables(v: np.ndarray, pick: np.ufunc = np.maximum) -> list[np.ndarray]:
    """``table[k][i]``: ``pick`` (the maximum, or the minimum) of ``v[i:i + 2**k]``, for
    every block that fits in ``v``."""
    table = [v]
    size = 1
    while 2 * size <= len(v):
        prev = table[-1]
        table.append(pick(prev[:-size], prev[size:]))
        size *= 2
    return table


def _walk(highs: list[np.ndarray], lows: list[np.ndarray], at: np.ndarray,
          top: np.ndarray, way: int) -> np.ndarray:
    """From mark ``at`` of each peak, walking ``way`` (-1 left, +1 right) over the marks
    no higher than the peak's ``top``: the lowest sample met, up to (not including) the
    first mark higher than the peak, or to the end of ``x``."""
    m = len(highs[0])
    reach = at.copy()  # the farthest mark walked to so far
    base = top.copy()
    for k in range(len(highs) - 1, -1, -1):
        size = 1 << k
        marks = reach - size if way < 0 else reach + 1  # the next block's first mark
        fits = (marks >= 0) & (marks + size <= m)
        marks = np.where(fits, marks, 0)
        step = fits & (highs[k][marks] <= top)
        stretches = marks if way < 0 else np.where(step, reach, 0)  # their first one
        np.minimum(base, lows[k][stretches], out=base, where=step)
        reach += np.where(step, way * size, 0)
    # The stretch that ends (left) or starts (right) at the mark the walk stopped at.
    if way < 0:
        more = reach > 0
        np.minimum(base, lows[0][np.maximum(reach - 1, 0)], out=base, where=more)
    else:
        np.minimum(base, lows[0][reach], out=base)
    return base
