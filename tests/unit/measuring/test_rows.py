"""Per-row functions computed as a batch computes them: what :func:`by_rows` gives for
any rows is what forward kinematics gives for a batch holding them, to the bit and in
the same memory layout (one row alone too), and row keys tell rows apart by their bits."""

from __future__ import annotations

import numpy as np

from aou_dsl.robot.batch_fk import batch_fk, rows_fk
from aou_dsl.robot.load import load_arm
from aou_dsl.robot.rows import by_rows, row_keys


def test_any_rows_give_what_a_batch_holding_them_gives_to_the_bit():
    """Forward kinematics of rows in batches of every size (one row alone, repeats)
    equals those rows of one batch of them all, bit for bit, laid out as batch_fk lays
    them out."""
    arm = load_arm("panda")
    q = np.random.default_rng(3).uniform(-1.5, 1.5, (400, arm.n))
    whole = batch_fk(arm, q)
    for at in (np.arange(400), np.r_[100:400, 0, 5, 5], np.r_[399], np.r_[7:9]):
        got = rows_fk(arm, q[at])
        for g, w in zip(got, whole, strict=True):
            assert np.array_equal(g, w[at])
        for g, w in zip(got, batch_fk(arm, q[at]), strict=True):
            assert (g.flags.c_contiguous, g.flags.f_contiguous) == (
                w.flags.c_contiguous, w.flags.f_contiguous)


def test_one_row_is_computed_as_two_and_laid_out_as_the_function_lays_out():
    calls: list[int] = []

    def fn(rows):
        calls.append(len(rows))
        return rows * 2.0, np.asfortranarray(rows + 1.0)

    q = np.arange(6.0).reshape(2, 3)
    two = by_rows(q[:1], fn)
    assert calls == [2]
    assert np.array_equal(two[0], q[:1] * 2) and np.array_equal(two[1], q[:1] + 1)
    assert two[0].flags.c_contiguous and two[0].shape == (1, 3)
    assert by_rows(q, fn)[1].flags.f_contiguous and calls == [2, 2]


def test_row_keys_tell_rows_apart_by_their_bits():
    q = np.array([[0.0, 1.0], [0.0, 1.0], [-0.0, 1.0], [0.0, np.nextafter(1.0, 2.0)]])
    keys = row_keys(q)
    assert keys[0] == keys[1] and len(set(keys)) == 3


def test_a_builds_second_look_at_its_samples_is_kept_and_never_lies(monkeypatch):
    """The checks and the measurement of a build ask forward kinematics and the joints'
    noise of the same samples: the second answer is the first, kept by the samples'
    bytes; a copy (changing it changes nothing kept), and samples one bit apart are
    computed again."""
    from aou_dsl.measuring import signal
    from aou_dsl.robot import batch_fk as fk_module

    arm = load_arm("panda")
    t = np.linspace(0.0, 2.0, 500)
    q = np.sin(np.outer(t, np.arange(1.0, arm.n + 1.0)))
    calls: list[str] = []
    real_fk, real_noise = fk_module.batch_fk, signal._joint_noise
    monkeypatch.setattr(fk_module, "batch_fk", lambda a, r: calls.append("fk") or real_fk(a, r))
    monkeypatch.setattr(signal, "_joint_noise",
                        lambda a, b: calls.append("noise") or real_noise(a, b))
    first = rows_fk(arm, q)
    noise = signal.joint_noise(t, q)
    first[0][:] = 0.0
    noise.sigma[:] = -1.0
    again, noise_again = rows_fk(arm, q.copy()), signal.joint_noise(t.copy(), q.copy())
    assert calls == ["fk", "noise"]
    want = real_fk(arm, q)
    assert np.array_equal(again[0], want[0]) and np.array_equal(again[1], want[1])
    assert again[0].flags.f_contiguous == want[0].flags.f_contiguous
    assert np.array_equal(noise_again.sigma, real_noise(t, q).sigma)
    moved = q.copy()
    moved[250, 3] = np.nextafter(moved[250, 3], 9.0)
    assert not np.array_equal(rows_fk(arm, moved)[0], want[0])
    signal.joint_noise(t, moved)
    assert calls == ["fk", "noise", "fk", "noise"]
