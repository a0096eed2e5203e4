"""Joint rows as bytes, and per-row functions computed as a batch computes them.

:func:`row_keys` names a configuration by its bytes: equal keys, equal joint values to
the bit (the collision sweep keeps PyBullet's answers by them, which cost far more than
the look-up). :func:`by_rows` computes a per-row function (forward kinematics) on a
batch; a batch of one row is computed as two (the row twice), as a batch of one can
round differently from a larger batch.

Forward kinematics is not kept between builds: finding thousands of rows among those
kept costs about what computing them does (a couple of milliseconds for a motion's
5,000 samples), and keeping a motion never seen before costs twice that.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import cast

import numpy as np

__all__ = ["Content", "by_rows", "content_key", "row_keys"]


def row_keys(q: np.ndarray) -> list[bytes]:
    """Each row of ``q`` (N, n) as bytes: equal keys, equal joint values to the bit."""
    q = np.ascontiguousarray(np.atleast_2d(q), dtype=float)
    if q.shape[1] == 0:
        return [b""] * len(q)
    rows = q.view(np.dtype((np.void, q.shape[1] * q.itemsize))).ravel()
    return cast("list[bytes]", rows.tolist())  # a void row's item is its bytes


class Content:
    """Bytes that compare by their whole content and hash by a sample of it (the length
    and every 4099th byte): a key of arrays of a few hundred kilobytes is hashed in
    microseconds, and equal keys are still equal arrays to the bit."""

    __slots__ = ("data", "_hash")

    def __init__(self, data: bytes):
        self.data = data
        self._hash = hash((len(data), data[::4099], data[-64:]))

    def __hash__(self) -> int:
        return self._hash

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Content) and self.data == other.data


def content_key(*arrays: np.ndarray) -> tuple:
    """Arrays by what they hold: each one's type, shape and bytes (equal keys, equal
    arrays to the bit), for a cache of a function of them."""
    return tuple((a.dtype.str, a.shape, Content(np.ascontiguousarray(a).tobytes()))
                 for a in map(np.asarray, arrays))


def by_rows(q: np.ndarray, fn: Callable[[np.ndarray], tuple[np.ndarray, ...]]
            ) -> tuple[np.ndarray, ...]:
    """``fn(q)`` of the rows of ``q`` (N, n), whose outputs have one row per row of
    ``q``: each row's values are those of any batch of two rows or more holding it (but
    the last few rows of a batch, where a matrix product may round otherwise: see
    :func:`.batch_fk.rows_fk`). One row alone is computed as two, and given back laid
    out as ``fn`` lays out its outputs (C or Fortran order)."""
    q = np.ascontiguousarray(np.atleast_2d(q), dtype=float)
    if len(q) != 1:
        return tuple(fn(q))
    outs = [np.asarray(out) for out in fn(np.vstack([q, q]))]
    return tuple(np.asfortranarray(out[:1]) if out.flags.f_contiguous
                 and not out.flags.c_contiguous else np.ascontiguousarray(out[:1])
                 for out in outs)
