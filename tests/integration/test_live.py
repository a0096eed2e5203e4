"""Live regulation (aou_dsl.live.regulator): hysteresis, the uncertainty mapping, and re-plans that
start at the arm's state with position, velocity and acceleration continuous.

Continuity is checked with finite differences against explicit bounds: between samples
``h`` apart, a motion whose jerk stays within ``J`` and acceleration within ``A`` has
``|dqdd| <= J h``, ``|dqd - h (qdd0 + qdd1) / 2| <= J h^2 / 4`` and
``|dq - h (qd0 + qd1) / 2| <= A h^2 / 4``; a jump in position, velocity or acceleration
breaks them.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import aou_dsl
from aou_dsl.core.diagnostics import AouError
from aou_dsl.lang.cv import CANONICAL, classify
from aou_dsl.lang.ir import State
from aou_dsl.live.regulator import PATH, Hysteresis, Regulator, from_uncertainty
from aou_dsl.live.splice import LEAD, transition
from tests.conftest import ROOT

EPS = 1e-9


@pytest.fixture(scope="module")
def reg() -> Regulator:
    return Regulator("panda")


@pytest.fixture(scope="module")
def moving(reg):
    """A confident reach from its start, and a sample of it while the arm accelerates."""
    first = reg.replan(reg.plan(State.CONFIDENT, 0.5).q[0], None, None, State.CONFIDENT,
                       0.5, restart=True).trajectory
    on = np.flatnonzero(np.abs(first.qd).max(axis=1) > 0.05)
    k = int(on[len(on) // 3])
    return first, k


def _continuous(t, q, qd, qdd, jerk, accel):
    """Finite differences of consecutive samples within the bounds of the module's
    docstring (per joint)."""
    h = np.diff(t)[:, None]
    assert np.all(np.abs(np.diff(qdd, axis=0)) <= jerk * h + EPS)
    assert np.all(np.abs(np.diff(qd, axis=0) - h * (qdd[1:] + qdd[:-1]) / 2)
                  <= jerk * h ** 2 / 4 + EPS)
    assert np.all(np.abs(np.diff(q, axis=0) - h * (qd[1:] + qd[:-1]) / 2)
                  <= accel * h ** 2 / 4 + EPS)


def _executed(first, k, new):
    """What the arm does: ``first`` up to sample ``k``, then ``new`` (which starts there)."""
    t0 = first.t[k]
    return (np.concatenate([first.t[:k + 1], t0 + new.t[1:]]),
            *(np.vstack([getattr(first, f)[:k + 1], getattr(new, f)[1:]])
              for f in ("q", "qd", "qdd")))


def test_replan_mid_motion_is_continuous(reg, moving):
    """A re-plan from a moving, accelerating arm starts exactly at its state, and the motion
    through the splice and into the new plan has no jump (the arm's jerk limits)."""
    first, k = moving
    rep = reg.replan(first.q[k], first.qd[k], first.qdd[k], State.HESITANT, 1.0)
    new = rep.trajectory
    for f in ("q", "qd", "qdd"):
        assert np.allclose(getattr(new, f)[0], getattr(first, f)[k], atol=EPS, rtol=0)
    assert rep.transition > 0 and np.abs(first.qdd[k]).max() > 0.01
    t, q, qd, qdd = _executed(first, k, new)
    junction = k + int(np.searchsorted(new.t, rep.transition))
    window = slice(k - 5, junction + 5)
    _continuous(t[window], q[window], qd[window], qdd[window], reg.arm.jmax, reg.arm.amax)


def test_transition_is_jerk_limited_at_fine_resolution(reg, moving):
    """Sampled 40 times finer than the output, the transition leaves the arm's exact state
    and arrives at the plan's exact state, its jerk within the regulator's share of the
    arm's jerk limits all the way."""
    first, k = moving
    plan = reg.plan(State.HESITANT, 1.0)
    x = (first.q[k], first.qd[k], first.qdd[k])
    j = len(plan.t) // 2
    target = (plan.q[j], plan.qd[j], plan.qdd[j])
    t, q, qd, qdd = transition(reg, x, target, 10000.0)
    for got, want in zip((q, qd, qdd), (*x, ), strict=True):
        assert np.allclose(got[0], want, atol=EPS, rtol=0)
    for got, want in zip((q, qd, qdd), target, strict=True):
        assert np.allclose(got[-1], want, atol=1e-7, rtol=0)
    jerk = reg.transition_scale * reg.arm.jmax
    _continuous(t, q, qd, qdd, jerk * (1 + 1e-6), reg.arm.amax)


def test_replan_output_passes_the_checks(reg, moving):
    """The whole re-planned trajectory (transition and the rest of the plan) passes the
    safety replay."""
    first, k = moving
    rep = reg.replan(first.q[k], first.qd[k], first.qdd[k], State.FEARFUL, 0.5)
    assert aou_dsl.check(rep.trajectory, dynamic=False).ok


def test_replanning_into_the_same_plan_goes_on_where_the_arm_is(reg):
    """Re-planned into the plan it is following, the arm joins it where it is: moving, at
    that sample; holding, no earlier than it (a re-plan never starts a pause over)."""
    plan = reg.plan(State.HESITANT, 0.5)
    for frac in (0.1, 0.3, 0.6, 0.9):
        i = int(frac * (len(plan.t) - 1))
        first = reg.replan(plan.q[0], None, None, State.HESITANT, 0.5, restart=True)
        # the arm is at the plan's start, at rest: no transition worth the name (under a
        # millisecond: the plan's first samples may creep by a rounding error)
        assert first.transition < 1e-3
        for elapsed in (None, float(plan.t[i])):
            rep = reg.replan(plan.q[i], plan.qd[i], plan.qdd[i], State.HESITANT, 0.5,
                             elapsed=elapsed)
            if np.abs(plan.qd[i]).max() > 0 or elapsed is not None:
                assert rep.join_time == pytest.approx(plan.t[i] + LEAD, abs=0.05)
            else:
                assert rep.join_time >= plan.t[i] + LEAD - 1e-9
            assert rep.transition == pytest.approx(LEAD, abs=0.01)
            on_plan = plan.q[np.searchsorted(plan.t, plan.t[i] + rep.transition / 2)]
            mid = rep.trajectory.q[np.searchsorted(rep.trajectory.t, rep.transition / 2)]
            assert np.abs(mid - on_plan).max() < 0.01  # it follows the plan, no detour
            reg.replan(plan.q[0], None, None, State.HESITANT, 0.5, restart=True)


def test_restart_joins_the_plan_at_its_start(reg, moving):
    """restart=True begins a new reach: the transition leads to the plan's first sample."""
    first, k = moving
    rep = reg.update(first.q[k], first.qd[k], first.qdd[k], C=1.0, V=-1.0, intensity=0.5,
                     restart=True)
    assert rep is not None and rep.join_time == 0.0
    plan = reg.plan(State.CONFIDENT, 0.5)
    end = int(np.searchsorted(rep.trajectory.t, rep.transition))
    assert np.allclose(rep.trajectory.q[end], plan.q[0], atol=EPS)


def test_inactive_brakes_and_holds(reg, moving):
    """Disengaging brakes the moving arm without a jump and holds it at rest."""
    first, k = moving
    rep = reg.replan(first.q[k], first.qd[k], first.qdd[k], State.INACTIVE, 0.5)
    new = rep.trajectory
    assert np.allclose(new.qd[0], first.qd[k], atol=EPS)
    assert np.allclose(new.qd[-1], 0.0) and np.allclose(new.qdd[-1], 0.0)
    assert new.duration - rep.transition == pytest.approx(3.0, abs=0.01)
    t, q, qd, qdd = _executed(first, k, new)
    _continuous(t[k - 5:], q[k - 5:], qd[k - 5:], qdd[k - 5:], reg.arm.jmax, reg.arm.amax)


def test_noise_within_the_hysteresis_does_not_flip_the_state():
    """A point jittering across the border between two states keeps its state; without
    hysteresis the same jitter flips it again and again."""
    rng = np.random.default_rng(3)
    jitter = rng.uniform(-0.05, 0.05, (300, 2)) + 0.5  # around (0.5, 0.5): the border
    for margin, most in ((0.2, 1), (0.0, 300)):
        r = Regulator("panda", hysteresis=Hysteresis(state=margin))
        changes = 0
        for c, v in jitter:
            choice = r.decide(float(c), float(v), 0.5)
            if choice is not None:
                r.expressed, changes = choice, changes + 1
        assert 1 <= changes <= most
        if margin == 0.0:
            assert changes > 10
    r.expressed = (State.HESITANT, 0.5)
    assert r.decide(0.9, 0.9, 0.5) == (State.CURIOUS, 0.5)


def test_intensity_changes_only_past_the_hysteresis():
    """An intensity jittering at the midpoint between two levels keeps the level; a clear
    change moves it."""
    r = Regulator("panda", hysteresis=Hysteresis(intensity=0.05), intensity_step=0.25)
    r.expressed = (State.CURIOUS, 0.25)
    for i in np.random.default_rng(1).uniform(0.34, 0.41, 100):
        assert r.decide(1.0, 1.0, float(i)) is None
    assert r.decide(1.0, 1.0, 0.6) == (State.CURIOUS, 0.5)


def test_uncertainty_backlash():
    """An uncertainty signal moving less than the backlash keeps the estimate."""
    r = Regulator("panda", hysteresis=Hysteresis(uncertainty=0.05))
    first = r.estimate(uncertainty=0.3)
    for u in np.random.default_rng(2).uniform(0.26, 0.34, 50):
        assert r.estimate(uncertainty=float(u)) == first
    assert r.estimate(uncertainty=0.4) == from_uncertainty(0.4)


@pytest.mark.parametrize("k, state", list(enumerate(PATH)))
def test_uncertainty_path_visits_the_states_in_order(k, state):
    """Uncertainty k/4 is the canonical point of the k-th state, at full intensity."""
    C, V, i = from_uncertainty(k / 4)
    assert (C, V) == pytest.approx(CANONICAL[state]) and i == pytest.approx(1.0)
    if k < 4:
        assert from_uncertainty(k / 4 + 1 / 8)[2] == pytest.approx(0.0)


@given(st.floats(0.0, 1.0), st.floats(0.0, 1.0))
def test_uncertainty_mapping_is_continuous_and_classified(a, b):
    """The mapping is continuous (the plane's legs are at most 2 long per 1/4), and away
    from the borders a point belongs to the state the path is nearest."""
    pa, pb = np.array(from_uncertainty(a)[:2]), np.array(from_uncertainty(b)[:2])
    assert np.linalg.norm(pa - pb) <= 8.0 * abs(a - b) + 1e-9
    s = 4 * a
    if abs(s - round(s)) < 0.45:
        assert classify(*pa) is PATH[round(s)]


@pytest.mark.parametrize("kwargs", [
    {"uncertainty": 1.2}, {"uncertainty": 0.5, "C": 0.1}, {"C": 0.1},
    {"C": 2.0, "V": 0.0}, {"C": 0.0, "V": 0.0, "intensity": -0.1}])
def test_bad_estimates_are_diagnostics(reg, kwargs):
    """A bad estimate is an AouError (I504), never a crash."""
    with pytest.raises(AouError) as err:
        reg.update(np.zeros(reg.arm.n), **kwargs)
    assert err.value.diagnostics[0].code == "I504"


@pytest.mark.parametrize("q", [np.zeros(3), "home", [np.nan] * 7, None])
def test_bad_arm_state_is_a_diagnostic(reg, q):
    """A joint state of the wrong size, or not numbers, is an I504, never a crash."""
    with pytest.raises(AouError) as err:
        reg.update(q, uncertainty=0.1, restart=True)
    assert err.value.diagnostics[0].code == "I504"


@pytest.mark.slow
@settings(max_examples=12, deadline=None)
@given(frac=st.floats(0.05, 0.95), state=st.sampled_from(PATH[1:]),
       level=st.sampled_from([0.0, 0.5, 1.0]))
def test_any_replan_is_continuous(reg, moving, frac, state, level):
    """From any instant of a reach into any state and level, the splice is continuous."""
    first, _ = moving
    k = max(5, int(frac * (len(first.t) - 1)))
    rep = reg.replan(first.q[k], first.qd[k], first.qdd[k], state, level)
    t, q, qd, qdd = _executed(first, k, rep.trajectory)
    end = k + int(np.searchsorted(rep.trajectory.t, rep.transition)) + 5
    w = slice(k - 5, end)
    _continuous(t[w], q[w], qd[w], qdd[w], reg.arm.jmax, reg.arm.amax)


@pytest.mark.slow
def test_live_regulation_example_runs(tmp_path):
    """examples/live_regulation.py regulates a minute of noisy uncertainty and plots it."""
    png = tmp_path / "live.png"
    out = subprocess.run([sys.executable, str(ROOT / "examples" / "live_regulation.py"),
                          str(png)], cwd=ROOT, check=True, timeout=300, capture_output=True,
                         text=True).stdout
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert f"wrote {png}" in out and "re-plans" in out


# --- the default hysteresis and the camera's noise --------------------------------------

#: The regulator's default before it was made from the camera's noise: the test below
#: must find it chattering.
OLD_DEFAULT = Hysteresis(state=0.2, intensity=0.05, uncertainty=0.05)


def test_the_default_hysteresis_is_the_one_the_measured_noise_gives():
    """The default is made from the calibration's measurement of the camera's confidence
    noise (docs/perception-noise.csv): its largest std at a still scene, held past each
    border by NOISE_MARGIN of it on the path's longest leg."""
    from aou_dsl.live import calibrate
    from aou_dsl.live.regulator import (
        CONFIDENCE_NOISE,
        NOISE_MARGIN,
        hysteresis_for,
        hysteresis_margins,
    )

    rows = calibrate.read_csv((ROOT / "docs" / "perception-noise.csv").read_text())
    sigma = calibrate.noise_sigma(rows)
    assert sigma == CONFIDENCE_NOISE > 0
    assert Hysteresis() == hysteresis_for(sigma)
    # the margin in uncertainty on the longest leg (confident-curious, 2 C-V units)
    u = 0.125 + NOISE_MARGIN * sigma
    c, v, _ = from_uncertainty(u)
    gain = (np.hypot(c - 1.0, v + 1.0) - np.hypot(c - 1.0, v - 1.0))
    assert gain == pytest.approx(hysteresis_margins(sigma)[0], abs=1e-3)
    # the scenes where the detector flickers are among those measured
    assert max(r["std"] for r in rows) > 10 * np.median([r["std"] for r in rows])


def _camera_like(border: float, sigma: float, seed: int, seconds: float = 40.0,
                 rate: float = 100.0, camera: float = 20.0, window: float = 1.0) -> np.ndarray:
    """An uncertainty drifting slowly across ``border`` (0.2 over ``seconds``) with noise
    as the camera's: white per frame at ``camera`` Hz, averaged over its ``window``
    (std ``sigma`` after it), each answer held until the next frame."""
    rng = np.random.default_rng(seed)
    frames = int(seconds * camera)
    per = int(window * camera)
    white = rng.normal(0.0, sigma * np.sqrt(per), frames + per)
    noise = np.convolve(white, np.ones(per) / per, "valid")[:frames]
    drift = border - 0.1 + 0.2 * np.arange(frames) / frames
    u = np.clip(drift + noise, 0.0, 1.0)
    return np.repeat(u, int(rate / camera))


def _expressed(hysteresis: Hysteresis, us: np.ndarray) -> list[tuple[State, float]]:
    """What the regulator expresses tick by tick (its :meth:`decide`, as ``update``
    calls it; no plan is made)."""
    reg = Regulator("panda", hysteresis=hysteresis)
    out = []
    for u in us:
        choice = reg.decide(*reg.estimate(uncertainty=float(u)))
        if choice is not None:
            reg.expressed = choice
        out.append(reg.expressed)
    return out


def _flips(seq: list) -> int:
    return sum(a != b for a, b in zip(seq, seq[1:], strict=False))


@pytest.mark.parametrize("border", [0.125, 0.375, 0.625, 0.875])
def test_the_default_hysteresis_does_not_chatter_on_the_cameras_noise(border):
    """A slow crossing of each border between two states, with the camera's measured
    noise: the default changes state once and its intensity a few times; the old
    default re-plans more than twice as often on the same signals."""
    from aou_dsl.live.regulator import CONFIDENCE_NOISE

    new = old = 0
    for seed in range(4):
        us = _camera_like(border, CONFIDENCE_NOISE, seed)
        got = _expressed(Hysteresis(), us)
        assert _flips([s for s, _ in got]) == 1, (border, seed)
        # the intensity goes down to 0 at the border and up again: a few levels, once
        assert _flips(got) <= 4, (border, seed, got)
        new += _flips(got)
        old += _flips(_expressed(OLD_DEFAULT, us))
    assert old > 2 * new  # the check can fail: the old default chatters on the same signals
