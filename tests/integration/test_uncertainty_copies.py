"""How the re-noised copies of aou_dsl/measuring/uncertainty.py are made cheaply: their
hand poses expanded about the recording's own (which its measurement has already
computed), with the Jacobian at every few samples; and four copies where they all read
the recording's segmentation, ten where they do not.
"""

from __future__ import annotations

import numpy as np
import pytest

from aou_dsl.core.trajectory import Trajectory
from aou_dsl.measuring import uncertainty
from aou_dsl.measuring.linearised import JACOBIAN_STEP, Linearised
from aou_dsl.measuring.measured import _measure
from aou_dsl.measuring.uncertainty import attach
from aou_dsl.robot.batch_fk import batch_fk, batch_fk_jacobian
from aou_dsl.robot.load import load_arm
from tests.conftest import BEHAVIOURS
from tests.integration.test_recordings import build
from tests.recsim import noisy, record


@pytest.mark.parametrize("robot", ["panda", "ur5"])
def test_a_copys_pose_about_the_recordings_own_is_the_exact_one_to_the_noise_squared(robot):
    """A recording's joints (a wandering path at 1 kHz with 1e-3 rad of noise), its
    smoothed base and a copy: each pose expanded about the recording's, with the
    Jacobian interpolated between every eighth sample, misses the exact one by the
    noise squared times the arm's reach, and the interpolated Jacobian's expansion
    that of the exact Jacobian by a hundredth of what the noise moves the hand."""
    arm = load_arm(robot)
    rng = np.random.default_rng(6)
    n = 20 * JACOBIAN_STEP + 3  # the last knot is the last sample, not on the step
    path = np.cumsum(rng.normal(0.0, 2e-3, (n, arm.model.nq)), axis=0) + 0.3
    rec = path + rng.normal(0.0, 1e-3, path.shape)
    fk = Linearised(arm, {"grid": rec})
    pos0, rot0, jac = batch_fk_jacobian(arm, rec)
    for q in (path, path + rng.normal(0.0, 1e-3, path.shape)):
        pos, rot = fk(q, "grid")
        want_pos, want_rot = batch_fk(arm, q)
        moved = np.abs(want_pos - pos0).max()
        assert moved > 1e-3
        # A copy differs from the recording by two draws of the noise: sqrt(2) times it.
        assert np.abs(pos - want_pos).max() < 6e-5 < 0.05 * moved
        assert np.abs(rot - want_rot).max() < 1e-4
        full = pos0 + np.einsum("nkj,nj->nk", jac[:, :3], q - rec)
        assert np.abs(pos - full).max() < 0.01 * moved
    # Another clock's length is computed exactly.
    pos, rot = fk(path[:-1], "grid")
    assert np.array_equal(pos, batch_fk(arm, path[:-1])[0])


def _recording(name: str, noise: float, rate: float, seed: int) -> Trajectory:
    doc = build((BEHAVIOURS / f"{name}.aou").read_text(), name)[0]
    rec = record(doc, noisy(noise, rate, seed), dynamic=False)
    return Trajectory(rec["t"], rec["q"], tuple(rec["joint_names"]), rec["robot"], None,
                      tuple(rec["goal"]["position"]))


def _attached(tr: Trajectory) -> tuple:
    """``tr`` measured, and given its uncertainty; with the recordings measured for it
    (the smoothed base, then each copy)."""
    m, jn = _measure(tr)
    calls = []

    def once(r, pinned, fk):
        calls.append(r)
        return _measure(r, pinned, fk)

    attach(m, tr, jn, once)
    return m, calls


@pytest.mark.parametrize("name,noise,rate,seed,copies", [
    ("fearful", 1e-4, 1000.0, 2, uncertainty.FIRST),  # every copy reads one segmentation
    ("hesitant", 1e-3, 250.0, 3, uncertainty.REPLICATES),  # its pause count flips
])
def test_four_copies_where_they_agree_on_the_segmentation_ten_where_not(name, noise, rate,
                                                                       seed, copies):
    """The base and the first four copies are measured; when a count or a presence
    differs among them and the recording, six more copies are."""
    m, calls = _attached(_recording(name, noise, rate, seed))
    assert len(calls) == 1 + copies
    flipped = [k for k, s in m.uncertainty.items() if not s.stable]
    assert bool(flipped) == (copies == uncertainty.REPLICATES)


def test_a_state_the_first_copies_flip_takes_no_more_copies():
    """60 s of approaches, pauses, retreats and gazes whose C-V point lies on the border of
    fearful and curious: at 3e-4 rad and 250 Hz its copies read both states while every
    count and presence holds. The state is then already not to be trusted (R411 names
    both), and six more copies would only list it again: four are measured (ten were,
    which made the benchmark's noisy minute take twice as long)."""
    from aou_dsl.compiler.pipeline import CompileOptions, compile_behaviour
    from aou_dsl.lang.linter import load

    text = ("approach a=0.05\npause 2s x14\nretreat 0.05m a=0.1 x8\n"
            "gaze horizontal 15deg x4\n")
    clean = compile_behaviour(load(text, "minute.aou")[0],
                              CompileOptions(rate=250.0)).trajectory
    q = np.asarray(clean.q)
    tr = clean.with_(q=q + np.random.default_rng(2).normal(0, 3e-4, q.shape), qd=None,
                     qdd=None)
    m, calls = _attached(tr)
    assert set(m.inferred.states) == {"fearful", "curious"}
    assert all(s.stable for s in m.uncertainty.values())
    assert len(calls) == 1 + uncertainty.FIRST
    r411 = [d for d in m.diagnostics if d.code == "R411"]
    assert r411 and "fearful" in r411[0].message and "curious" in r411[0].message
