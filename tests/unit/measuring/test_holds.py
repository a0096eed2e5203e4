"""The measurement's search for where a motion passes through zero speed without a
rest sample (``measuring/holds.py``), on speed levels made by hand."""

from types import SimpleNamespace

import numpy as np

from aou_dsl.measuring.holds import _dips


def _rest(level: np.ndarray) -> SimpleNamespace:
    """What ``_dips`` reads of a recording's rest signals: one joint moving forward at
    ``level`` (its velocity never changes sign), sampled at 250 Hz."""
    n = len(level)
    v = level[:, None] * 0.01
    thr = np.full((n, 1), 0.001)
    return SimpleNamespace(level=level, v=v, thr=thr, ratio=np.abs(v) / thr, v_long=v,
                           thr_long=thr, ratio_long=np.abs(v) / thr, window=0,
                           t=np.arange(n) * 0.004, h=0.004, carried=None,
                           q=np.cumsum(v, axis=0) * 0.004)


def test_a_flat_stretch_of_equal_levels_is_read_at_a_sample_not_as_a_reversal():
    """A recording that holds one speed for a few samples (a live run's repeated sample)
    makes a flat valley whose middle falls between two samples. With no joint reversing
    there, the dip is read at a sample; it was taken for a reversal and looked up in the
    table of reversals (an internal error, KeyError, in ``aouc measure``)."""
    level = np.array([10, 8, 6, 2, 2, 2, 2, 6, 8, 10.0])
    (dip,) = _dips(_rest(level), np.zeros(len(level), bool))
    t0, t1, k = dip
    assert 3 <= k <= 6 and t0 <= t1
