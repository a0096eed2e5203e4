"""A build's measurement asks forward kinematics of its checks' samples but the last (its
grid ends a sample early): the answer comes from the kept batch, equal to the bit, and
in batch_fk's layout, to what batch_fk gives for those rows alone (whose last rows round
differently from the same rows inside a longer batch); only a true prefix of the same
arm's samples is answered so."""

from __future__ import annotations

import numpy as np

from aou_dsl.core import memo
from aou_dsl.robot import batch_fk as fk_module
from aou_dsl.robot.load import load_arm

KEPT = "aou_dsl.robot.batch_fk.rows_fk"


def _counting(monkeypatch) -> list[int]:
    calls: list[int] = []
    real = fk_module.batch_fk
    monkeypatch.setattr(fk_module, "batch_fk",
                        lambda arm, rows: calls.append(len(rows)) or real(arm, rows))
    return calls


def _same(got, want) -> bool:
    return all(np.array_equal(g, w) and (g.flags.c_contiguous, g.flags.f_contiguous)
               == (w.flags.c_contiguous, w.flags.f_contiguous)
               for g, w in zip(got, want, strict=True))


def test_the_first_rows_of_a_kept_batch_are_what_batch_fk_gives_for_them(monkeypatch):
    """Sizes where the last rows of the shorter batch round differently from the same
    rows of the longer one (700 and 699 rows; 5224 and 5222) are answered as the shorter
    batch computes them; only the last rows are computed again."""
    arm = load_arm("panda")
    rng = np.random.default_rng(7)
    cases = [(np.sin(np.outer(np.linspace(0.0, 3.0, 700), np.arange(1.0, 8.0))), 699),
             (rng.uniform(-3.0, 3.0, (5224, 7)), 5222),
             *((q, len(q) - int(rng.integers(1, 4))) for q in
               (rng.uniform(-3.0, 3.0, (int(rng.integers(300, 9000)), 7)) for _ in range(8)))]
    for q, m in cases:
        memo.clear([KEPT])
        calls = _counting(monkeypatch)
        fk_module.rows_fk(arm, q)
        got = fk_module.rows_fk(arm, q[:m])  # a view, as the grid holds it
        assert calls[0] == len(q) and len(calls) == 2 and calls[1] < 200
        monkeypatch.undo()
        want = fk_module.batch_fk(arm, np.ascontiguousarray(q[:m]))
        assert _same(got, want)
        got[0][:] = 0.0  # a copy: the kept answer is untouched
        assert _same(fk_module.rows_fk(arm, q[:m]), want)


def test_only_a_true_prefix_of_the_same_arms_samples_is_answered_from_it(monkeypatch):
    memo.clear([KEPT])
    panda, ur5 = load_arm("panda"), load_arm("ur5")
    q = np.random.default_rng(5).uniform(-1.0, 1.0, (900, 7))
    calls = _counting(monkeypatch)
    fk_module.rows_fk(panda, q)
    moved = q[:800].copy()
    moved[150, 2] += 1e-3
    for arm, rows in ((panda, q[1:]), (panda, moved), (ur5, q[:800, :6])):
        fk_module.rows_fk(arm, rows)
    assert calls == [900, 899, 800, 800]
    monkeypatch.undo()
    assert _same(fk_module.rows_fk(panda, moved), fk_module.batch_fk(panda, moved))


def test_a_kernel_that_rounds_by_position_is_caught_and_computed_whole(monkeypatch):
    """The rows computed again before the last ones must equal the kept ones: where they
    do not (here a product that rounds short batches its own way), the asked rows are
    computed whole, never stitched."""
    memo.clear([KEPT])
    arm = load_arm("panda")
    q = np.random.default_rng(9).uniform(-2.0, 2.0, (1000, 7))
    real = fk_module.batch_fk
    fk_module.rows_fk(arm, q)

    def shifted(a, rows):  # short batches round up by one unit in the last place
        pos, rot = real(a, rows)
        return (np.nextafter(pos, np.inf), rot) if len(rows) < 300 else (pos, rot)

    calls: list[int] = []
    monkeypatch.setattr(fk_module, "batch_fk",
                        lambda a, rows: calls.append(len(rows)) or shifted(a, rows))
    got = fk_module.rows_fk(arm, q[:998])
    assert calls[-1] == 998
    assert _same(got, real(arm, np.ascontiguousarray(q[:998])))
