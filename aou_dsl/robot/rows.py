"""Per-configuration results kept between builds, by the configuration's bytes.

A recompilation after one value changed (a pause, one episode's acceleration) moves
most samples only in time: the arm passes through the same joint values as before. What
depends on the joint values alone (forward kinematics, a collision engine's distances) is
the same for those samples, to the bit, so it is looked up instead of computed again.
Only rows never seen are computed, all together in one call; a call on one row is made
on two (the row twice), as a batch of one can round differently from a larger batch.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from typing import cast

import numpy as np

from ..core.memo import Keyed, cached

__all__ = ["RowMemo", "kept", "row_keys"]

#: Rows a memo holds before it starts again empty (about 100 bytes a row and output).
MEMO_ROWS = 100_000


def row_keys(q: np.ndarray) -> list[bytes]:
    """Each row of ``q`` (N, n) as bytes: equal keys, equal joint values to the bit."""
    q = np.ascontiguousarray(np.atleast_2d(q), dtype=float)
    if q.shape[1] == 0:
        return [b""] * len(q)
    rows = q.view(np.dtype((np.void, q.shape[1] * q.itemsize))).ravel()
    return cast("list[bytes]", rows.tolist())  # a void row's item is its bytes


class RowMemo:
    """The arrays a function gives for rows of ``q``, kept row by row (at most ``size``
    rows: beyond, it starts again empty, so memory stays bounded)."""

    def __init__(self, size: int = MEMO_ROWS):
        self.size = size
        self.index: dict[bytes, int] = {}
        self.store: list[np.ndarray] = []
        self.used = 0
        #: Per output, whether ``fn`` gives it in Fortran order: the copies given back
        #: are laid out the same, since numpy sums along a contiguous axis pairwise and
        #: along another one by one (the last bits of a mean would differ).
        self.fortran: list[bool] = []

    def clear(self) -> None:
        """Forget every row."""
        self.index, self.store, self.used, self.fortran = {}, [], 0, []

    def of(self, q: np.ndarray, fn: Callable[[np.ndarray], tuple[np.ndarray, ...]]
           ) -> tuple[np.ndarray, ...]:
        """``fn(q)``, whose outputs are arrays with one row per row of ``q``; rows seen
        before are not computed again."""
        q = np.ascontiguousarray(np.atleast_2d(q), dtype=float)
        if len(q) > self.size:  # more than it keeps: computed, not kept
            return tuple(fn(q))
        keys = row_keys(q)
        at = np.fromiter(map(self.index.get, keys, itertools.repeat(-1)), dtype=np.intp,
                         count=len(keys))
        missing = np.flatnonzero(at < 0)
        if len(missing):
            if self.used + len(missing) > self.size:
                self.clear()
                at[:], missing = -1, np.arange(len(q))
            at[missing] = self._add(q, keys, missing, fn)
        return tuple(np.asfortranarray(s[at]) if f else s[at]
                     for s, f in zip(self.store, self.fortran, strict=True))

    def _add(self, q: np.ndarray, keys: list[bytes], missing: np.ndarray,
             fn: Callable[[np.ndarray], tuple[np.ndarray, ...]]) -> np.ndarray:
        """Compute the missing rows (each distinct row once) and keep them; their places
        in the store, in the order of ``missing``."""
        first: dict[bytes, int] = {}
        for i in missing.tolist():
            first.setdefault(keys[i], i)
        rows = np.fromiter(first.values(), dtype=np.intp, count=len(first))
        outs = fn(q[rows] if len(rows) > 1 else q[np.r_[rows, rows]])
        start = self.used
        self.fortran = [bool(np.asarray(out).flags.f_contiguous
                             and not np.asarray(out).flags.c_contiguous) for out in outs]
        for k, out in enumerate(outs):
            out = np.asarray(out)[:len(rows)]
            if not self.store or len(self.store) <= k:
                self.store.append(np.empty((max(1024, 2 * len(rows)), *out.shape[1:]),
                                           dtype=out.dtype))
            if start + len(rows) > len(self.store[k]):
                grown = np.empty((2 * (start + len(rows)), *out.shape[1:]), out.dtype)
                grown[:start] = self.store[k][:start]
                self.store[k] = grown
            self.store[k][start:start + len(rows)] = out
        self.used = start + len(rows)
        for n, key in enumerate(first):
            self.index[key] = start + n
        return np.fromiter((self.index[keys[i]] for i in missing.tolist()), dtype=np.intp,
                           count=len(missing))


def kept(owner: object, name: str, q: np.ndarray,
         fn: Callable[[np.ndarray], tuple[np.ndarray, ...]]) -> tuple[np.ndarray, ...]:
    """``fn(q)`` through the memo of ``owner`` (an arm, a kinematic chain, kept alive
    by the memo) and ``name``. A ``q`` of more than a quarter of what a memo holds (a
    long recording) is computed directly: it would push every other row out."""
    if len(q) > MEMO_ROWS // 4:
        return tuple(fn(q))
    return _memo(Keyed((id(owner), name), owner)).of(q, fn)


@cached(maxsize=8)
def _memo(owner: Keyed) -> RowMemo:
    """One memo per owner and function (the key holds the owner, so its id stays its)."""
    return RowMemo()
