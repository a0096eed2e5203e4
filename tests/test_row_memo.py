"""The row memo of a recompilation: what it gives back is what the function gives for
the same rows, to the bit and in the same memory layout, whichever rows it had seen."""

from __future__ import annotations

import numpy as np

from aou_dsl.robot.batch_fk import batch_fk
from aou_dsl.robot.load import load_arm
from aou_dsl.robot.rows import RowMemo, row_keys


def test_rows_seen_and_unseen_give_a_fresh_batch_to_the_bit():
    """Forward kinematics of rows partly seen before (and one row alone) equal one batch
    of them all, bit for bit, laid out as batch_fk lays them out."""
    arm = load_arm("panda")
    q = np.random.default_rng(3).uniform(-1.5, 1.5, (400, arm.n))
    memo = RowMemo(size=1000)

    def fk(rows):
        return batch_fk(arm, rows)

    memo.of(q[:250], fk)
    for rows in (np.vstack([q[100:400], q[:1], q[5:6], q[5:6]]), q[399:400], q[7:9]):
        got, want = memo.of(rows, fk), batch_fk(arm, rows)
        for g, w in zip(got, want, strict=True):
            assert np.array_equal(g, w)
            assert (g.flags.c_contiguous, g.flags.f_contiguous) == (
                w.flags.c_contiguous, w.flags.f_contiguous)


def test_only_new_rows_are_computed_and_a_full_memo_starts_again():
    """Each distinct new row is computed once; past its size the memo forgets and
    computes again, so its memory stays bounded."""
    calls: list[int] = []

    def double(rows):
        calls.append(len(rows))
        return (rows * 2.0,)

    memo = RowMemo(size=6)
    q = np.arange(20.0).reshape(10, 2)
    assert np.array_equal(memo.of(q[:4], double)[0], q[:4] * 2)
    assert np.array_equal(memo.of(np.vstack([q[:4], q[4:5], q[4:5]]), double)[0],
                          np.vstack([q[:4], q[4:5], q[4:5]]) * 2)
    assert calls == [4, 2]  # the new row once (a single row is computed as two)
    assert np.array_equal(memo.of(q[5:9], double)[0], q[5:9] * 2)  # 9 rows > 6: again
    assert calls[-1] == 4 and memo.used == 4
    assert np.array_equal(memo.of(q, double)[0], q * 2)  # more than it holds: not kept
    assert memo.used == 4


def test_row_keys_tell_rows_apart_by_their_bits():
    q = np.array([[0.0, 1.0], [0.0, 1.0], [-0.0, 1.0], [0.0, np.nextafter(1.0, 2.0)]])
    keys = row_keys(q)
    assert keys[0] == keys[1] and len(set(keys)) == 3
